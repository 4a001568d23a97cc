"""Energy audit (spec §1): E_mech(t) + E_dissipated(t) - W_external(t) = E_mech(0)."""
import numpy as np
import pytest

from physics import load_scene, simulate

from helpers import energy_residual

LOSSLESS = {"effects.friction": "none", "contact.damping": 0.0, "bearing.damping": 0.0,
            "support.damping": 0.0, "effects.unbalance": False, "effects.bearing_friction": False,
            "amb.damping": 0.0, "solver.rtol": 1e-8}


def test_without_friction_and_damping_mechanical_energy_is_conserved():
    scene = load_scene("paper", LOSSLESS)
    r = simulate(scene, t_end=0.4)
    res, e = energy_residual(r)
    assert e["dissipated"][-1] == 0.0
    assert r.contact_force("RB1").max() > 1000.0                 # it did bounce hard
    drop_energy = scene.rotor.mass * scene.world.gravity * scene.contact.clearance
    post = r.t > scene.amb.off_time                              # AMBs off: no external work
    ep = e["mechanical"][post]
    assert np.ptp(ep) < 1e-3 * drop_energy
    assert res.max() < 1e-3 * drop_energy


@pytest.mark.parametrize("overrides", [{}, {"effects.friction": "kinematic"},
                                       {"effects.retainer_bearing": "linear"},
                                       {"effects.housing": False},
                                       {"contact.friction": 0.5},
                                       # massless sleeve, with and without the EHL film
                                       {"effects.sleeve_inertia": False},
                                       {"effects.sleeve_inertia": False, "contact.friction": 0.5},
                                       {"effects.sleeve_inertia": False, "effects.ehl_film": False,
                                        "contact.friction": 0.5},
                                       {"effects.sleeve_inertia": False, "contact.friction": 0.5,
                                        "effects.friction": "kinematic"},
                                       {"effects.sleeve_inertia": False, "effects.ehl_film": False,
                                        "contact.friction": 0.5, "effects.friction": "kinematic"},
                                       # mu following the sleeve temperature (test_thermal.py
                                       # checks the heat audit: stored + lost = friction work)
                                       {"effects.thermal": True, "thermal.mu_slope": 0.02,
                                        "thermal.initial_rise": 30.0}])
def test_energy_lost_equals_integrated_dissipated_power(overrides):
    r = simulate(load_scene("paper", overrides), t_end=0.4)
    res, e = energy_residual(r)
    assert e["dissipated"][-1] > 100.0                           # friction spun the sleeves up
    assert res.max() < 1e-5 * e["dissipated"][-1]


@pytest.mark.parametrize("film", [True, False])
def test_massless_sleeve_audit_converges_with_the_tolerance(film):
    """Without sleeve inertia the film follows the algebraic rolling speed; the audit counts its
    share of the ball forces as external work, so it closes like any integration error: to
    ~1e-8 of the dissipated energy at rtol 1e-7, with the film as without (it stuck at 3e-5
    at every rtol with the film before)."""
    r = simulate(load_scene("paper", {"effects.sleeve_inertia": False, "effects.ehl_film": film,
                                      "solver.rtol": 1e-7}), t_end=0.4)
    res, e = energy_residual(r)
    assert res.max() < 3e-8 * e["dissipated"][-1]


def test_kinematic_slip_friction_only_dissipates_while_paper_slip_can_feed_the_whirl():
    """The paper's slip ignores the whirl velocity, so its friction can do positive work."""
    kin = simulate(load_scene("paper", {"effects.friction": "kinematic", "contact.friction": 0.5}),
                   t_end=0.4).energy()["dissipated"]
    assert np.all(np.diff(kin) >= -1e-6 * kin[-1])          # dense-output interpolation noise
    pap = simulate(load_scene("paper", {"contact.friction": 0.5, "effects.friction": "paper"}),
                   t_end=0.4).energy()["dissipated"]
    assert np.diff(pap).min() < 0.0


ONLY_CONTACT_FRICTION = {"support.damping": 0.0, "contact.damping": 0.0, "bearing.damping": 0.0,
                         "effects.bearing_friction": False}
# a whirl reaches the paper preset's 600 µm AMB air gap, which ends validity (no stator in the
# model); an AMB gap wide enough keeps these whirls valid and their retainer physics the same
WIDE_GAP = {"amb.air_gap": 3e-3}


@pytest.mark.parametrize("overrides", [{"contact.friction": 0.25},
                                       {"contact.friction": 0.5, "effects.friction": "kinematic"}])
def test_friction_heat_is_all_the_energy_lost_when_friction_is_the_only_loss(overrides):
    """The retainer design metric friction_heat_J (∫ F_mu v_slip dt from the output samples)
    against the energy audit's exact quadrature, with every other loss switched off."""
    from physics.metrics import compute_metrics
    r = simulate(load_scene("paper", {**ONLY_CONTACT_FRICTION, **WIDE_GAP, **overrides}), t_end=0.5)
    m = compute_metrics(r)
    lost = r.energy()["dissipated"]
    i = np.searchsorted(r.t, r.t_fault)
    heat = sum(m["planes"][p]["friction_heat_J"] for p in ("RB1", "RB2"))
    assert m["backward_whirl"]                       # without damping both whirl: heavy sliding
    assert heat == pytest.approx(lost[-1] - lost[i], rel=5e-3)


def test_sleeve_spin_up_turns_half_the_friction_work_into_heat():
    """A sleeve spun up from rest by a sliding contact: the friction heat equals the sleeve's
    final kinetic energy ½ J_s ω_s² (the classic clutch result), here to 2 % (the rotor slows
    slightly and the journal's orbit adds slip)."""
    from physics.metrics import compute_metrics
    scene = load_scene("paper", {"contact.friction": 0.25, "effects.bearing_friction": False,
                                 "effects.friction": "kinematic"})
    r = simulate(scene)
    m = compute_metrics(r)
    assert not m["backward_whirl"]
    for p in ("RB1", "RB2"):
        ws = r.sleeve_speed(p)[-1]
        assert ws > 0.9 * r.rotor_speed[-1]                             # spun up
        assert m["planes"][p]["friction_heat_J"] == pytest.approx(
            0.5 * scene.sleeve.spin_inertia * ws ** 2, rel=0.02)


def test_static_safety_factor_is_the_load_rating_over_the_peak_bearing_load():
    """s_0 = C_0 / P_0 (ISO 76); a whirl at least halves it (its loads are about twice the
    resting ones, spec §7) and the peak bearing load exceeds the static weight share."""
    from physics.ball_bearing import max_contact_pressure
    from physics.metrics import compute_metrics
    rest = compute_metrics(simulate(load_scene("paper", {"contact.friction": 0.1}), t_end=0.4))
    whirl = compute_metrics(simulate(load_scene("paper", {"contact.friction": 0.6, **WIDE_GAP}),
                                     t_end=0.4))
    scene = load_scene("paper")
    weight_share = 0.5 * scene.rotor.mass * scene.world.gravity
    for m in (rest, whirl):
        for e in m["planes"].values():
            assert e["static_safety_factor"] == pytest.approx(
                scene.bearing.static_load_rating / e["peak_bearing_load_N"])
            assert e["peak_bearing_load_N"] > weight_share
    assert not rest["backward_whirl"] and whirl["backward_whirl"]
    for m in (rest, whirl):                 # the worst ball: between F / Z and F, near 5 F / Z
        for e in m["planes"].values():
            F, Q = e["peak_bearing_load_N"], e["max_ball_load_N"]
            assert F / scene.bearing.balls < Q < F
            assert Q == pytest.approx(5.0 * F / scene.bearing.balls, rel=0.2)
            assert e["max_contact_pressure_MPa"] == pytest.approx(
                1e-6 * max_contact_pressure(scene.bearing, Q))
    assert (whirl["planes"]["RB1"]["max_contact_pressure_MPa"]
            > rest["planes"]["RB1"]["max_contact_pressure_MPa"])
    assert (whirl["planes"]["RB1"]["static_safety_factor"]
            < 0.5 * rest["planes"]["RB1"]["static_safety_factor"])
