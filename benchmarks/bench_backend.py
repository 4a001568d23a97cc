"""Ray backend against the local one on the drops of ``rotordrop study paper --quick``.

    python benchmarks/bench_backend.py [--repeats 3] [--quick-only] [--json out.json]

The swept drops of the quick paper study (with the study's observables) run through
:func:`physics.runs.backend.run_drops`, interleaved per repeat: the local backend on 1 thread (and on
2 threads when ``physics.runs.sweep.run_chunk`` is there), then Ray on this machine with 1 and with 2 CPUs
(``ray.init(num_cpus=N)`` by this script; its start-up is timed apart, the batch time includes
the start of Ray's worker processes and their loading of the compiled kernels, as a user's run
does). Prints medians over the repeats: the Ray overhead against local on the same cores, the
speed-up from 1 to 2 CPUs, and what is sent per task.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import time

os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")


def quick_study_runs():
    from physics.runs.study.paper import Plan, StudyInput, plan_runs
    return [r for r in plan_runs(Plan.make(quick=True), StudyInput()) if r.label["member"] != -1]


def local(runs, threads: int) -> dict:
    from physics.runs.backend import Backend, run_drops
    from physics.runs.study.observables import drop_observables
    t0 = time.perf_counter()
    outcomes, _ = run_drops(runs, drop_observables, Backend("local"), jobs=threads, progress=False)
    return dict(batch_s=time.perf_counter() - t0, outcomes=outcomes)


def on_ray(runs, cpus: int) -> dict:
    import ray
    from physics.runs.backend import Backend, run_drops
    from physics.runs.study.observables import drop_observables
    t0 = time.perf_counter()
    ray.init(num_cpus=cpus, include_dashboard=False, logging_level="ERROR")
    start = time.perf_counter() - t0
    try:
        t0 = time.perf_counter()
        outcomes, info = run_drops(runs, drop_observables, Backend("ray"), progress=False)
        return dict(batch_s=time.perf_counter() - t0, start_s=start, outcomes=outcomes,
                    backend=info.backend)
    finally:
        ray.shutdown()


def same_numbers(a, b) -> bool:
    timing = ("wall_time_s", "compile_time_s")
    return all({k: v for k, v in x.metrics.items() if k not in timing}
               == {k: v for k, v in y.metrics.items() if k not in timing} and x.extra == y.extra
               for x, y in zip(a, b))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    import physics.runs.sweep
    if hasattr(physics.runs.sweep, "run_chunk"):                # threads in one process
        configs = [("local", 1), ("local", 2), ("ray", 1), ("ray", 2)]
    else:
        configs = [("local", 1), ("ray", 1), ("ray", 2)]
    runs = quick_study_runs()
    local(runs[:2], 1)                                   # kernels compiled / cached once
    times: dict[tuple, list] = {c: [] for c in configs}
    starts: dict[int, list] = {1: [], 2: []}
    sent = None
    reference = None
    for rep in range(args.repeats):
        for kind, n in configs:
            r = local(runs, n) if kind == "local" else on_ray(runs, n)
            times[(kind, n)].append(r["batch_s"])
            if kind == "ray":
                starts[n].append(r["start_s"])
                sent = r["backend"]["bytes_per_task"]
            reference = reference or r["outcomes"]
            assert same_numbers(reference, r["outcomes"]), f"{kind} {n}: numbers differ"
            print(f"repeat {rep + 1}: {kind:5} {n} CPU(s): {r['batch_s']:.2f} s"
                  + (f" (+ Ray start {r['start_s']:.2f} s)" if kind == "ray" else ""), flush=True)
    med = {c: statistics.median(v) for c, v in times.items()}
    overhead = med[("ray", 1)] / med[("local", 1)] - 1.0
    report = dict(drops=len(runs), repeats=args.repeats,
                  median_batch_s={f"{k} {n}": v for (k, n), v in med.items()},
                  median_ray_start_s={n: statistics.median(v) for n, v in starts.items()},
                  ray_overhead_1cpu=overhead,
                  ray_speedup_1_to_2=med[("ray", 1)] / med[("ray", 2)],
                  bytes_per_task=sent)
    if ("local", 2) in med:
        report["ray_overhead_2cpu"] = med[("ray", 2)] / med[("local", 2)] - 1.0
        report["local_speedup_1_to_2"] = med[("local", 1)] / med[("local", 2)]
    print(f"{len(runs)} drops of the quick study, median of {args.repeats} (identical numbers "
          "on every backend):")
    for (k, n), v in med.items():
        print(f"  {k:5} {n} CPU(s): {v:6.2f} s")
    print(f"  Ray overhead on 1 CPU: {100 * overhead:+.1f} %"
          + (f"; on 2 CPUs: {100 * report['ray_overhead_2cpu']:+.1f} %" if "ray_overhead_2cpu" in report else ""))
    print(f"  Ray speed-up 1 -> 2 CPUs: {report['ray_speedup_1_to_2']:.2f}x"
          + (f"; local: {report['local_speedup_1_to_2']:.2f}x" if "local_speedup_1_to_2" in report else ""))
    print(f"  Ray start-up (ray.init, apart): {report['median_ray_start_s'][1]:.2f} s (1 CPU), "
          f"{report['median_ray_start_s'][2]:.2f} s (2 CPUs)")
    print(f"  sent per task: {sent['median']:.0f} bytes (median), {sent['max']:.0f} max")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(report, fh, indent=1)


if __name__ == "__main__":
    main()
