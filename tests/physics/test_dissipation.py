"""Every dissipative element takes energy out of the motion, at every output sample.

The energy audit (test_energy.py) ties each applied force to the power it integrates; these
tests tie each power's sign to its physics (physics/dissipation.py). Together they fail when a
friction or damping sign is flipped in the kernel: tests/mutants.py flips each one in a copy of
the package and runs this file and test_energy.py against it.
"""
import numpy as np
import pytest

from physics import load_scene, simulate
from physics.dissipation import dissipation_check, dissipation_powers
from physics.metrics import after, compute_metrics, friction_heat, whirl

from helpers import energy_residual

# a drop that exercises every element: whirl (sliding under load), stator contact, a
# semi-active damper, and a second, unsymmetric plane
WHIRL = {"contact.friction": 0.5}
VARIANTS = [
    ("paper", {}),
    ("paper, whirl", WHIRL),
    ("spec", {}),
    ("asymmetric, whirl", WHIRL),
    ("paper, whirl, stator contact", {**WHIRL, "effects.stator_contact": True,
                                      "support.stiffness": 5e6}),
    ("paper, whirl, semi-active damper", {**WHIRL, "effects.semi_active_damper": True}),
    ("paper, whirl, linear bearing", {**WHIRL, "effects.retainer_bearing": "linear"}),
    ("paper, whirl, massless sleeve", {**WHIRL, "effects.sleeve_inertia": False}),
    ("paper, whirl, hertz_line", {**WHIRL, "contact.law": "hertz_line"}),
    ("paper, whirl, thermal", {**WHIRL, "effects.thermal": True, "thermal.mu_slope": 0.02}),
]


def _drop(name: str, overrides: dict, t_end: float = 0.5):
    return simulate(load_scene(name.split(",")[0], overrides), t_end=t_end)


@pytest.mark.parametrize("label, overrides", VARIANTS, ids=[v[0] for v in VARIANTS])
def test_every_element_dissipates_at_every_sample(label, overrides):
    r = _drop(label, overrides)
    check = dissipation_check(r)
    assert check["ok"], check["negative"]
    assert check["created_energy_J"] == 0.0
    powers = dissipation_powers(r)
    # the elements this drop switches on do work (so the check saw them act)
    assert powers["RB1.contact_friction"].max() > 100.0
    assert powers["RB1.contact_damping"].max() > 0.0
    if "stator" in label:
        assert powers["AMB1.stator_friction"].max() > 0.0
        assert powers["AMB1.stator_damping"].max() > 0.0
        assert powers["AMB1.stator_mount_damping"].max() > 0.0
    # the per-element powers add up to the audit's dissipated energy: the check reads the
    # powers the kernel integrates, not a copy of them (the massless sleeve also counts the
    # drag it passes on, which is one of these terms)
    # and the audit closes: each applied force's work is the power booked for it
    res, e = energy_residual(r)
    assert res.max() < 1e-5 * e["dissipated"][-1]
    t = r.t
    total = sum(powers.values())
    integral = np.sum(0.5 * (total[1:] + total[:-1]) * np.diff(t))
    assert integral == pytest.approx(e["dissipated"][-1] - e["dissipated"][0], rel=2e-2)


def test_the_paper_slip_law_creates_energy_and_says_so():
    """Eq. 19 as printed follows Omega - omega_s: with r != R it pushes along the sliding (the
    sleeve driven towards Omega overtakes the no-slip speed Omega r / R), and the metrics report
    the energy it created; the kinematic law on the same drop creates none."""
    scene = load_scene("paper", {"effects.friction": "paper"})
    r = simulate(scene)
    m = compute_metrics(r)
    d = m["dissipation"]
    assert not d["ok"] and set(d["negative"]) == {"RB1.contact_friction", "RB2.contact_friction"}
    created = [m["planes"][p]["friction_energy_created_J"] for p in ("RB1", "RB2")]
    assert min(created) > 0.1
    assert d["created_energy_J"] == pytest.approx(sum(created), rel=0.05)   # (pre-fault too)
    assert any("created" in w and "paper" in w for w in m["warnings"])
    # the sleeve ends faster than the no-slip speed Omega r / R: the law drove it past
    ratio = scene.rotor.journal_radius / (scene.rotor.journal_radius + scene.contact.clearance)
    assert r.sleeve_speed("RB1")[-1] > 1.005 * ratio * r.rotor_speed[-1]
    kin = compute_metrics(simulate(scene.with_overrides({"effects.friction": "kinematic"})))
    assert kin["dissipation"]["ok"] and not any("created" in w for w in kin["warnings"])
    assert all(kin["planes"][p]["friction_energy_created_J"] == 0.0 for p in ("RB1", "RB2"))
    # and there the sleeve ends at the no-slip speed
    rk = simulate(scene.with_overrides({"effects.friction": "kinematic"}))
    assert rk.sleeve_speed("RB1")[-1] == pytest.approx(ratio * rk.rotor_speed[-1], rel=2e-3)


def test_the_default_law_dissipates_in_every_preset():
    for name in ("paper", "spec", "asymmetric"):
        assert load_scene(name).effects.friction == "kinematic", name


def test_stiff_support_whirl_heats_both_planes_over_six_seconds():
    """K_s = 5e8, mu = 0.25: the whirl runs away after 1 s; under the paper law the net friction
    work per plane turned negative at 2.05 s. With the default law the friction heat stays
    positive and never decreases, to the end, and every element dissipates over the whole run.
    The run leaves validity long before (the AMB-plane orbit reaches the air gap at 0.19 s; the
    preset has no stator), so the metrics report the heat only up to then; the law's heat is read
    here from the friction power over the whole run."""
    r = simulate(load_scene("paper", {"support.stiffness": 5e8, "solver.output_rate": 2000.0}),
                 t_end=6.0)
    m = compute_metrics(r)
    assert whirl(r, "RB1", r.t_fault)["backward_whirl"]        # over the whole run
    whole = dissipation_check(r)
    assert whole["ok"], whole["negative"]
    assert m["dissipation"]["ok"], m["dissipation"]["negative"]     # over the valid samples
    assert 0.1 < m["left_validity_at_s"] < 0.3 and m["left_validity_plane"] == "AMB1"
    post = after(r, r.t_fault)
    for p in ("RB1", "RB2"):
        heat = friction_heat(r, p, post)
        assert heat[-1] > 100.0 and np.all(np.diff(heat) >= 0.0)
        assert m["planes"][p]["friction_heat_J"] is None
        assert m["planes"][p]["friction_heat_J_before_invalid"] > 100.0
        assert m["planes"][p]["friction_energy_created_J_before_invalid"] == 0.0
    res, e = energy_residual(r)
    assert res.max() < 1e-3 * e["dissipated"][-1]


def test_a_heavily_damped_contact_never_pulls():
    """c = 1e6 N s/m (the range's top): during restitution the dashpot term c delta' would exceed
    the elastic force (-19 kN against it at RB1, measured from the record), so eq. 14's force is
    clipped at zero: a unilateral contact only pushes. Its dashpot then takes F_r - F_el, which
    stays dissipative, and the audit closes; a dashpot that pulls would also dissipate and close
    the audit, which is why the force's sign is checked here on the record."""
    r = simulate(load_scene("paper", {"contact.damping": 1e6, "solver.output_rate": 20e3}),
                 t_end=0.2)
    for p in ("RB1", "RB2"):
        f = r.contact_force(p)
        assert f.max() > 1e3 and f.min() >= 0.0
    check = dissipation_check(r)
    assert check["ok"], check["negative"]
    assert check["terms"]["RB1.contact_damping"]["min_power_W"] >= 0.0
    res, e = energy_residual(r)
    assert res.max() < 1e-5 * e["dissipated"][-1]


EARLY = [("paper, whirl, hertz_line", {**WHIRL, "contact.law": "hertz_line"}, 0.13),
         ("paper, whirl, stator contact", {**WHIRL, "effects.stator_contact": True,
                                           "support.stiffness": 5e6}, 0.14)]


@pytest.mark.parametrize("label, overrides, t_end", EARLY, ids=[v[0] for v in EARLY])
def test_the_first_contacts_dissipate_and_close_the_audit(label, overrides, t_end):
    """The first impacts only (the stator first touched at 0.113 s): a force or power of the
    wrong sign shows here as a failed check on a finite run, before it could drive the run to a
    blow-up (which says only that the run broke, not what is wrong)."""
    r = _drop(label, overrides, t_end)
    check = dissipation_check(r)
    assert check["ok"], check["negative"]
    res, e = energy_residual(r)
    assert res.max() < 1e-5 * e["dissipated"][-1]
    if "stator" in label:
        assert dissipation_powers(r)["AMB1.stator_damping"].max() > 0.0   # it touched
