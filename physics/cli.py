"""physics' part of the ``rotordrop`` command line: ``drop``, ``params``, ``study`` and
``accuracy``, and the argparse helpers every layer's commands share. It sits above the model and
the run tools (:mod:`physics.runs`), and imports them inside the handlers.

The ``rotordrop`` entry point is ``agents.cli:main`` (the top layer): it calls each layer's
``register(subparsers)`` (this module's and agents') and runs the chosen command through :func:`run`. Registration must stay light: heavy
imports happen inside the handlers (docs/architecture.md).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from .runs import UsageError


def at_least(low: int):
    """argparse type of an integer option >= ``low`` (``--jobs``, ``--members``: 1; ``--seed``: 0)."""
    def integer(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or value < low:
            raise argparse.ArgumentTypeError(f"must be an integer >= {low}, got {text!r}")
        return value
    return integer


def add_scene_args(p: argparse.ArgumentParser) -> None:
    """--scene and --set, shared by every command that runs the simulator."""
    p.add_argument("--scene", default="paper",
                   help="preset name (see `rotordrop params --presets`) or a TOML file")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a parameter by dotted key (repeatable), e.g. contact.friction=0.4")


def _assignments(args) -> dict:
    from .scene import parse_assignment
    return dict(parse_assignment(a) for a in args.overrides)


def scene_from_args(args):
    """The scene named by --scene with the --set overrides applied (validated)."""
    from .scene import load_scene
    return load_scene(args.scene, _assignments(args))


def overrides_from_args(args) -> dict:
    """The --set overrides as typed values, validated against --scene now (before any run of a
    batch starts), for commands that pass a scene on as source + overrides."""
    scene = scene_from_args(args)
    return {k: scene.get(k) for k in _assignments(args)}


def cmd_drop(args) -> int:
    from .metrics import compute_metrics
    from .runs.plots import plot_drop
    from .simulate import simulate

    scene = scene_from_args(args)
    out = output_dir(args.out)
    result = simulate(scene, t_end=args.t_end, progress=not args.quiet)
    metrics = compute_metrics(result)
    (out / "metrics.json").write_text(json.dumps(metrics, indent=2))
    (out / "scene.toml").write_text(result.model.scene.to_toml())
    result.save_npz(out / "timeseries.npz")
    title = f"(mu = {scene.contact.friction:g}{'' if metrics['fault_simulated'] else ', no fault'})"
    figures = [] if args.no_plots else plot_drop(result, out, title)
    print(summary_table(metrics))
    print(f"wrote {out / 'metrics.json'}, {out / 'timeseries.npz'}, {out / 'scene.toml'}"
          + "".join(f", {f.name}" for f in figures))
    return 0


def output_dir(path: str) -> Path:
    """The --out directory, created; a one-line UsageError when it cannot be."""
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {path} is an existing file, not a directory")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UsageError(f"--out {path}: cannot create the directory ({exc.strerror})") from None
    return out


def summary_table(m: dict) -> str:
    """A short human-readable table of the drop metrics, its warnings last (``warning: ...``).
    Without a fault in the run the post-fault tables are left out."""
    lines = [f"scene {m['scene']}: {m['t_end']:g} s simulated in {m['wall_time_s']:.3f} s "
             f"({m['rhs_evaluations']} rhs evaluations, {m['n_state']} states; compile/cache load "
             f"{m['compile_time_s']:.2f} s)", _contact_line(m),
             f"final rotor speed {_cell(m, 'final_rotor_speed_rpm', '.0f')} rpm"]
    r = m.get("rotor", {})
    if r.get("model") == "flexible":
        lines.insert(1, f"flexible rotor (shaft {r['shaft']!r}): {r['elastic_modes']} elastic modes"
                     f" per bending plane ({r['bending_modes']} bending below"
                     f" {r['mode_cutoff_hz']:g} Hz, {r['static_correction_modes']} static"
                     f" correction) at " + ", ".join(f"{f:.0f}" for f in r["frequencies_hz"])
                     + " Hz")
    if m["fault_simulated"]:
        lines += _post_fault_tables(m)
    lines.append(f"{'AMB plane':10}{'max disp [µm]':>15}{'stator':>8}{'contacts':>10}{'peak F [N]':>12}")
    for p, v in m["amb_planes"].items():
        lines.append(f"{p:10}{_cell(v, 'max_displacement_um', '.1f'):>15}"
                     f"{_yes(v, 'stator_contact'):>8}"
                     f"{_fmt(v['stator_contacts'], 'd'):>10}{_cell(v, 'stator_peak_force_N', '.0f'):>12}")
    if m["left_validity_at_s"] is not None:
        lines.append(f"n/a (beyond validity at t = {m['left_validity_at_s']:.4f} s): "
                     f"{m['left_validity_plane']} passed its validity bound "
                     f"({m['left_validity_criterion']}); every metric of the motion after it is not "
                     "computable (metrics.json keeps their values up to then as *_before_invalid)")
    lines += [f"warning: {w}" for w in m["warnings"]]
    return "\n".join(lines)


def _contact_line(m: dict) -> str:
    fc = m["first_contact_after_fault_s"]
    if not m["fault_simulated"]:
        if not m["amb_on_events"]:
            return "no fault in the simulated time (the AMBs never switched off)"
        from .metrics import valid_or_before
        t0 = m["first_contact_time_s"]
        touched = ("no retainer contact" if t0 is None else
                   f"first retainer contact at t = {t0 * 1e3:.2f} ms, peak contact force "
                   + ", ".join(f"{p} {valid_or_before(v, 'pre_fault_peak_contact_force_N'):.0f} N"
                               for p, v in m["planes"].items()))
        return f"AMBs on throughout ({', '.join(m['amb_on_events'])}): {touched}"
    if fc is None:
        return "no contact"
    if fc < 0.0:
        return f"first contact {-fc * 1e3:.2f} ms BEFORE the fault (in contact while levitated)"
    return f"first contact {fc * 1e3:.2f} ms after the fault"


def _post_fault_tables(m: dict) -> list[str]:
    """The per-plane drop table and the retainer-bearing table (after the fault)."""
    lines = [f"{'plane':6}{'max disp [µm]':>15}{'peak F_r [N]':>14}{'whirl':>7}{'f_whirl [Hz]':>14}"
             f"{'sleeve [rpm]':>14}"]
    for p, v in m["planes"].items():
        lines.append(f"{p:6}{_cell(v, 'max_displacement_um', '.1f'):>15}"
                     f"{_cell(v, 'peak_contact_force_N', '.0f'):>14}"
                     f"{_yes(v, 'backward_whirl'):>7}{_cell(v, 'whirl_frequency_hz', '.1f'):>14}"
                     f"{_cell(v, 'final_sleeve_speed_rpm', '.0f'):>14}")
    lines.append(f"{'retainer':10}{'bearing load [N]':>17}{'s0':>7}{'worst ball [N]':>16}"
                 f"{'p_max [MPa]':>13}{'friction heat [J]':>19}")
    for p, v in m["planes"].items():
        lines.append(f"{p:10}{_cell(v, 'peak_bearing_load_N', '.0f'):>17}"
                     f"{_cell(v, 'static_safety_factor', '.1f'):>7}"
                     f"{_cell(v, 'max_ball_load_N', '.0f'):>16}{_cell(v, 'max_contact_pressure_MPa', '.0f'):>13}"
                     f"{_cell(v, 'friction_heat_J', '.0f'):>19}")
    from .metrics import valid_or_before
    p0 = m.get("rating_pressure_MPa")
    created = {p: valid_or_before(v, "friction_energy_created_J") for p, v in m["planes"].items()}
    lines += ["s0: static safety factor C_0 / peak bearing load; p_max: Hertz pressure of the worst "
              "ball" + (f" (s0 = 1 at {p0:.0f} MPa for this bearing)" if p0 else ""),
              "friction heat: generated at the rotor-sleeve contact after the fault"
              + (" (net: the paper slip law also created "
                 + ", ".join(f"{p} {v:.1f} J" for p, v in created.items())
                 + ")" if any(v > 0.0 for v in created.values())
                 else "")]
    if "max_temperature_rise_K" in next(iter(m["planes"].values())):       # effects.thermal
        lines.append("sleeve heating: " + ", ".join(
            f"{p} +{_cell(v, 'max_temperature_rise_K', '.1f')} K max, mu "
            f"{_cell(v, 'min_friction_coefficient', '.3f')}-{_cell(v, 'max_friction_coefficient', '.3f')}"
            for p, v in m["planes"].items()))
    return lines


def _cell(v: dict, key: str, spec: str) -> str:
    """A per-plane metric for the tables: "n/a" where the run left validity before it could be
    computed (``physics.metrics.mark_validity``), else :func:`_fmt`."""
    from .metrics import BEFORE_INVALID
    if v[key] is None and key + BEFORE_INVALID in v:
        return "n/a"
    return _fmt(v[key], spec)


def _yes(v: dict, key: str) -> str:
    """A per-plane yes/no metric for the tables, "n/a" like :func:`_cell`."""
    from .metrics import BEFORE_INVALID
    if v[key] is None and key + BEFORE_INVALID in v:
        return "n/a"
    return "yes" if v[key] else "no"


def _fmt(value, spec: str) -> str:
    """``value`` formatted, "-" for None; a value that rounds to zero never prints as "-0"."""
    if value is None:
        return "-"
    text = format(value, spec)
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def cmd_params(args) -> int:
    from .scene import preset_names
    if args.presets:
        print("\n".join(preset_names()))
        return 0
    rows = scene_parameter_rows(scene_from_args(args))
    if args.json:
        print(json.dumps(rows, indent=1, default=str))
        return 0
    print(f"scene {args.scene}: the values `rotordrop drop --scene {args.scene}` runs with "
          "(* differs from the parameter's default)")
    wide = max(len(r["allowed"]) for r in rows) + 2
    print(f"{'key':32}{'value':>18}  {'unit':9}{'allowed':{wide}}{'tag':4} description")
    for r in rows:
        value = str(r["value"]) + ("*" if r["value"] != r["default"] else " ")
        print(f"{r['key']:32}{value:>19} {r['unit']:9}{r['allowed']:{wide}}{r['tag']:4} {r['doc']}")
    print("\ntags: P = paper, A = assumed, D = derived. Override any key with --set KEY=VALUE.")
    return 0


def scene_parameter_rows(scene) -> list[dict]:
    """``parameter_table()`` rows with the value ``scene`` uses added as ``value`` (``default``
    stays the parameter's own default)."""
    from .scene import parameter_table
    return [dict(r, value=scene.get(r["key"])) for r in parameter_table()]


def register(sub) -> None:
    """``drop``, ``params``, ``study`` and ``accuracy``."""
    p = sub.add_parser("drop", help="simulate a drop: summary table, metrics.json, time series, plots")
    add_scene_args(p)
    p.add_argument("--t-end", type=float, default=None, help="simulated time [s] (solver.t_end)")
    p.add_argument("--out", default="out/drop", help="output directory")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG figures")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_drop)

    p = sub.add_parser("params", help="list every scene parameter: the value a scene uses (default:"
                       " the `rotordrop drop` default scene), unit, range and source")
    add_scene_args(p)
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.add_argument("--presets", action="store_true", help="list the preset scene names")
    p.set_defaults(func=cmd_params)
    _register_study(sub)
    _register_accuracy(sub)


# ------------------------------------------------------------------ study and accuracy --
def _register_study(subparsers) -> None:
    from .runs.backend import add_backend_args
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
    from .runs.backend import Backend
    from .runs.study.run import run_paper_study
    summary = run_paper_study(args.scene, overrides_from_args(args), args.out, quick=args.quick,
                              jobs=args.jobs, progress=not args.quiet,
                              backend=Backend.from_args(args), resume=args.resume)
    print(summary)
    return 0


def cmd_study_sweep(args) -> int:
    from .runs.backend import Backend
    from .runs.study.parametric import notes, run_parametric, summary_table
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


def _register_accuracy(subparsers) -> None:
    p = subparsers.add_parser("accuracy", help="what accuracy costs in time: solver settings and "
                              "reduced models against a tight reference (Markdown, JSON, Pareto plot)")
    add_scene_args(p)
    p.add_argument("--out", default="out/accuracy", help="output directory")
    p.add_argument("--quick", action="store_true", help="2 drops of 0.3 s, fewer settings")
    p.add_argument("--modes", nargs="?", const="auto", default=None, metavar="N,N,...",
                   help="a flexible rotor: also run the drops with fewer elastic modes (these "
                        "bending-mode counts per plane, each with and without the static "
                        "correction modes; default 0,1,2,3,5,8,12,19, --quick 0,2,5,19) against "
                        "the run with the most modes: modes.csv, modes.png, a table in accuracy.md")
    p.add_argument("--modes-only", action="store_true",
                   help="run the --modes sweep alone (no solver settings, no tight reference)")
    p.add_argument("--jobs", type=at_least(1), default=None, help="threads (default: all cores)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_accuracy)


def cmd_accuracy(args) -> int:
    from .runs.accuracy import mode_counts, run_accuracy, scene_setting_text
    asked = "auto" if args.modes is None and args.modes_only else args.modes
    a, paths = run_accuracy(args.scene, overrides_from_args(args), args.out, quick=args.quick,
                            jobs=args.jobs, progress=not args.quiet,
                            modes=mode_counts(asked, args.quick), tolerances=not args.modes_only)
    solver, _, modes = Path(paths[1]).read_text().partition("## Retained elastic modes")
    if not args.modes_only:
        print(solver.split("\n\n![")[0])
    if modes:
        print("\n## Retained elastic modes" + modes.split("\n\n![")[0])
    if not args.modes_only:
        print(f"\nrecommended: {a['recommended']} ({a['recommended_reason']}); "
              f"scene's setting: {scene_setting_text(a)}")
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0


def run(args) -> int:
    """``args.func(args)``; a bad scene, integration or usage error is one line on stderr, exit 2."""
    from .scene import SceneError
    from .simulate import IntegrationError
    try:
        return args.func(args)
    except (SceneError, IntegrationError, UsageError) as exc:
        print(f"rotordrop: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:                  # `rotordrop params | head`: the reader left
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":        # the dispatcher sits in the top layer (docs/architecture.md)
    sys.exit("rotordrop: the command line starts in the top layer: run `rotordrop ...` "
             "or `python -m agents.cli ...`")
