"""``rotordrop study sweep``: a parameter study of the passive drop over one to three scene keys.

For retainer-bearing design: how do whirl, contact force and displacement change with, say,
the support damping and the friction coefficient? Every grid cell is an ensemble of
``members`` equally plausible drops (unbalance angle and fault time perturbed as in the paper
study, :mod:`physics.runs.study.ensemble`), because near the whirl threshold one drop per cell is a
coin toss. Per cell: whirl probability, whirl revolutions, peak contact force, maximum
displacement, peak retainer-bearing load, contact friction heat and ball-race contact pressure
(worst retainer plane; median and range over the members that have it), the runs that
failed, with their errors (never dropped; a run that ended before the fault is a failed drop),
and the drops per failed ``rotordrop drop`` check (:mod:`physics.runs.study.checks`). Every run can
be repeated with the ``rotordrop drop`` command stored next to it.

Values: ``KEY=V1,V2,...`` (numbers or choices, e.g. ``effects.friction=paper,kinematic``) or
``KEY=LO:HI:STEP`` (inclusive numeric range).
"""
from __future__ import annotations

import csv
import json
import math
import time
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from itertools import product
from pathlib import Path

import numpy as np

from ...metrics import whirl_decision, worst_plane
from ...scene import SceneError, load_scene
from ..backend import Backend, plan_threads, run_drops
from ..sweep import Outcome, Run
from .checks import (WARNING_KINDS, as_drop, counts_text, split_valid, warning_counts,
                     warnings_note)
from .ensemble import ENSEMBLE_KEYS, perturbations
from .labels import PLANE_KPIS, value_label

MAX_KEYS = 3
MAX_VALUES = 1000       # per key
MAX_RUNS = 20000


@dataclass(frozen=True)
class Axis:
    key: str
    values: tuple           # as typed by the scene (floats, ints, strings)

    @property
    def numeric(self) -> bool:
        return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in self.values)


def parse_vary(text: str) -> tuple[str, list[str]]:
    """``"contact.friction=0.3:0.5:0.05"`` or ``"support.damping=2790,27900"`` -> key, raw values.

    A range is stepped in decimal arithmetic, so its values are the decimals the user would type
    (``0.2:0.5:0.1`` is 0.2, 0.3, 0.4, 0.5; ``1e-14:3e-14:1e-14`` keeps its scale)."""
    if "=" not in text:
        raise SceneError(f"--vary expects KEY=V1,V2,... or KEY=LO:HI:STEP, got {text!r}")
    key, spec = (s.strip() for s in text.split("=", 1))
    if ":" in spec:
        try:
            lo, hi, step = (Decimal(p.strip()) for p in spec.split(":"))
        except (InvalidOperation, ValueError):
            raise SceneError(f"--vary {key}: LO:HI:STEP needs three numbers, got {spec!r}") from None
        if not (all(d.is_finite() for d in (lo, hi, step)) and step > 0 and hi >= lo):
            raise SceneError(f"--vary {key}: LO:HI:STEP needs finite LO <= HI and STEP > 0, got {spec!r}")
        values = [str(lo + i * step) for i in range(int(min((hi - lo) / step, MAX_VALUES)) + 1)]
    else:
        values = [v.strip() for v in spec.split(",") if v.strip()]
    if not values:
        raise SceneError(f"--vary {key}: no values in {spec!r}")
    if len(values) > MAX_VALUES:
        raise SceneError(f"--vary {key}: more than {MAX_VALUES} values in {spec!r}; "
                         f"at most {MAX_VALUES} per key")
    return key, values


def make_axes(source: str, overrides: dict, vary: list[str]) -> list[Axis]:
    """Validated axes: every value is coerced and range-checked by the scene now, before any
    run starts (a bad value names the key and its allowed range)."""
    if not 1 <= len(vary) <= MAX_KEYS:
        raise SceneError(f"study sweep varies 1 to {MAX_KEYS} keys (--vary), got {len(vary)}")
    axes = []
    for text in vary:
        key, raw = parse_vary(text)
        if key in overrides:
            raise SceneError(f"{key} is both varied (--vary) and fixed (--set); keep one")
        if any(a.key == key for a in axes):
            raise SceneError(f"--vary {key} is given twice")
        values = tuple(dict.fromkeys(load_scene(source, {**overrides, key: v}).get(key) for v in raw))
        axes.append(Axis(key, values))
    return axes


def ensemble_keys(overrides: dict, axes: list[Axis]) -> list[str]:
    """The ensemble keys the members perturb: those neither fixed (--set) nor varied (--vary)."""
    fixed = set(overrides) | {a.key for a in axes}
    return [k for k in ENSEMBLE_KEYS if k not in fixed]


def plan_runs(source: str, overrides: dict, axes: list[Axis], members: int, seed: int) -> list[Run]:
    """Cells (the product of the axes) × ensemble members, as :class:`~physics.runs.sweep.Run`."""
    if members < 1:
        raise SceneError(f"--members must be >= 1, got {members}")
    keys = ensemble_keys(overrides, axes)
    n = (members if keys else 1) * math.prod(len(a.values) for a in axes)
    if n > MAX_RUNS:                  # before the members are drawn: --members 1e8 fails at once
        raise SceneError(f"study sweep would simulate {n} drops; at most {MAX_RUNS} "
                         f"(fewer values or --members)")
    if keys:
        base = load_scene(source, overrides)
        pert = [{k: p[k] for k in keys} for p in perturbations(members, base.get("amb.off_time"), seed)]
    else:
        pert = [{}]                   # the user fixed every ensemble key: one drop per cell
    runs = []
    for cell in product(*(a.values for a in axes)):
        point = dict(zip((a.key for a in axes), cell))
        for m, p in enumerate(pert):
            runs.append(Run.of(source, {**overrides, **point, **p}, member=m, **point))
    return runs


def summarize_cell(outcomes: list[Outcome]) -> dict:
    """Whirl probability and the median / min / max of each plane KPI over the members that ran
    and have it (None where none has it, e.g. the ball-race pressure of a linear mount), and the
    drops per failed drop check (``warnings``, :mod:`physics.runs.study.checks`). A run without a
    fault is a failed drop (:func:`~physics.runs.study.checks.as_drop`). Drops beyond the contact
    laws' validity count in ``beyond_validity``, never in the KPIs, and in the whirl probability
    only if they whirled before (:func:`physics.metrics.whirl_decision`; ``whirl_undecided``: the
    others)."""
    ok = [o for o in outcomes if o.ok]
    valid, beyond = split_valid(ok)
    decided = [d for d in (whirl_decision(o.metrics) for o in ok) if d is not None]
    out = dict(members=len(outcomes), failed=len(outcomes) - len(ok), beyond_validity=beyond,
               errors=sorted({o.error.splitlines()[0] for o in outcomes if not o.ok}),
               warnings=warning_counts(outcomes),
               whirl_probability=float(np.mean(decided)) if decided else None,
               whirl_undecided=len(ok) - len(decided))
    for key in PLANE_KPIS:
        vals = np.array([v for v in (worst_plane(o.metrics, key) for o in valid) if v is not None])
        out[key] = dict(median=float(np.median(vals)), min=float(vals.min()),
                        max=float(vals.max())) if len(vals) else None
    return out


def run_parametric(source: str, overrides: dict, vary: list[str], out_dir, members: int = 8,
                   seed: int = 0, jobs: int | None = None, progress: bool = True,
                   plots: bool = True, backend: Backend = Backend(), resume: bool = False) -> dict:
    """Plan, simulate (on ``backend``; every finished drop kept in ``out_dir/drops``, and with
    ``resume`` only the missing drops run) and summarise the sweep; write ``sweep.json``,
    ``sweep.csv``, ``sweep.png``."""
    axes = make_axes(source, overrides, vary)
    runs = plan_runs(source, overrides, axes, members, seed)
    jobs, jobs_note = plan_threads(backend, jobs, len(runs))
    t0 = time.perf_counter()
    outcomes, dispatch = run_drops(runs, backend=backend, jobs=jobs, out=out_dir, resume=resume,
                                   desc="study sweep", progress=progress)
    outcomes = [as_drop(o) for o in outcomes]
    per_cell = len(runs) // math.prod(len(a.values) for a in axes)
    cells = []
    for i, cell in enumerate(product(*(a.values for a in axes))):
        chunk = outcomes[i * per_cell:(i + 1) * per_cell]
        cells.append(dict(zip((a.key for a in axes), cell), **summarize_cell(chunk)))
    report = dict(scene=source, overrides=overrides, axes={a.key: list(a.values) for a in axes},
                  members=per_cell, seed=seed, ensemble_keys=ensemble_keys(overrides, axes),
                  cells=cells, runs=[o.to_dict() for o in outcomes],
                  failed=sum(not o.ok for o in outcomes), warnings=warning_counts(outcomes),
                  jobs=jobs, jobs_note=jobs_note, backend=dispatch.backend,
                  dispatch_note=dispatch.note(), wall_time_s=time.perf_counter() - t0)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    (out / "sweep.json").write_text(json.dumps(report, indent=1))
    write_csv(report, out / "sweep.csv")
    report["files"] = ["sweep.json", "sweep.csv"]
    if plots:
        report["files"] += plot_files(report, axes, out)
    return report


def plot_files(report: dict, axes: list[Axis], out: Path) -> list[str]:
    """``sweep.png`` for one or two keys; with a third key one map of the first two per value
    of the third (``sweep_1.png``, ``sweep_2.png``, ... in the order of its values), all on one
    colour scale per quantity so that the maps compare."""
    from .report import plot_parametric
    if len(axes) < 3:
        return [plot_parametric(report, axes, out)]
    third = axes[2]
    limits = {}                                  # one colour scale over all the maps
    for key in ("peak_contact_force_N", "max_displacement_um"):
        med = [c[key]["median"] for c in report["cells"] if c[key] is not None]
        if med:
            limits[key] = (min(med), max(med))
    files = []
    for i, v in enumerate(third.values, 1):
        part = dict(report, cells=[c for c in report["cells"] if c[third.key] == v],
                    scene=f"{report['scene']}, {third.key} = {value_label(v)}")
        files.append(plot_parametric(part, axes[:2], out, f"sweep_{i}.png", limits))
    return files


def write_csv(report: dict, path: Path) -> None:
    keys = list(report["axes"])
    fields = keys + ["members", "failed", "beyond_validity", "whirl_probability"] + [
        f"{k}_{s}" for k in PLANE_KPIS for s in ("median", "min", "max")] + [
        f"warnings_{k}" for k in WARNING_KINDS]
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(fields)
        for c in report["cells"]:
            w.writerow([c[k] for k in keys] + [c["members"], c["failed"], c["beyond_validity"],
                                               c["whirl_probability"]]
                       + [None if c[k] is None else c[k][s] for k in PLANE_KPIS
                          for s in ("median", "min", "max")]
                       + [c["warnings"][k] for k in WARNING_KINDS])


def summary_table(report: dict) -> str:
    """Markdown: one row per cell; the last column counts the drops per failed drop check."""
    keys = list(report["axes"])
    head = ("| " + " | ".join(keys) + " | whirl prob. | peak force median (max) [N] | "
            "max disp. median (max) [µm] | failed | beyond validity | warnings |\n|"
            + "---|" * (len(keys) + 6) + "\n")
    rows = []
    for c in report["cells"]:
        f, d = c["peak_contact_force_N"], c["max_displacement_um"]
        flagged = counts_text(c["warnings"]) or "-"
        rows.append("| " + " | ".join(value_label(c[k]) for k in keys)
                    + (f" | {c['whirl_probability']:.2f} | {f['median']:.0f} ({f['max']:.0f}) | "
                       f"{d['median']:.0f} ({d['max']:.0f})" if f else " | - | - | -")
                    + f" | {c['failed']} | {c['beyond_validity']} | {flagged} |")
    return head + "\n".join(rows) + "\n"


def notes(report: dict, members: int) -> list[str]:
    """The lines printed under the table: capped --jobs, backend and resumed drops, fixed
    ensemble, failed and flagged drops."""
    out = [f"note: {report['jobs_note']}"] if report["jobs_note"] else []
    out += [report["dispatch_note"]] if report.get("dispatch_note") else []
    if report["members"] < members:
        out.append(f"note: --set/--vary fix {' and '.join(ENSEMBLE_KEYS)}, the keys that make the "
                   f"ensemble, so each cell is {report['members']} drop, not {members}")
    if report["failed"]:
        out.append(f"{report['failed']} drops failed (column 'failed'; the statistics are over the "
                   "drops that ran; a run that ended before the fault is a failed drop); their errors "
                   "are in sweep.json (cells[].errors, runs[].error)")
    beyond = sum(c["beyond_validity"] for c in report["cells"])
    if beyond:
        undecided = sum(c.get("whirl_undecided", 0) for c in report["cells"])
        out.append(f"{beyond} drops left validity (a contact law's bound, or the AMB air gap "
                   "without stator contact; column 'beyond validity'): they are not in the force "
                   "and displacement statistics, and count in the whirl probability only if they "
                   f"whirled before ({undecided} did not: undecided, left out of it)")
    flagged = warnings_note(report["warnings"])
    if flagged:
        out.append(f"{flagged}; see column 'warnings', and runs[].metrics.warnings in sweep.json "
                   "for the texts `rotordrop drop` prints")
    return out
