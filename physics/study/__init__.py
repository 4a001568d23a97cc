"""``rotordrop study``: published drop studies re-run as ensembles (Markdown + PNG + JSON).

``rotordrop study paper [--quick] [--jobs N] [--scene S] [--set K=V] --out DIR`` runs the three
studies of Kärkkäinen, Sopanen & Mikkola §V (friction, support stiffness, support damping), the
claims table and the sensitivity to every assumed parameter. ``rotordrop study sweep --vary
KEY=VALUES [--vary KEY=VALUES] [--members N]`` is a parameter study of the passive drop over one
to three scene keys (:mod:`physics.study.parametric`). Both run on ``--backend local|ray``
(:mod:`physics.backend`) and keep every finished drop in ``--out`` for ``--resume``. Registration is light: the heavy
modules are imported by the handler.
"""
from __future__ import annotations


def register(subparsers) -> None:
    from ..backend import add_backend_args
    from ..cli import add_scene_args, at_least
    p = subparsers.add_parser("study", help="re-run a published study: report.md, figures, study.json")
    sub = p.add_subparsers(dest="study", required=True)
    q = sub.add_parser("paper", help="the paper's friction, stiffness and damping studies (§V)")
    add_scene_args(q)
    q.add_argument("--out", default="out/study", help="output directory")
    q.add_argument("--quick", action="store_true",
                   help="coarse grid and small ensembles (same outputs, minutes -> seconds)")
    q.add_argument("--jobs", type=at_least(1), default=None,
                   help="threads (default: all cores; at most one per CPU and per drop)")
    q.add_argument("--quiet", action="store_true", help="no progress bar")
    add_backend_args(q, jobs=True)
    q.set_defaults(func=cmd_study_paper)

    q = sub.add_parser("sweep", help="a parameter study of the passive drop over 1 to 3 scene keys, "
                                     "an ensemble of drops per cell")
    add_scene_args(q)
    q.add_argument("--vary", action="append", default=[], metavar="KEY=VALUES", required=True,
                   help="a scene key and its values: KEY=V1,V2,... or KEY=LO:HI:STEP (1 to 3 times; a third key gives one map per value), "
                        "e.g. --vary support.damping=2790,27900,1e5 --vary contact.friction=0.3:0.6:0.05")
    q.add_argument("--members", type=at_least(1), default=8,
                   help="drops per cell, unbalance angle and fault time perturbed (default 8)")
    q.add_argument("--seed", type=at_least(0), default=0, help="seed of the ensemble perturbations")
    q.add_argument("--out", default="out/sweep", help="output directory")
    q.add_argument("--jobs", type=at_least(1), default=None,
                   help="threads (default: all cores; at most one per CPU and per drop)")
    q.add_argument("--no-plots", action="store_true", help="no sweep.png")
    q.add_argument("--quiet", action="store_true", help="no progress bar")
    add_backend_args(q, jobs=True)
    q.set_defaults(func=cmd_study_sweep)


def cmd_study_paper(args) -> int:
    from ..backend import Backend
    from ..cli import overrides_from_args
    from .run import run_paper_study
    summary = run_paper_study(args.scene, overrides_from_args(args), args.out, quick=args.quick,
                              jobs=args.jobs, progress=not args.quiet,
                              backend=Backend.from_args(args), resume=args.resume)
    print(summary)
    return 0


def cmd_study_sweep(args) -> int:
    from ..backend import Backend
    from ..cli import overrides_from_args
    from .parametric import notes, run_parametric, summary_table
    report = run_parametric(args.scene, overrides_from_args(args), args.vary, args.out,
                            members=args.members, seed=args.seed, jobs=args.jobs,
                            progress=not args.quiet, plots=not args.no_plots,
                            backend=Backend.from_args(args), resume=args.resume)
    print(summary_table(report))
    for line in notes(report, args.members):
        print(line)
    print("wrote " + ", ".join(f"{args.out}/{f}" for f in report["files"])
          + f" in {report['wall_time_s']:.0f} s")
    return 0
