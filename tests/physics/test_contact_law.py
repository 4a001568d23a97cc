"""contact.law = "hertz_line" (physics/contact.py) and the contact-validity metrics."""
import math

import numpy as np
import pytest

from physics import load_scene, simulate
from physics.contact import (hunt_crossley, hysteresis_factor, line_continuation, line_elastic_force,
                             line_potential)
from physics.metrics import compute_metrics, left_validity

from helpers import energy_residual

C = 300e-6                                     # contact.clearance
E_STAR = 206e9 / (2 * (1 - 0.3 ** 2))          # steel on steel
A = math.pi * 0.022 * E_STAR                   # pi L E*, L = contact.length


@pytest.mark.parametrize("F", [10.0, 1e3, 1e4, 1e5, 4e5])
def test_line_law_inverts_johnsons_internal_line_contact(F):
    """delta(F) = F / (pi L E*) [ln(4 pi L E* c / F) - 1] written out here; the kernel's F(delta)
    returns F. At 10 kN the approach is 7.5 µm (the paper preset's K delta^1.1 needs 123 µm)."""
    delta = F / A * (math.log(4 * A * C / F) - 1.0)
    assert delta < line_continuation(C)
    assert line_elastic_force(delta, A, C) == pytest.approx(F, rel=1e-12)
    if F == 1e4:
        assert delta == pytest.approx(7.47e-6, rel=0.01)


def test_line_law_is_continued_linearly_and_smoothly_past_u_e_minus_3():
    dv = line_continuation(C)
    assert dv == pytest.approx(8 * C / math.e ** 3)
    f0 = line_elastic_force(dv * (1 - 1e-9), A, C)
    assert line_elastic_force(dv * (1 + 1e-9), A, C) == pytest.approx(f0, rel=1e-6)
    assert line_elastic_force(dv + 1e-5, A, C) - line_elastic_force(dv, A, C) == pytest.approx(A * 1e-5)
    slope = (line_elastic_force(dv, A, C) - line_elastic_force(dv - 1e-9, A, C)) / 1e-9
    assert slope == pytest.approx(A, rel=1e-3)       # tangent stiffness reaches pi L E* there


def test_line_potential_is_the_integral_of_the_force():
    d = np.linspace(0.0, 1.5 * line_continuation(C), 200_001)
    f = np.array([line_elastic_force(x, A, C) for x in d])
    work = np.concatenate(([0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(d))))
    for i in (2_000, 50_000, 130_000, 200_000):
        assert line_potential(d[i], A, C) == pytest.approx(work[i], rel=1e-6)


def test_hunt_crossley_damping_gives_the_restitution_at_the_reference_speed():
    """A mass on the hertz_line law hitting at v_ref rebounds with about e (Lankarani-Nikravesh is
    an approximation for e near 1), and a slower impact rebounds more elastically."""
    m, e = 48.65, 0.9
    v_ref = math.sqrt(2 * 9.80665 * C)
    chi = hysteresis_factor(e, v_ref)

    def rebound(v0):
        x, v, h = 0.0, v0, 2e-8
        while x >= 0.0:
            f = hunt_crossley(line_elastic_force(x, A, C), v, chi)
            v -= h * f / m
            x += h * v
        return -v / v0

    assert rebound(v_ref) == pytest.approx(e, abs=0.03)
    assert rebound(0.3 * v_ref) > rebound(v_ref)


def impact(v0, chi, m=48.65, h=5e-8):
    """A mass m hitting the hertz_line law at v0 (symplectic Euler on hunt_crossley): (exit
    speed, the power (F - F_el) delta' of the hysteresis part integrated over the contact)."""
    x, v, dissipated = 0.0, v0, 0.0
    while x >= 0.0:
        f_el = line_elastic_force(x, A, C)
        f = hunt_crossley(f_el, v, chi)
        dissipated += h * (f - f_el) * v
        v -= h * f / m
        x += h * v
    return -v, dissipated


def elastic_damping_work(v0, chi, m=48.65, n=4000):
    """First order in chi v0: the hysteresis work along the undamped impact, 2 chi ∫ F_el(δ) δ'(δ) dδ
    over the approach to δ_max (½ m v0² = V(δ_max)), with δ'² = v0² - 2 V(δ)/m (rebound mirrored)."""
    lo, hi = 0.0, 1e-3                                  # δ_max by bisection on V(δ) = ½ m v0²
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if line_potential(mid, A, C) < 0.5 * m * v0 * v0 else (lo, mid)
    d = lo * (1.0 - np.cos(np.linspace(0.0, 0.5 * np.pi, n)))       # dense near δ_max
    rate = np.sqrt(np.maximum(v0 * v0 - 2.0 * np.array([line_potential(x, A, C) for x in d]) / m, 0.0))
    g = np.array([line_elastic_force(x, A, C) for x in d]) * rate
    return 2.0 * chi * float(np.sum(0.5 * (g[1:] + g[:-1]) * np.diff(d)))


@pytest.mark.parametrize("v_scale", [0.1, 0.3])
def test_hunt_crossley_impact_loses_the_work_of_its_hysteresis(v_scale):
    """One impact on the hertz_line law, slow enough that chi v0 << 1: the kinetic energy it loses
    is the work of the hysteresis part chi F_el delta' of the force (the balance closes), that work
    is a loss (> 0, so e < 1), and it matches the first-order estimate along the undamped impact,
    2 chi ∫ F_el delta' d delta (the loss grows as chi v0: 1 - e² ∝ chi v0 for this law too)."""
    m, v_ref = 48.65, math.sqrt(2 * 9.80665 * C)
    chi = hysteresis_factor(0.9, v_ref)
    v0 = v_scale * v_ref
    v1, dissipated = impact(v0, chi)
    lost = 0.5 * m * (v0 * v0 - v1 * v1)
    assert lost == pytest.approx(dissipated, rel=1e-4)             # the balance of the impact
    assert lost > 0.0 and v1 < v0                              # a loss: e < 1
    assert lost == pytest.approx(elastic_damping_work(v0, chi), rel=1.5 * chi * v0)   # next order: ~chi v0


@pytest.fixture(scope="module")
def hertz_drops():
    return {mu: simulate(load_scene("paper", {"contact.law": "hertz_line", "contact.friction": mu}),
                         t_end=0.4) for mu in (0.25, 0.5)}


@pytest.mark.parametrize("mu", [0.25, 0.5])
def test_hertz_line_drop_is_finite_and_its_energy_audit_closes(hertz_drops, mu):
    r = hertz_drops[mu]
    assert np.isfinite(r.Y).all() and r.t[-1] == pytest.approx(0.4)
    assert r.contact_force("RB1").max() > 1e3                    # it landed
    res, e = energy_residual(r)
    assert res.max() < 1e-5 * e["dissipated"][-1]
    m, bounds = compute_metrics(r), left_validity(r)
    for p in ("RB1", "RB2"):                     # steel contact: micrometres, within its 28 µm
        v = bounds[p]
        pen = r.penetration(p).max() * 1e6
        assert 0.0 < pen < v["validity_bound_um"] == pytest.approx(28.0, abs=0.1)
        assert v["left_validity_at_s"] is None
    assert not m["penetration_beyond_validity"]
    # the mu = 0.5 whirl reaches the AMB air gap (no stator in the preset): valid up to there
    assert m["air_gap_beyond_validity"] == ([] if mu < 0.5 else ["AMB1", "AMB2"])


@pytest.fixture(scope="module")
def paper_drops():
    return {name: simulate(load_scene("paper", ov), t_end=0.3)
            for name, ov in (("calm", {}), ("whirl", {"contact.friction": 0.5}),
                             ("fast", {"contact.friction": 0.5, "rotor.speed_rpm": 30000.0,
                                       # wide enough that it does not reach the AMB stator
                                       "amb.air_gap": 3e-3}))}


def test_max_penetration_is_reported_within_the_paper_laws_bound(paper_drops):
    """42 µm at mu = 0.25 and 179 µm in the mu = 0.5 whirl: both below the paper law's 553 µm
    (the 52 kN at which a steel line contact reaches b = 0.3 r): no warning, numbers kept."""
    calm = compute_metrics(paper_drops["calm"])
    whirl = left_validity(paper_drops["whirl"])  # the retainer bounds (it reaches the AMB air gap)
    for p in ("RB1", "RB2"):
        pen = paper_drops["whirl"].penetration(p).max() * 1e6
        bound = whirl[p]["validity_bound_um"]
        assert bound == pytest.approx(553.4, abs=0.1) and whirl[p]["left_validity_at_s"] is None
        assert calm["planes"][p]["max_penetration_um"] < pen < bound
    assert calm["left_validity_at_s"] is None and not calm["penetration_beyond_validity"]
    assert not any("validity bound" in w for w in calm["warnings"])
    assert not compute_metrics(paper_drops["whirl"])["penetration_beyond_validity"]


def test_film_thicker_than_the_internal_play_is_warned(paper_drops):
    """At 30 000 rpm the sleeves spin up to a 12.6 µm film, beyond the 7.5 µm radial play; at
    10 000 rpm the film stays below it."""
    fast, calm = compute_metrics(paper_drops["fast"]), compute_metrics(paper_drops["calm"])
    assert fast["bearing_radial_play_um"] == 7.5
    assert fast["planes"]["RB1"]["max_film_thickness_um"] == pytest.approx(12.6, abs=0.3)
    assert fast["film_exceeds_play"] == ["RB1", "RB2"]
    assert any("internal play" in w for w in fast["warnings"])
    assert calm["planes"]["RB1"]["max_film_thickness_um"] < 7.5 and not calm["film_exceeds_play"]
    off = compute_metrics(simulate(load_scene("paper", {"effects.ehl_film": False}), t_end=0.12))
    assert off["planes"]["RB1"]["max_film_thickness_um"] is None and not off["film_exceeds_play"]


def test_output_rate_check_follows_the_contact_law_and_the_stator():
    """The sampling check resolves the stiffer hertz_line contact (its tangent stiffness at the
    load) and, once the rotor touches it, the stator impact 2π √(m/k_st) = 0.98 ms."""
    from physics.metrics import contact_period, stator_period
    paper = load_scene("paper")
    hertz = paper.with_overrides({"contact.law": "hertz_line"})
    k = A / (math.log(4 * A * C / 3e3) - 2.0)
    assert contact_period(hertz, "RB1", 3e3) == pytest.approx(2 * math.pi * math.sqrt(48.65 / k))
    assert contact_period(hertz, "RB1", 3e3) < 0.5 * contact_period(paper, "RB1", 3e3)
    assert stator_period(paper) == pytest.approx(2 * math.pi * math.sqrt(48.65 / 2e9))
    m = compute_metrics(simulate(paper.with_overrides({"contact.friction": 0.5,
                                                       "effects.stator_contact": True,
                                                       "stator.friction": 0.0,
                                                       "solver.output_rate": 5000.0}), t_end=0.3))
    assert m["min_output_rate_source"].startswith("stator contact period")
    assert m["output_rate_too_coarse"]
