"""The metrics' shared pieces (Result.orbit_after / radius_after) and the study's unobserved drops
change no number: each is checked bit for bit against the plain formula it replaced."""
import numpy as np
import pytest

from physics import load_scene, simulate
from physics.metrics import compute_metrics, whirl
from physics.model import PLANES
from physics.runs.study.observables import drop_observables
from physics.runs.study.paper import Plan, StudyInput, plan_runs
from physics.runs.sweep import Run, outcome_of


@pytest.fixture(scope="module")
def whirling():
    return simulate(load_scene("paper", {"contact.friction": 0.5, "solver.t_end": 0.3}))


def _plain_whirl(result, plane, after):
    """The whirl detection as it was written on the full time series (the reference)."""
    sel = result.t >= after
    e = (result.orbit(plane) - result.sleeve(plane))[sel]
    t = result.t[sel]
    spin = np.sign(result.rotor_speed[sel].mean()) or 1.0
    r = np.hypot(e[:, 0], e[:, 1])
    ang = np.arctan2(e[:, 1], e[:, 0])
    far = r > 0.5 * result.model.scene.contact.clearance
    both = far[1:] & far[:-1]
    dang = ((np.diff(ang) + np.pi) % (2 * np.pi) - np.pi)[both]
    moving_back = -spin * dang > 0
    t_back = np.diff(t)[both][moving_back].sum()
    return -spin * dang.sum() / (2 * np.pi), (-spin * dang[moving_back]).sum() / (2 * np.pi * t_back)


def test_orbit_pieces_after_a_time_are_the_masked_series_bit_for_bit(whirling):
    r = whirling
    for p in PLANES:
        for t0 in (0.0, r.t_fault, 0.2, r.t[-1]):
            sel = r.t >= t0
            rel = (r.orbit(p) - r.sleeve(p))[sel]
            assert np.array_equal(r.orbit_after(p, t0), r.orbit(p)[sel])
            assert np.array_equal(r.orbit_after(p, t0, relative=True), rel)
            assert np.array_equal(r.radius_after(p, t0, relative=True), np.hypot(rel[:, 0], rel[:, 1]))
            assert r.radius_after(p, t0) is r.radius_after(p, t0)       # computed once
            with pytest.raises(ValueError):                             # and read-only
                r.radius_after(p, t0)[0] = 1.0


def test_whirl_equals_the_plain_formula_on_a_whirling_drop(whirling):
    for p in PLANES:
        w = whirl(whirling, p, whirling.t_fault)
        revs, freq = _plain_whirl(whirling, p, whirling.t_fault)
        assert w["backward_whirl"] and w["whirl_revolutions"] == revs > 3.0
        assert w["whirl_frequency_hz"] == freq


def test_the_sensitivity_drops_skip_only_their_observables(whirling):
    runs = plan_runs(Plan.make(quick=True), StudyInput())
    assert all(r.observe == (r.label["study"] != "sensitivity") for r in runs)
    assert sum(not r.observe for r in runs) > 100
    seen, unseen = Run.of("paper", {"contact.friction": 0.5}), Run.of(
        "paper", {"contact.friction": 0.5}, observe=False)
    a, b = outcome_of(seen, whirling, drop_observables), outcome_of(unseen, whirling, drop_observables)
    assert a.extra == drop_observables(whirling) and a.extra["max_x_um"] > 0.0 and b.extra == {}
    drop_timing = lambda m: {k: v for k, v in m.items() if k not in ("wall_time_s", "compile_time_s")}
    assert drop_timing(a.metrics) == drop_timing(b.metrics) == drop_timing(compute_metrics(whirling))


def test_the_bisection_stops_early_with_the_result_of_all_its_iterations():
    """bisect_decreasing (the sleeve's rest offset, the stator's damping ratio) leaves the loop
    once the bracket stops moving: the root is bit for bit that of the 200 iterations."""
    from physics.roots import bisect_decreasing

    def all_iterations(f, target, lo, hi):
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if f(mid) > target else (lo, mid)
        return 0.5 * (lo + hi)

    for a in (0.3, 1.0, 7.0):
        for target in (-2.0, 0.0, 1e-9, 3.0, -(a * 0.5 ** 3 + 0.5)):   # the last one hit exactly
            calls = []

            def f(x, a=a):
                calls.append(x)
                return -a * x ** 3 - x
            root = bisect_decreasing(f, target, -10.0, 10.0)
            # it stopped early (a root at 0 moves on through the denormals for all 200)
            assert len(calls) < 100 or target == 0.0
            assert root == all_iterations(f, target, -10.0, 10.0)


def test_twin_planes_computed_once_give_the_numbers_of_both_computed(whirling):
    """A symmetric drop's planes have the same time series bit for bit (Result.twin_planes); the
    metrics and observables computed once for both equal those computed plane by plane, and a
    drop with the retainers placed asymmetrically is not a twin."""
    import dataclasses
    r = whirling
    assert r.twin_planes()
    twin = (compute_metrics(r), drop_observables(r))
    plain = dataclasses.replace(r)              # a fresh result: nothing memoised
    plain._derived["twin"] = False
    assert (compute_metrics(plain), drop_observables(plain)) == twin
    assert twin[0]["planes"]["RB1"] is not twin[0]["planes"]["RB2"]
    lopsided = simulate(load_scene("paper", {"positions.rb2": 0.3, "contact.friction": 0.5,
                                             "solver.t_end": 0.15}))
    assert not lopsided.twin_planes()
