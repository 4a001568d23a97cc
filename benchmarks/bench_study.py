"""Ensemble speed: `rotordrop study paper` against its floor, one drop's cost times its drops.

    python benchmarks/bench_study.py [--quick] [--repeats 5] [--sample 40] [--json out.json]

Study ratio = study wall time / (simulated seconds of all its drops x one drop's wall time per
simulated second / cores), all measured in this run:

* the study: the whole ``rotordrop study paper`` (``--quick``: the quick plan, 388 drops; default
  the full plan, 6 273 drops) in this process, with its figures and report;
* one drop's wall time per simulated second (the integration's ``wall_time_s``, as
  ``benchmarks/bench_drop.py``), two ways: the paper drop (mu = 0.25, no whirl), median of
  ``--repeats`` before and ``--repeats`` after the study; and the mean over ``--sample`` drops of
  the study itself (every k-th, run one at a time), which carries its mix of whirling drops
  (costlier per simulated second) and calm ones;
* cores: the CPUs this process may use.

Ratio 1 is the study at the cost of its drops' integration alone, perfectly parallel; what is
above it is the output sampling, diagnostics, metrics, figures and threading. On a machine shared
with other work the ratio rises with the load (``uptime`` is printed).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import tempfile
import time

from physics import load_scene, simulate
from physics.sweep import available_cores
from physics.simulate import warm_up
from physics.model import build_model
from physics.study.paper import Plan, StudyInput, plan_runs
from physics.study.run import run_paper_study


def drop_rate(scene, repeats: int) -> list[float]:
    """Wall seconds per simulated second of ``repeats`` drops of ``scene``."""
    out = []
    for _ in range(repeats):
        r = simulate(scene)
        out.append(r.stats.wall_time_s / scene.solver.t_end)
    return out


def sample_rate(runs, k: int) -> float:
    """Mean wall seconds per simulated second of every k-th run, simulated one at a time."""
    rates = []
    for run in runs[::k]:
        scene = run.to_scene()
        rates.append(simulate(scene).stats.wall_time_s / scene.solver.t_end)
    return statistics.fmean(rates)


def load() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the quick plan (388 drops)")
    ap.add_argument("--repeats", type=int, default=5, help="paper drops before and after")
    ap.add_argument("--sample", type=int, default=40, help="study drops run one at a time")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    paper = load_scene("paper")
    warm_up(build_model(paper))
    base = StudyInput("paper", {})
    runs = plan_runs(Plan.make(args.quick), base)
    sim_s = sum(r.to_scene().solver.t_end for r in runs)
    cores = available_cores()
    print(f"{'quick' if args.quick else 'full'} paper study: {len(runs)} drops, {sim_s:g} simulated "
          f"s, {cores} cores; {load()}")

    before = drop_rate(paper, args.repeats)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as out:
        run_paper_study("paper", {}, out, quick=args.quick, progress=False)
    wall = time.perf_counter() - t0
    after = drop_rate(paper, args.repeats)
    mix = sample_rate(runs, max(1, len(runs) // args.sample))
    one = statistics.median(before + after)
    res = dict(drops=len(runs), simulated_s=sim_s, cores=cores, study_wall_s=wall,
               paper_drop_s_per_sim_s=one, paper_drop_before=before, paper_drop_after=after,
               study_mix_s_per_sim_s=mix,
               ratio_paper_drop=wall / (sim_s * one / cores),
               ratio_study_mix=wall / (sim_s * mix / cores), load=os.getloadavg())
    print(f"study wall {wall:.1f} s; one paper drop {one * 1e3:.1f} ms per simulated s "
          f"(before {statistics.median(before) * 1e3:.1f}, after {statistics.median(after) * 1e3:.1f});"
          f" the study's own drops one at a time {mix * 1e3:.1f} ms per simulated s")
    print(f"study ratio {res['ratio_paper_drop']:.2f} (vs the paper drop), "
          f"{res['ratio_study_mix']:.2f} (vs the study's own drops); {load()}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(res, f, indent=2)
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
