"""Cost of the solver tolerance: wall seconds per simulated second and rhs evaluations.

    python benchmarks/bench_accuracy.py [--scene paper] [--set KEY=VALUE ...] [--repeats 5]

For each adaptive tolerance (and the scene's default) the median over ``--repeats`` runs of one
1 s drop after a JIT warm-up, on one core. The accuracy side of the trade-off is
``rotordrop accuracy`` (docs/accuracy.md); this script only times it.
"""
from __future__ import annotations

import argparse
import statistics

from physics import load_scene, simulate
from physics.scene import Scene, parse_assignment

RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default="paper")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument("--repeats", type=int, default=5)
    args = p.parse_args()
    base = load_scene(args.scene, dict(parse_assignment(a) for a in args.overrides))
    simulate(base, t_end=0.11)                                   # compile / load the cache
    default = Scene().solver.rtol
    print(f"scene {args.scene}: median of {args.repeats} runs, {base.solver.t_end:g} s simulated")
    print(f"{'rtol':>8}{'wall s / sim s':>16}{'rhs evaluations':>17}{'steps':>10}{'rejected':>10}")
    for rtol in RTOLS:
        walls, stats = [], None
        for _ in range(args.repeats):
            r = simulate(base.with_overrides({"solver.rtol": rtol}))
            walls.append(r.stats.wall_time_s / base.solver.t_end)
            stats = r.stats
        mark = "  <- default" if rtol == default else ""
        print(f"{rtol:8.0e}{statistics.median(walls):16.4f}{stats.rhs_evaluations:17d}"
              f"{stats.steps:10d}{stats.rejected_steps:10d}{mark}")


if __name__ == "__main__":
    main()
