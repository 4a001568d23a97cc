"""``rotordrop study``: published drop studies re-run as ensembles (Markdown + PNG + JSON).

``rotordrop study paper [--quick] [--jobs N] [--scene S] [--set K=V] --out DIR`` runs the three
studies of Kärkkäinen, Sopanen & Mikkola §V (friction, support stiffness, support damping), the
claims table and the sensitivity to every assumed parameter. Registration is light: the heavy
modules are imported by the handler.
"""
from __future__ import annotations


def register(subparsers) -> None:
    from ..cli import add_scene_args
    p = subparsers.add_parser("study", help="re-run a published study: report.md, figures, study.json")
    sub = p.add_subparsers(dest="study", required=True)
    q = sub.add_parser("paper", help="the paper's friction, stiffness and damping studies (§V)")
    add_scene_args(q)
    q.add_argument("--out", default="out/study", help="output directory")
    q.add_argument("--quick", action="store_true",
                   help="coarse grid and small ensembles (same outputs, minutes -> seconds)")
    q.add_argument("--jobs", type=int, default=None, help="worker processes (default: all cores)")
    q.add_argument("--quiet", action="store_true", help="no progress bar")
    q.set_defaults(func=cmd_study_paper)


def cmd_study_paper(args) -> int:
    from ..cli import overrides_from_args
    from .run import run_paper_study
    summary = run_paper_study(args.scene, overrides_from_args(args), args.out, quick=args.quick,
                              jobs=args.jobs, progress=not args.quiet)
    print(summary)
    return 0
