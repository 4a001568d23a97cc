"""Validity bounds of the contact laws (physics/validity.py, contact.py, stator.py) and how the
metrics, the drop table, the studies and the environments treat a run that passes them."""
import math

import numpy as np
import pytest

from physics import load_scene, simulate
from physics.cli import summary_table
from physics.contact import (half_width_approach, half_width_load, line_deflection,
                             line_elastic_force)
from physics.metrics import BEFORE_INVALID, INVALID_KEYS, compute_metrics
from physics.runs.study.checks import beyond_validity, split_valid
from physics.runs.study.parametric import summarize_cell
from physics.runs.sweep import Outcome
from physics.validity import validity_bound
from rotordrop_env.env import RotorDropEnv

E_STAR = 206e9 / (2 * (1 - 0.3 ** 2))          # steel on steel, bearing.youngs_modulus / poisson


def half_width(F, r, c, L):
    """Hertz half-width of a cylinder of radius r in a bore of radius r + c (Johnson §4.3),
    written out independently of physics.contact: 1/R' = 1/r - 1/(r + c), b^2 = 4 F R'/(pi L E*)."""
    R = 1.0 / (1.0 / r - 1.0 / (r + c))
    return math.sqrt(4.0 * F * R / (math.pi * L * E_STAR))


@pytest.mark.parametrize("r, c, L", [(0.030, 300e-6, 0.022), (0.045, 600e-6, 0.040),
                                     (0.010, 50e-6, 0.005)])
def test_hertz_line_bound_is_where_the_half_width_reaches_0p3_r(r, c, L):
    """The law's force at the bound gives b = 0.3 r; a = pi L E* cancels out of the approach."""
    a = math.pi * L * E_STAR
    d = half_width_approach(r, c)
    assert half_width(line_elastic_force(d, a, c), r, c, L) == pytest.approx(0.3 * r, rel=1e-9)
    assert line_deflection(half_width_load(r, c, a), a, c) == pytest.approx(d, rel=1e-12)
    assert half_width(line_elastic_force(1.2 * d, a, c), r, c, L) > 0.3 * r


def test_paper_scene_bounds():
    """hertz_line: 28.0 µm (0.093 c, the half-width 9 mm at 52.3 kN); the paper law: 52.3 kN
    through K delta^1.1, 553 µm with K = 2e8 (paper preset), 1039 µm with 1e8 (spec preset);
    the stator: 55.9 µm (0.093 g_0), k delta = 112 kN."""
    paper, spec = load_scene("paper"), load_scene("spec")
    hertz = validity_bound(load_scene("paper", {"contact.law": "hertz_line"}))
    assert hertz.penetration == pytest.approx(28.0e-6, abs=0.05e-6)
    assert hertz.load == pytest.approx(52.28e3, rel=1e-3)
    assert half_width(hertz.load, 0.030, 300e-6, 0.022) == pytest.approx(9e-3, rel=1e-9)
    law = validity_bound(paper)
    assert law.load == pytest.approx(hertz.load, rel=1e-9)         # the same steel contact's load
    assert 2e8 * law.penetration ** 1.1 == pytest.approx(law.load, rel=1e-12)
    assert law.penetration == pytest.approx(553.4e-6, abs=0.1e-6)
    assert validity_bound(spec).penetration == pytest.approx(1039.2e-6, abs=0.1e-6)
    st = validity_bound(paper, "stator")
    assert st.penetration == pytest.approx(55.9e-6, abs=0.05e-6)
    assert st.load == pytest.approx(2e9 * st.penetration)
    assert validity_bound(spec, "stator") == st


def test_bound_rejects_bad_input():
    with pytest.raises(ValueError, match="where must be one of"):
        validity_bound(load_scene("paper"), "housing")
    with pytest.raises(ValueError, match="limit"):
        half_width_load(0.03, 300e-6, 1e9, limit=1.5)


@pytest.fixture(scope="module")
def drops():
    """A 20 t rotor dropped at t = 0 passes the paper law's 553 µm (52 kN) on its first impact
    (with an AMB air gap wide enough that the rotor does not reach the stator first, which would
    end validity before: test_validity_window.py); the paper drop at mu = 0.25 stays far within it."""
    heavy = simulate(load_scene("paper", {"amb.off_time": 0.0, "rotor.mass": 2e4,
                                          "amb.air_gap": 3e-3}), t_end=0.12)
    calm = simulate(load_scene("paper"), t_end=0.3)
    return {"heavy": (heavy, compute_metrics(heavy)), "calm": (calm, compute_metrics(calm))}


def test_a_drop_past_the_bound_gets_its_time_and_null_peaks(drops):
    r, m = drops["heavy"]
    t = m["left_validity_at_s"]
    assert t is not None and 0.0 < t < 0.05 and m["penetration_beyond_validity"] == ["RB1", "RB2"]
    bound = m["planes"]["RB1"]["validity_bound_um"] * 1e-6
    pen = r.penetration("RB1")
    assert pen[r.t < t].max() <= bound < pen[r.t >= t][0]    # the crossing lies at t
    for p, v in m["planes"].items():
        assert v["left_validity_at_s"] == pytest.approx(t)
        for key in INVALID_KEYS:
            assert v.get(key) is None, key           # the thermal keys only with effects.thermal
        assert v["max_displacement_um"] is None and v["static_safety_factor"] is None
        assert v["peak_contact_force_N" + BEFORE_INVALID] == pytest.approx(
            r.contact_force(p)[r.t < t].max())
        assert v["max_penetration_um" + BEFORE_INVALID] <= v["validity_bound_um"]
    assert m["step_resolved_peaks"] is None and not m["sampled_peaks_missed"]
    assert any("validity bound" in w for w in m["warnings"])
    table = summary_table(m)
    assert f"n/a (beyond validity at t = {t:.4f} s)" in table
    assert "RB1               n/a           n/a" in table


def test_a_normal_paper_drop_keeps_its_numbers(drops):
    _, m = drops["calm"]
    assert m["left_validity_at_s"] is None and not m["penetration_beyond_validity"]
    for v in m["planes"].values():
        assert v["left_validity_at_s"] is None and v["peak_contact_force_N"] > 1e3
        assert not any(k.endswith(BEFORE_INVALID) for k in v)
    assert "n/a" not in summary_table(m)


def test_studies_count_drops_beyond_validity_apart(drops):
    """The heavy drop is counted in 'beyond_validity' and in the whirl probability, never in the
    peak statistics (which are the calm drop's alone)."""
    outs = [Outcome(run=None, ok=True, metrics=drops[k][1]) for k in ("calm", "heavy")]
    assert beyond_validity(outs[1].metrics) and not beyond_validity(outs[0].metrics)
    assert split_valid(outs) == ([outs[0]], 1)
    cell = summarize_cell(outs)
    calm_peak = max(v["peak_contact_force_N"] for v in drops["calm"][1]["planes"].values())
    assert cell["beyond_validity"] == 1 and cell["members"] == 2
    assert cell["peak_contact_force_N"]["max"] == pytest.approx(calm_peak)
    assert cell["whirl_probability"] == 0.0


def _episode(overrides, terminate):
    env = RotorDropEnv("paper", overrides=overrides, terminate_on_failure=terminate,
                       episode_time=0.05)
    _, info = env.reset(seed=0)
    infos = [info]
    while True:
        _, _, term, trunc, info = env.step(np.zeros(env.action_space.shape, np.float32))
        infos.append(info)
        if term or trunc:
            return infos, term


# a 10 µm clearance and K = 1e12 N/m^1.1 bring the paper law's bound down to 1.7 kN (F_b is
# proportional to c), passed at the first impact (13 kN); the raised load rating keeps the
# bearing-overload failure out of the way
STIFF = {"contact.clearance": 1e-5, "contact.stiffness": 1e12, "bearing.static_load_rating": 1e8}


@pytest.mark.parametrize("overrides, beyond", [({}, False), (STIFF, True)])
def test_env_info_reports_validity_every_step(overrides, beyond):
    infos, term = _episode(overrides, terminate=False)
    assert not term and len(infos) == 51
    flags = [i["beyond_validity"] for i in infos]
    assert all(isinstance(f, np.bool_) for f in flags) and not flags[0]   # numpy, as all of info
    assert bool(flags[-1]) == beyond and flags == sorted(flags)      # latched once passed
    kpi = infos[-1]
    assert bool(kpi["kpi_beyond_validity"]) == beyond
    t_valid = kpi["kpi_time_within_validity_s"]
    assert math.isfinite(t_valid)
    if beyond:
        first = next(i["time_s"] for i in infos if i["beyond_validity"])
        assert 0.0 < t_valid <= first < 0.05
    else:
        assert t_valid == pytest.approx(0.05)


def test_terminate_on_failure_ends_the_episode_past_the_bound():
    infos, term = _episode(STIFF, terminate=True)
    last = infos[-1]
    assert term and last["beyond_validity"] and len(infos) < 51
    assert not last["kpi_stator_contact"] and not last["kpi_bearing_overload"]
    assert last["reward_failure"] < 0.0


def test_paper_study_medians_and_claims_leave_drops_beyond_validity_out(drops):
    """The friction-class medians take the calm drop alone and count the heavy one apart; a
    support-stiffness claim whose nominal drop left validity says so instead of a ratio."""
    from physics.runs.study.claims import _stiff_ratio_base
    from physics.runs.study.observables import drop_observables
    from physics.runs.study.paper import _medians
    outs = [Outcome(run=None, ok=True, metrics=drops[k][1], extra=drop_observables(drops[k][0]))
            for k in ("calm", "heavy")]
    med = _medians(outs)
    assert med["runs"] == 2 and med["beyond_validity"] == 1
    assert med["peak_contact_force_N"] == pytest.approx(
        max(v["peak_contact_force_N"] for v in drops["calm"][1]["planes"].values()))
    assert med["mean_late_force_N"] == pytest.approx(outs[0].extra["mean_late_force_N"])
    rows = [dict(stiffness=5e7, peak_contact_force_N=3143.0),
            dict(stiffness=5e8, beyond_validity_at_s=0.2, backward_whirl=True)]
    with pytest.raises(ValueError, match=r"left validity \(the first bound it passed.*\) at t = 0.200 s"):
        _stiff_ratio_base(dict(support_stiffness=rows), 300.0)


def test_batched_env_reports_the_same_validity_as_the_single_env():
    """The batched step (kernels.step_batch / step_rows) latches the same flag at the same step."""
    import gymnasium as gym
    from rotordrop_env import BatchedRotorDropVecEnv
    kw = dict(overrides=STIFF, episode_time=0.006, terminate_on_failure=False)
    venv = BatchedRotorDropVecEnv("RotorDrop-Passive-v1", 2, seed=3, **kw)
    venv.reset()
    batched = [venv.step(np.zeros((2,) + venv.action_space.shape, np.float32))[3]
               for _ in range(6)]
    env = gym.make("RotorDrop-Passive-v1", **kw)
    env.reset(seed=3)
    single = [env.step(np.zeros(env.action_space.shape, np.float32))[4]["beyond_validity"]
              for _ in range(6)]
    assert not single[0] and single[-1]                          # passed at 2.8 ms
    for e in range(2):
        assert [b[e]["beyond_validity"] for b in batched] == single
