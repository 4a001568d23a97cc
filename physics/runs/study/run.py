"""Orchestration of ``rotordrop study paper``: sweep, analysis, claims, figures, report."""
from __future__ import annotations

import json
import time
from pathlib import Path

from ...metrics import whirled
from ...scene import load_scene
from ..backend import Backend, plan_threads
from . import report
from .checks import warnings_note
from .claims import claims
from .paper import (PRIMARY_SLIP, SENSITIVITY, Plan, StudyInput, analyse, plan_runs, run_study,
                    simulate_figure_drop)


def run_paper_study(source: str, overrides: dict, out_dir, quick: bool = False,
                    jobs: int | None = None, progress: bool = True, backend: Backend = Backend(),
                    resume: bool = False) -> str:
    """Run the study (its drops on ``backend``, each kept in ``out_dir/drops`` as it finishes;
    ``resume`` runs only the missing ones), write ``study.json``, ``report.md`` and the
    figures; return a summary."""
    plan = Plan.make(quick)
    base = StudyInput(source, dict(overrides))          # refuses --set on the studies' own keys
    jobs, jobs_note = plan_threads(backend, jobs, len(plan_runs(plan, base)))
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    outcomes, nominal, dispatch = run_study(plan, base, jobs=jobs, progress=progress,
                                            backend=backend, out=out, resume=resume)
    a = analyse(plan, base, outcomes)
    scene = base.scene
    a["claims"] = claims(a, scene.contact.clearance * 1e6)
    a["calibration"] = calibration(source, overrides)
    figures = dict(
        probability=[report.plot_probability(a, out)],
        friction=report.plot_friction_runs(friction_runs(base, plan), out),
        response=[report.plot_friction_response(a, out)],
        stiffness=report.plot_support(nominal["stiffness"], "support.stiffness", out),
        damping=report.plot_support(nominal["damping"], "support.damping", out),
        sensitivity=[report.plot_sensitivity(a, out)])
    commands = interesting_runs(a, outcomes, base, plan)
    a["reproduce"] = [dict(label=l, command=c) for l, c in commands]
    wall = time.perf_counter() - t0
    a["wall_time_s"] = wall
    a["jobs"] = jobs
    a["backend"] = dispatch.backend
    a["quick"] = quick
    (out / "study.json").write_text(json.dumps(a, indent=1, default=_json))
    meta = dict(wall_s=wall, where=where(dispatch.backend, jobs), quick=quick, commands=commands,
                calibration=calibration_text(a["calibration"], source),
                ranges={f.name: f.why for f in SENSITIVITY})
    path = report.write_report(a, out, figures, meta)
    th = a["friction_threshold"]
    ok = sum(c["reproduced"] for c in a["claims"])
    flagged = warnings_note(a["warnings"]["total"])
    notes = [n for n in (jobs_note and f"note: {jobs_note}", dispatch.note(), flagged) if n]
    return (f"whirl threshold (50 %): kinematic slip {th['kinematic']}, paper's eq. 19 {th['paper']}; "
            f"{ok}/{len(a['claims'])} claims reproduced; {a['runs']['failed']} of "
            f"{a['runs']['total']} runs failed; {wall:.0f} s\n" + "".join(n + "\n" for n in notes)
            + f"wrote {path}, {out / 'study.json'}")


def where(backend: dict, jobs: int | None) -> str:
    """Where the drops ran, for the report's first line."""
    if backend.get("backend") == "ray":
        return f"on Ray ({backend['nodes']} node(s), {backend['cpus']} CPU(s))"
    return f"on {jobs} core(s)" if jobs else "(every drop resumed from disk)"


def friction_runs(base: StudyInput, plan: Plan) -> dict:
    """The nominal drops at the figure frictions (full time series, simulated here; the support
    studies' nominal drops come from :func:`physics.runs.study.paper.run_study`)."""
    return {mu: simulate_figure_drop(base.run({"contact.friction": mu}),
                                     f"the friction figure's drop at contact.friction = {mu:g}")
            for mu in plan.figure_frictions}


def interesting_runs(a: dict, outcomes, base: StudyInput, plan: Plan) -> list[tuple[str, str]]:
    """Reproduce commands for a few drops worth looking at."""
    fr = [o for o in outcomes if o.ok and o.run.label["study"] == "friction"
          and o.run.label["slip"] == PRIMARY_SLIP and o.run.label["drag"]]
    fr.sort(key=lambda o: (o.run.label["friction"], o.run.label["member"]))
    out = []
    first = next((o for o in fr if whirled(o.metrics)), None)
    if first is not None:
        out.append((f"the lowest-μ drop that whirls (μ = {first.run.label['friction']:g})",
                    first.run.to_dict()["command"]))
    certain = a["friction_onset"][f"{PRIMARY_SLIP}, drag on"].get("certain_from")
    if certain is not None:
        calm = [o for o in fr if not whirled(o.metrics) and o.run.label["friction"] < certain]
        if calm:
            o = calm[-1]
            out.append((f"the highest-μ drop that does not whirl (μ = {o.run.label['friction']:g})",
                        o.run.to_dict()["command"]))
    for row in a["support_stiffness"] + a["support_damping"]:
        if "command" in row:
            key = "stiffness" if "stiffness" in row else "damping"
            out.append((f"support {key} {row[key]:g}, nominal drop", row["command"]))
    return out


def calibration(source: str, overrides: dict) -> list[dict]:
    """Every parameter where the study's scene differs from the frozen ``spec`` preset."""
    scene = load_scene(source, overrides).flat()
    spec = load_scene("spec").flat()
    return [dict(key=k, spec=spec[k], used=v) for k, v in scene.items() if spec[k] != v]


def calibration_text(diff: list[dict], source: str) -> str:
    if not diff:
        return (f"The `{source}` scene uses the spec's values throughout (no calibration).\n")
    rows = "\n".join(f"| `{d['key']}` | {d['spec']} | {d['used']} |" for d in diff)
    return (f"The `{source}` scene differs from the spec's values (`spec` preset) in:\n\n"
            f"| key | spec | used here |\n|---|---|---|\n{rows}\n\n"
            "(See Sensitivity for what each does; `physics/presets/paper.toml` documents why.)\n")


def _json(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return str(x)
