"""A run is valid up to the first validity bound it passes, whichever it is (physics/metrics.py,
physics/validity.py): the contact law's penetration bound at a retainer plane, the stator's bound
with stator contact, the AMB air gap without it. Every metric of the motion after that time is
None in metrics.json, its value before kept as ``*_before_invalid``."""
from dataclasses import replace

import numpy as np
import pytest

from physics import load_scene, simulate
from physics.cli import summary_table
from physics.metrics import (BEFORE_INVALID, RUN_INVALID_KEYS, _null, compute_metrics,
                             first_bound, first_crossing, whirled)
from physics.validity import validity_bound

STIFF = {"support.stiffness": 5e8, "contact.friction": 0.25}     # stator contact off (paper)
RUN_STATS = {"wall_time_s", "compile_time_s", "rhs_evaluations", "steps", "rejected_steps"}


def row(t):
    return dict(left_validity_at_s=t)


def test_the_first_bound_passed_wins_whatever_it_is():
    assert first_bound({"RB1": row(None), "AMB1": row(None)}) == (None, None)
    assert first_bound({"RB1": row(1.42), "RB2": row(1.43), "AMB1": row(0.19)}) == (0.19, "AMB1")
    assert first_bound({"RB1": row(0.05), "AMB1": row(0.19)}) == (0.05, "RB1")
    assert first_bound({"RB1": row(None), "RB2": row(0.3), "AMB2": row(None)}) == (0.3, "RB2")
    assert first_bound({"RB1": row(0.2), "AMB1": row(0.2)}) == (0.2, "RB1")     # a tie: listed first


def test_nulling_keeps_the_value_before_and_leaves_absent_values_absent():
    table = {"RB1": dict(peak_contact_force_N=5e4, max_ball_load_N=None, whirl_frequency_hz=None,
                         backward_whirl=True, untouched=1.0)}
    early = {"RB1": dict(peak_contact_force_N=3e4, max_ball_load_N=None, whirl_frequency_hz=180.0,
                         backward_whirl=False, untouched=0.5)}
    _null(table, early, ("peak_contact_force_N", "max_ball_load_N", "whirl_frequency_hz",
                         "backward_whirl"))
    v = table["RB1"]
    assert v["peak_contact_force_N"] is None and v["peak_contact_force_N" + BEFORE_INVALID] == 3e4
    assert v["whirl_frequency_hz"] is None and v["whirl_frequency_hz" + BEFORE_INVALID] == 180.0
    assert v["backward_whirl"] is None and v["backward_whirl" + BEFORE_INVALID] is False
    assert v["max_ball_load_N"] is None and "max_ball_load_N" + BEFORE_INVALID not in v
    assert v["untouched"] == 1.0 and "untouched" + BEFORE_INVALID not in v
    assert not whirled(v)                      # the whirl decision is the one within validity
    assert whirled(dict(backward_whirl=None, backward_whirl_before_invalid=True))


def test_the_air_gap_bounds_a_scene_without_stator_contact():
    scene = load_scene("paper")
    b = validity_bound(scene, "air_gap")
    assert b.penetration == scene.amb.air_gap and b.load is None
    assert "stator is not modelled" in b.criterion


@pytest.fixture(scope="module")
def stiff():
    """The stiff-support drop (K_s = 5e8, mu = 0.25, no stator contact) over 1.6 s: its AMB-plane
    orbit passes the 600 µm air gap at about 0.2 s, its retainer penetration the paper law's
    553 µm bound at 1.42 s (the 6 s run's metrics: the same bounds, measured once)."""
    r = simulate(load_scene("paper", STIFF), t_end=1.6)
    return r, compute_metrics(r)


def test_the_stiff_drop_is_valid_until_the_rotor_reaches_the_air_gap(stiff):
    r, m = stiff
    gap = r.model.scene.amb.air_gap
    o = r.amb_orbit("AMB1")
    radius = np.hypot(o[:, 0], o[:, 1])
    k = int(np.flatnonzero(radius > gap)[0])          # the first sample past the gap
    t = m["left_validity_at_s"]
    assert r.t[k - 1] <= t <= r.t[k] and 0.15 < t < 0.3
    assert m["left_validity_plane"] == "AMB1" and "air_gap" in m["left_validity_criterion"]
    assert m["air_gap_beyond_validity"] == ["AMB1", "AMB2"] and m["stator_beyond_validity"] == []
    retainer = first_crossing(r.t, r.penetration("RB1"), m["planes"]["RB1"]["validity_bound_um"] * 1e-6)
    assert retainer is not None and retainer > 1.0 > t   # the retainer bound comes much later
    assert m["planes"]["RB1"]["left_validity_at_s"] is None     # its crossing: motion after
    assert m["penetration_beyond_validity"] == []
    for key in RUN_INVALID_KEYS:
        assert m[key] is None and m[key + BEFORE_INVALID] is not None
    assert m["final_slip_ratio"] is None and m["sleeves_still_sliding"] is None
    assert m["final_rotor_speed_rpm" + BEFORE_INVALID] == pytest.approx(
        r.rotor_speed[r.t < t][-1] * 30 / np.pi)
    for v in m["planes"].values():
        for key in ("peak_contact_force_N", "static_safety_factor", "friction_heat_J",
                    "whirl_revolutions", "whirl_frequency_hz", "final_sleeve_speed_rpm"):
            assert v[key] is None, key
        assert v["peak_contact_force_N" + BEFORE_INVALID] == pytest.approx(
            r.contact_force("RB1")[(r.t >= r.t_fault) & (r.t < t)].max())
    assert m["amb_planes"]["AMB1"]["stator_contact"] is True     # reaching the gap came first
    assert any("validity bound first at AMB1" in w for w in m["warnings"])
    table = summary_table(m)
    assert "final rotor speed n/a rpm" in table and "passed its validity bound" in table


def leaves(d, path=()):
    """(path, value) of every scalar in a nested dict/list."""
    if isinstance(d, dict):
        for k, v in d.items():
            yield from leaves(v, path + (k,))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            yield from leaves(v, path + (i,))
    else:
        yield path, d


def test_no_number_in_the_metrics_depends_on_the_motion_after_validity_ends(stiff):
    """The same run with every sample after the first one past the bound replaced by a different
    motion (scaled, shifted states and outputs) gets the same metrics: every value that is not
    None, the warnings included, is a function of the motion up to the end of validity."""
    r, m = stiff
    k = int(np.searchsorted(r.t, m["left_validity_at_s"])) + 1    # after the crossing sample
    Y, aux = r.Y.copy(), r.aux.copy()
    rng = np.random.default_rng(0)
    Y[k:] = Y[k:] * 1.7 + 1e-4 * rng.standard_normal(Y[k:].shape)
    aux[k:] = aux[k:] * 0.3 + 10.0
    other = replace(r, Y=Y, aux=aux, step_peaks=None if r.step_peaks is None else r.step_peaks * 2)
    m2 = compute_metrics(other)
    changed = dict(leaves(m2))
    compared = 0
    for path, value in leaves(m):
        if value is None or path[0] in RUN_STATS:
            continue
        compared += 1
        assert changed[path] == (pytest.approx(value) if isinstance(value, float) else value), path
    assert compared > 80


def test_the_drops_page_lists_every_metrics_key(stiff):
    """docs/drops.md names every key of metrics.json (run, retainer plane, AMB plane, rotor and
    energy audit), for a run past validity (its *_before_invalid keys by the pattern)."""
    from pathlib import Path
    page = (Path(__file__).resolve().parents[2] / "docs/drops.md").read_text()
    _, m = stiff
    keys = (set(m) | set(m["planes"]["RB1"]) | set(m["amb_planes"]["AMB1"]) | set(m["rotor"])
            | set(m["dissipation"]))
    missing = sorted(k for k in keys if not k.endswith(BEFORE_INVALID) and f"`{k}`" not in page)
    assert not missing
    assert f"`<key>{BEFORE_INVALID}`" in page
