"""Drop-simulator speed: wall seconds per simulated second, rhs evaluations, cost of each effect.

    python benchmarks/bench_drop.py [--repeats 5] [--t-end 1.0] [--json out.json]

Every figure is the median of ``--repeats`` runs after a JIT warm-up, on one core (numba kernels
are single-threaded). Also times a cold compile (empty numba cache, in a subprocess) and a warm
start (kernels loaded from the on-disk cache), and the floor ratio of the paper drop: its
integration time over the accepted steps' rhs evaluations times the cost of one rhs, each drop
followed by its rhs timing (interleaved, so a machine's load moves both).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from physics import load_scene, simulate
from physics.runs.accuracy import REDUCED
from physics.model import N_AUX, build_model, rhs
from physics.simulate import warm_up

# the reduced-fidelity scenes of the accuracy study, plus the switches it does not vary
EFFECTS_OFF = [("full model (paper)", {}), *REDUCED,
               ("no unbalance", {"effects.unbalance": False}),
               ("no gyroscopic coupling", {"effects.gyroscopic": False}),
               ("kinematic slip", {"effects.friction": "kinematic"}),
               ("no friction", {"effects.friction": "none"})]
# effects beyond the paper, off by default: what switching them on costs
EFFECTS_ON = [("sleeve heating (thermal)", {"effects.thermal": True}),
              ("base excitation (5 g, 11 ms pulse at 50 ms)",
               {"effects.base_excitation": True, "ground.pulse_peak_g": 5.0,
                "ground.pulse_start": 0.05})]


def _rhs_timer(result, samples=400, clock=time.perf_counter):
    """A function timing one pass of ``reps`` rhs evaluations over states sampled from a run,
    returning ns per evaluation (by ``clock``: the wall clock, or ``time.thread_time``)."""
    m = result.model
    Y = np.ascontiguousarray(result.Y[:: max(1, len(result.Y) // samples)])
    U = m.controls(False)
    dy, aux = np.empty(m.n_state), np.empty(N_AUX)

    def time_once(reps: int) -> float:
        t0 = clock()
        _rhs_loop(Y, m.P, m.I, U, dy, aux, reps)
        return (clock() - t0) / (reps * len(Y)) * 1e9
    return time_once


def ns_per_rhs(result, samples=400, reps=50, clock=time.perf_counter) -> float:
    """Median cost of one right-hand-side evaluation over states sampled from a run [ns]."""
    time_once = _rhs_timer(result, samples, clock)
    return statistics.median(time_once(reps) for _ in range(5))


def rhs_cost_ratio(result, reference, rounds=41, reps=5) -> float:
    """Median over ``rounds`` interleaved pairs of (ns per rhs of ``result``) / (ns per rhs of
    ``reference``): short alternating passes, so load from other processes hits both alike."""
    a, b = _rhs_timer(result), _rhs_timer(reference)
    ratios = []
    for i in range(rounds):
        if i % 2:                       # alternate which goes first
            tb, ta = b(reps), a(reps)
        else:
            ta, tb = a(reps), b(reps)
        ratios.append(ta / tb)
    return statistics.median(ratios)


def floor_ratio(scene, t_end: float, repeats: int) -> dict:
    """A drop's integration time over its floor, the accepted steps' rhs evaluations (every rhs
    evaluation but the 6 of each rejected step) times the cost of one rhs, timed right after
    each drop (interleaved); medians of ``repeats``. By the wall clock (the drop's
    ``wall_time_s``) and by the thread's CPU time (``cpu_time_s``: robust to a loaded machine)."""
    wall, cpu = [], []
    for _ in range(repeats):
        r = simulate(scene, t_end=t_end)
        st = r.stats
        accepted_rhs = st.rhs_evaluations - 6 * st.rejected_steps
        wall.append(st.wall_time_s / (accepted_rhs * ns_per_rhs(r) * 1e-9))
        cpu.append(st.cpu_time_s / (accepted_rhs * ns_per_rhs(r, clock=time.thread_time) * 1e-9))
    return dict(floor_ratio_wall=statistics.median(wall), floor_ratio_cpu=statistics.median(cpu),
                wall_s_per_sim_s=st.wall_time_s / t_end, rhs_evaluations=st.rhs_evaluations,
                rejected=st.rejected_steps, accepted_rhs=accepted_rhs,
                compile_time_s=st.compile_time_s)


def _make_loop():
    from physics._jit import njit

    @njit
    def loop(Y, P, I, U, dy, aux, reps):
        for _ in range(reps):
            for k in range(Y.shape[0]):
                rhs(0.5, Y[k], P, I, U, dy, aux)
    return loop


_rhs_loop = _make_loop()


def run_case(overrides: dict, t_end: float, repeats: int, source: str = "paper") -> dict:
    """Median wall time of ``repeats`` drops of scene ``source`` with ``overrides``, the solver
    statistics of the last one and the cost of one rhs evaluation over its states."""
    scene = load_scene(source, overrides)
    walls, last = [], None
    for _ in range(repeats):
        last = simulate(scene, t_end=t_end)
        walls.append(last.stats.wall_time_s)
    wall = statistics.median(walls)
    return dict(n_state=last.model.n_state, wall_s_per_sim_s=wall / t_end,
                rhs_evaluations=last.stats.rhs_evaluations, steps=last.stats.steps,
                rejected=last.stats.rejected_steps, ns_per_rhs=ns_per_rhs(last), result=last)


def compile_times() -> dict:
    """Seconds to compile from an empty cache and to load from a warm cache (fresh processes)."""
    code = ("import time; t=time.perf_counter(); from physics import load_scene, build_model;"
            "from physics.simulate import warm_up; warm_up(build_model(load_scene('paper')));"
            "print(time.perf_counter()-t)")
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        cold = float(subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                                    text=True, check=True).stdout)
        warm = float(subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                                    text=True, check=True).stdout)
    return dict(cold_compile_s=cold, warm_cache_load_s=warm)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--t-end", type=float, default=1.0)
    ap.add_argument("--json", default=None, help="also write the figures to this JSON file")
    ap.add_argument("--skip-compile", action="store_true")
    args = ap.parse_args()
    warm_up(build_model(load_scene("paper")))
    out: dict = {"repeats": args.repeats, "t_end": args.t_end}
    if not args.skip_compile:
        out["compile"] = compile_times()
        print(f"compile from empty cache {out['compile']['cold_compile_s']:.1f} s, "
              f"warm start {out['compile']['warm_cache_load_s']:.2f} s (process import + cache load)")

    print(f"\nfloor ratio (integration time / (accepted steps' rhs evaluations x ns per rhs), "
          f"each drop followed by its rhs timing; median of {args.repeats}):")
    out["floor"] = {}
    for mu in (0.25, 0.5):
        row = floor_ratio(load_scene("paper", {"contact.friction": mu}), args.t_end, args.repeats)
        out["floor"][f"mu={mu}"] = row
        print(f"  mu = {mu:<5} {row['floor_ratio_wall']:.3f} (wall), {row['floor_ratio_cpu']:.3f} "
              f"(CPU time); {row['wall_s_per_sim_s']:.4f} wall s per simulated s, "
              f"{row['rhs_evaluations']} rhs evaluations, {row['rejected']} rejected steps")

    print(f"\npaper scene, default tolerance, median of {args.repeats} runs of {args.t_end:g} s:")
    out["paper"] = {}
    for mu in (0.25, 0.5):
        for slip in ("paper", "kinematic"):
            row = run_case({"contact.friction": mu, "effects.friction": slip}, args.t_end, args.repeats)
            del row["result"]
            out["paper"][f"mu={mu} {slip}"] = row
            print(f"  mu = {mu:<5} {slip:9} slip: {row['wall_s_per_sim_s']:.4f} wall s per simulated s, "
                  f"{row['rhs_evaluations']} rhs evaluations, {row['ns_per_rhs']:.0f} ns per rhs")

    print(f"\ncost of each effect, off (on for those the paper lacks; mu = 0.25, median of "
          f"{args.repeats}):")
    print(f"  {'scene':30}{'states':>7}{'wall s/sim s':>14}{'rhs evals':>11}{'ns/rhs':>8}")
    out["effects"] = {}
    results = {}
    for name, ov in EFFECTS_OFF + EFFECTS_ON:
        row = run_case(ov, args.t_end, args.repeats)
        results[name] = row.pop("result")
        out["effects"][name] = row
        print(f"  {name:30}{row['n_state']:7d}{row['wall_s_per_sim_s']:14.4f}"
              f"{row['rhs_evaluations']:11d}{row['ns_per_rhs']:8.0f}")
    # an effect that is off must cost nothing: ns per rhs relative to the full model, measured
    # as the median of interleaved pairs (robust to other load on the machine)
    full = results[EFFECTS_OFF[0][0]]
    out["rhs_cost_vs_full"] = {}
    print("\nns per rhs relative to the full model (median of 41 interleaved pairs):")
    for name, _ in EFFECTS_OFF[1:] + EFFECTS_ON:
        ratio = rhs_cost_ratio(results[name], full)
        out["rhs_cost_vs_full"][name] = ratio
        print(f"  {name:30}{ratio:8.3f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=2)
        print(f"\nwrote {args.json}")


if __name__ == "__main__":
    main()
