"""Ensemble speed: `rotordrop study paper` against its floor, one drop's cost times its drops.

    python benchmarks/bench_study.py [--quick] [--repeats 5] [--sample 40] [--json out.json]
    python benchmarks/bench_study.py --quick --cores 1,2 [--rounds 3]     # speed-up 1 -> 2 cores

Study ratio = study wall time / (simulated seconds of all its drops x one drop's wall time per
simulated second / cores), all measured in this run:

* the study: the whole ``rotordrop study paper`` (``--quick``: the quick plan, 388 drops; default
  the full plan, 6 273 drops) in this process, with its figures and report;
* one drop's wall time per simulated second (the integration's ``wall_time_s``, as
  ``benchmarks/bench_drop.py``), two ways: the paper drop (mu = 0.25, no whirl), median of
  ``--repeats`` before and ``--repeats`` after the study; and the mean over ``--sample`` drops of
  the study itself (every k-th, run one at a time), which carries its mix of whirling drops
  (costlier per simulated second) and calm ones;
* cores: the CPUs this process may use;
* by CPU time: the study's CPU seconds (all threads) over its drops' integration CPU seconds,
  summed over every drop the study runs (:class:`IntegrationMeter`), and over the sample's mean
  per drop times the drops: the overhead alone, whatever the load.

``--cores 1,2``: instead, the study's wall time on 1 and on 2 threads (``--jobs``), the runs
interleaved over ``--rounds`` rounds, medians and the speed-up (on a machine shared with other
work the second core is only as free as the load average, printed before and after, says).

Ratio 1 is the study at the cost of its drops' integration alone, perfectly parallel; what is
above it is the output sampling, diagnostics, metrics, figures and threading. The CPU time per
drop of each part (the sampled drops, one at a time) says where it goes. On a machine shared
with other work the ratio rises with the load (``uptime`` is printed).
"""
from __future__ import annotations

import argparse
import importlib
import json
import os
import statistics
import tempfile
import threading
import time

from physics import load_scene, simulate
from physics.model import build_model
from physics.simulate import run_model, warm_up
from physics.runs.study.observables import drop_observables
from physics.runs.study.paper import Plan, StudyInput, plan_runs
from physics.runs.study.run import run_paper_study
from physics.runs.sweep import available_cores, outcome_of


def drop_rate(scene, repeats: int) -> list[float]:
    """Wall seconds per simulated second of ``repeats`` drops of ``scene``."""
    out = []
    for _ in range(repeats):
        r = simulate(scene)
        out.append(r.stats.wall_time_s / scene.solver.t_end)
    return out


def sample_rate(runs, k: int) -> tuple[float, dict]:
    """Every k-th run simulated one at a time, as the study does it (scene, model, drop,
    metrics and observables): the mean wall seconds of its integration per simulated second,
    and the mean CPU seconds per drop of each part."""
    rates, parts = [], {"integration": [], "output-sample diagnostics": [],
                        "metrics and observables": [], "scene and model": []}
    clock = time.thread_time
    for run in runs[::k]:
        c0 = clock()
        model = build_model(run.to_scene())
        c1 = clock()
        result = run_model(model)
        c2 = clock()
        outcome_of(run, result, drop_observables)
        c3 = clock()
        rates.append(result.stats.wall_time_s / model.scene.solver.t_end)
        parts["integration"].append(result.stats.cpu_time_s)
        parts["output-sample diagnostics"].append(c2 - c1 - result.stats.cpu_time_s)
        parts["metrics and observables"].append(c3 - c2)
        parts["scene and model"].append(c1 - c0)
    return statistics.fmean(rates), {k: statistics.fmean(v) for k, v in parts.items()}


def core_scaling(quick: bool, cores: list[int], rounds: int) -> dict:
    """Wall seconds of the whole study on each thread count of ``cores``, interleaved over
    ``rounds`` (the order alternates); medians and the speed-up over the first count."""
    walls: dict[int, list[float]] = {c: [] for c in cores}
    used: dict[int, list[float]] = {c: [] for c in cores}     # CPU s / wall s: cores it got
    print(f"{'quick' if quick else 'full'} paper study on {', '.join(map(str, cores))} threads, "
          f"{rounds} interleaved rounds; {load()}")
    for k in range(rounds):
        for c in (cores if k % 2 == 0 else cores[::-1]):
            t0, c0 = time.perf_counter(), time.process_time()
            with tempfile.TemporaryDirectory() as out:
                run_paper_study("paper", {}, out, quick=quick, jobs=c, progress=False)
            walls[c].append(time.perf_counter() - t0)
            used[c].append((time.process_time() - c0) / walls[c][-1])
            print(f"  round {k + 1}, {c} thread(s): {walls[c][-1]:.1f} s, {used[c][-1]:.2f} cores "
                  f"busy on average; {load()}", flush=True)
    med = {c: statistics.median(w) for c, w in walls.items()}
    base = cores[0]
    for c in cores:
        print(f"{c} thread(s): median {med[c]:.1f} s, speed-up over {base}: "
              f"{med[base] / med[c]:.2f}x (runs: {', '.join(f'{w:.1f}' for w in walls[c])})")
    return dict(walls=walls, cores_busy=used, median=med,
                speedup={c: med[base] / med[c] for c in cores},
                load_after=os.getloadavg())


class IntegrationMeter:
    """While active, sums the integration CPU time (``RunStats.cpu_time_s``) of every drop run in
    this process, by wrapping :func:`physics.simulate.run_model` (what every drop of a study runs,
    on any thread): the study's own integration, measured in the study itself."""

    def __enter__(self) -> "IntegrationMeter":
        self.module = importlib.import_module("physics.simulate")
        self.original = self.module.run_model
        self.cpu, self.drops, lock = 0.0, 0, threading.Lock()

        def run_model(*args, **kwargs):
            result = self.original(*args, **kwargs)
            with lock:
                self.cpu += result.stats.cpu_time_s
                self.drops += 1
            return result
        self.module.run_model = run_model
        return self

    def __exit__(self, *exc) -> None:
        self.module.run_model = self.original


def load() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the quick plan (388 drops)")
    ap.add_argument("--repeats", type=int, default=5, help="paper drops before and after")
    ap.add_argument("--sample", type=int, default=40, help="study drops run one at a time")
    ap.add_argument("--json", default=None)
    ap.add_argument("--keep", default=None, metavar="DIR",
                    help="write the study there (study.json, report, drops) instead of a temporary folder")
    ap.add_argument("--cores", default=None, help="e.g. 1,2: the study's speed-up from 1 to 2 "
                    "threads instead of its ratio")
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds of --cores")
    args = ap.parse_args()
    paper = load_scene("paper")
    warm_up(build_model(paper))
    if args.cores:
        res = core_scaling(args.quick, [int(c) for c in args.cores.split(",")], args.rounds)
        if args.json:
            with open(args.json, "w") as f:
                json.dump(res, f, indent=2)
        return
    base = StudyInput("paper", {})
    runs = plan_runs(Plan.make(args.quick), base)
    sim_s = sum(r.to_scene().solver.t_end for r in runs)
    cores = available_cores()
    print(f"{'quick' if args.quick else 'full'} paper study: {len(runs)} drops, {sim_s:g} simulated "
          f"s, {cores} cores; {load()}")

    before = drop_rate(paper, args.repeats)
    t0, c0 = time.perf_counter(), time.process_time()
    with tempfile.TemporaryDirectory() as tmp, IntegrationMeter() as meter:
        run_paper_study("paper", {}, args.keep or tmp, quick=args.quick, progress=False)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    after = drop_rate(paper, args.repeats)
    mix, parts = sample_rate(runs, max(1, len(runs) // args.sample))
    one = statistics.median(before + after)
    res = dict(drops=len(runs), simulated_s=sim_s, cores=cores, study_wall_s=wall,
               paper_drop_s_per_sim_s=one, paper_drop_before=before, paper_drop_after=after,
               study_mix_s_per_sim_s=mix,
               ratio_paper_drop=wall / (sim_s * one / cores),
               ratio_study_mix=wall / (sim_s * mix / cores), cpu_per_drop_s=parts,
               study_cpu_s=cpu, ratio_cpu=cpu / (len(runs) * parts["integration"]),
               study_integration_cpu_s=meter.cpu, study_integrated_drops=meter.drops,
               ratio_cpu_in_study=cpu / meter.cpu, load=os.getloadavg())
    print(f"study wall {wall:.1f} s; one paper drop {one * 1e3:.1f} ms per simulated s "
          f"(before {statistics.median(before) * 1e3:.1f}, after {statistics.median(after) * 1e3:.1f});"
          f" the study's own drops one at a time {mix * 1e3:.1f} ms per simulated s")
    base = parts["integration"]
    print("CPU time per drop, the study's drops one at a time: " + ", ".join(
        f"{k} {v * 1e3:.1f} ms ({v / base:.2f})" for k, v in parts.items()))
    print(f"study ratio {res['ratio_paper_drop']:.2f} (vs the paper drop), "
          f"{res['ratio_study_mix']:.2f} (vs the study's own drops); by CPU time (all threads, "
          f"robust to load): {res['ratio_cpu_in_study']:.2f} (study CPU {cpu:.0f} s over the "
          f"integration CPU of the {meter.drops} drops it ran, {meter.cpu:.0f} s, summed in the "
          f"study), {res['ratio_cpu']:.2f} (over the sample's mean per drop); {load()}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(res, f, indent=2)
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
