"""Cost of the solver tolerance: wall seconds per simulated second and rhs evaluations.

    python benchmarks/bench_accuracy.py [--scene paper] [--set KEY=VALUE ...] [--repeats 5]

For each adaptive tolerance (and the scene's default) the median over ``--repeats`` runs of one
drop of the scene's ``solver.t_end`` (``simulate`` compiles or loads the kernels before it starts
the clock), on one core. The accuracy side of the trade-off is ``rotordrop accuracy``
(docs/accuracy.md); this script only times it.
"""
from __future__ import annotations

import argparse

from bench_drop import run_case
from physics import load_scene
from physics.scene import Scene, parse_assignment

RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default="paper")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument("--repeats", type=int, default=5)
    args = p.parse_args()
    overrides = dict(parse_assignment(a) for a in args.overrides)
    t_end = load_scene(args.scene, overrides).solver.t_end
    default = Scene().solver.rtol
    print(f"scene {args.scene}: median of {args.repeats} runs, {t_end:g} s simulated")
    print(f"{'rtol':>8}{'wall s / sim s':>16}{'rhs evaluations':>17}{'steps':>10}{'rejected':>10}")
    for rtol in RTOLS:
        row = run_case(overrides | {"solver.rtol": rtol}, t_end, args.repeats, source=args.scene)
        mark = "  <- default" if rtol == default else ""
        print(f"{rtol:8.0e}{row['wall_s_per_sim_s']:16.4f}{row['rhs_evaluations']:17d}"
              f"{row['steps']:10d}{row['rejected']:10d}{mark}")


if __name__ == "__main__":
    main()
