"""``rotordrop accuracy``: what accuracy costs in time.

A reference solution at a tight tolerance is computed for a small ensemble of drops of the
scene (the rotor's angular position at the fault and the fault time perturbed, as in the paper
study); then every solver setting — adaptive tolerances, fixed steps, reduced-fidelity models —
runs the same drops and is scored against it: wall time, right-hand-side evaluations, and the
error in peak contact force, max displacement, peak bearing load, max ball load, first-contact
time, the whirl decision and the orbit over the first 20 ms after first contact (pointwise
comparison is meaningless later: the motion is chaotic after repeated impacts).

The peaks are extremes over the whole run, so in a drop whose late motion is chaotic they are
not converged even at the reference tolerance. Such drops are detected (reference and a 10x
looser run disagree by more than ``CHAOS_REL``) and excluded from the whole-run criterion of the
recommended setting; the first-20-ms quantities are judged for every drop.

For a flexible rotor (``rotor.model = "flexible"``) ``--modes`` adds what the retained elastic
modes cost: the same drops with 0, 1, 2, ... free-free bending modes (``flexible.mode_cutoff_hz``
set between two bending frequencies of the scene's shaft), with and without the static
correction modes (``flexible.static_modes``), at the scene's own solver setting, each scored
against the run with the most modes (wall time, steps, right-hand-side evaluations, errors).
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..laws import SLIP_LAWS, slip_law
from ..metrics import whirled, worst_plane
from ..scene import SceneError

WINDOW_S = 0.02          # trajectory comparison window after the reference's first contact
CAPTURE_S = 0.06         # orbit samples kept from each run after the fault (covers the window)
TOLERANCE = 0.01         # the recommended setting keeps every whole-run peak within 1 %
CHAOS_REL = 1e-3         # reference not converged for a drop: whole-run extremes differ > 0.1 %
REDUCED = (              # reduced-fidelity scenes, run at the scene's own solver settings
    ("linear retainer bearing", {"effects.retainer_bearing": "linear"}),
    ("rigid retainer bearing", {"effects.retainer_bearing": "rigid"}),
    ("no EHL film", {"effects.ehl_film": False}),
    ("no bearing friction torque", {"effects.bearing_friction": False}),
    ("no housing flexibility", {"effects.housing": False}),
    ("no sleeve inertia", {"effects.sleeve_inertia": False}),
)
EXTREMES = (             # whole-run peaks scored against the reference: (error name, metric key)
    ("peak_contact_force", "peak_contact_force_N"), ("max_displacement", "max_displacement_um"),
    ("peak_bearing_load", "peak_bearing_load_N"), ("max_ball_load", "max_ball_load_N"),
)
WHOLE_KEYS = tuple(f"{name}_rel" for name, _ in EXTREMES)
#: bending modes per plane of the --modes sweep (each with and without the static correction
#: modes; capped at what the packed arrays hold, physics.flexible.floating.MAX_MODES, whose
#: largest count is always run: the sweep's reference)
MODE_COUNTS = (0, 1, 2, 3, 5, 8, 12, 19)
QUICK_MODE_COUNTS = (0, 2, 5, 19)


class AccuracyError(SceneError):
    """The scene cannot be studied as asked (the CLI prints it as one line)."""


@dataclass(frozen=True)
class Setting:
    label: str
    kind: str                 # reference | adaptive | fixed | reduced | modes
    overrides: dict
    info: dict | None = None  # kind modes: the retained modes (mode_info)

    @property
    def full_fidelity(self) -> bool:
        return self.kind in ("adaptive", "fixed")


@dataclass(frozen=True)
class AccuracyPlan:
    members: int
    t_end: float | None        # None: the scene's own solver.t_end
    reference_rtol: float
    rtols: tuple[float, ...]
    fixed_dts: tuple[float, ...]
    seed: int = 11

    @classmethod
    def make(cls, quick: bool = False) -> "AccuracyPlan":
        if quick:
            return cls(2, 0.3, 1e-10, (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9), (1e-5, 2e-5))
        return cls(6, None, 1e-11, (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10),
                   (2.5e-6, 5e-6, 1e-5, 2e-5, 4e-5))


def settings(plan: AccuracyPlan, scene) -> list[Setting]:
    """Reference, adaptive tolerances, fixed steps, and reduced-fidelity variants of ``scene``."""
    from .sweep import changes
    out = [Setting(f"reference (adaptive rtol {plan.reference_rtol:g})", "reference",
                   {"solver.method": "adaptive", "solver.rtol": plan.reference_rtol})]
    out += [Setting(f"adaptive rtol {r:g}", "adaptive", {"solver.method": "adaptive", "solver.rtol": r})
            for r in plan.rtols]
    out += [Setting(f"fixed dt {dt:g} s", "fixed", {"solver.method": "fixed", "solver.dt": dt})
            for dt in plan.fixed_dts]
    reduced = list(REDUCED)
    if slip_law(scene.effects.friction) is not None:        # each other registered slip law
        reduced += [(f"{other} slip instead of {scene.effects.friction}",
                     {"effects.friction": other}) for other, law in SLIP_LAWS.items()
                    if law is not None and law is not slip_law(scene.effects.friction)]
    out += [Setting(label, "reduced", ov) for label, ov in reduced if changes(scene, ov)]
    return out


def accuracy_observables(result) -> dict:
    """Sweep-worker hook: the orbit (and contact force) right after the fault, for comparison."""
    t = result.t
    t_f = result.t_fault or 0.0
    sel = (t >= t_f) & (t <= t_f + CAPTURE_S)
    return dict(t=t[sel].tolist(),
                orbit={p: result.orbit(p)[sel].tolist() for p in ("RB1", "RB2")},
                force={p: result.contact_force(p)[sel].tolist() for p in ("RB1", "RB2")})


def plan_runs(plan: AccuracyPlan, source: str, overrides: dict, modes: tuple[int, ...] = (),
              tolerances: bool = True):
    """The settings (tolerance rows, then mode rows) and their runs, every setting on the same
    perturbed drops."""
    from ..scene import load_scene
    from .study.ensemble import perturbations
    from .sweep import Run
    scene = load_scene(source, overrides)
    check_fault_in_span(scene, plan)
    members = perturbations(plan.members, scene.amb.off_time, plan.seed)
    extra = {} if plan.t_end is None else {"solver.t_end": plan.t_end}
    rows = (settings(plan, scene) if tolerances else []) + (mode_settings(scene, modes) if modes else [])
    runs = [Run.of(source, {**overrides, **extra, **m, **s.overrides}, setting=s.label, member=k)
            for s in rows for k, m in enumerate(members)]
    return rows, runs


# ------------------------------------------------------------------------ elastic modes --
def cutoff_for(freqs: np.ndarray, n: int) -> float:
    """A ``flexible.mode_cutoff_hz`` that keeps exactly the ``n`` lowest bending modes (the
    geometric mean of the n-th and the next frequency; half the first for none)."""
    if n == 0:
        return float(0.5 * freqs[0])
    return float(np.sqrt(freqs[n - 1] * freqs[n]))


def mode_info(scene) -> dict:
    """The retained elastic modes of a flexible scene: bending and static correction modes per
    plane, all of them, the highest modal frequency [Hz] (0 without modes)."""
    from ..flexible.shafts import drop_rotor
    fm = drop_rotor(scene)
    return dict(bending=fm.n_bending, static=fm.n_correction, modes=fm.n_modes,
                highest_mode_hz=float(fm.omega.max() / (2 * np.pi)) if fm.n_modes else 0.0)


def mode_counts(text: str | None, quick: bool) -> tuple[int, ...]:
    """``--modes`` as typed: ``auto`` (:data:`MODE_COUNTS`, quick: :data:`QUICK_MODE_COUNTS`)
    or comma-separated bending-mode counts."""
    if text is None:
        return ()
    if text == "auto":
        return QUICK_MODE_COUNTS if quick else MODE_COUNTS
    try:
        counts = tuple(sorted({int(v) for v in text.split(",")}))
    except ValueError:
        raise AccuracyError(f"--modes {text}: allowed 'auto' or comma-separated bending-mode "
                            f"counts, e.g. 0,2,5") from None
    if not counts or counts[0] < 0:
        raise AccuracyError(f"--modes {text}: the counts must be >= 0")
    return counts


def mode_settings(scene, counts: tuple[int, ...]) -> list[Setting]:
    """The --modes rows: each bending-mode count with the static correction modes, then
    without; the most the packed arrays hold is always among them (the sweep's reference,
    with the static modes: the first row)."""
    from ..flexible.floating import MAX_MODES
    from ..flexible.shafts import bending_frequencies
    if scene.rotor.model != "flexible":
        raise AccuracyError(f"--modes: rotor.model = {scene.rotor.model!r}: the mode sweep needs a"
                            f" flexible rotor (rotor.model = 'flexible', e.g. --scene paper-flexible)")
    freqs = bending_frequencies(scene)
    out = []
    for static in (True, False):
        probe = mode_info(scene.with_overrides({"flexible.mode_cutoff_hz": cutoff_for(freqs, 0),
                                                "flexible.static_modes": static}))
        most = min(MAX_MODES - probe["static"], len(freqs) - 1)
        if max(counts) > most:
            raise AccuracyError(f"--modes {','.join(map(str, counts))}: allowed at most {most}"
                                f" bending modes {'with' if static else 'without'} the"
                                f" {probe['static']} static correction modes (at most"
                                f" {MAX_MODES} elastic modes per plane)")
        rows = []
        for n in sorted(set(counts) | {most if static else max(counts)}, reverse=True):
            ov = {"flexible.mode_cutoff_hz": cutoff_for(freqs, n), "flexible.static_modes": static}
            info = mode_info(scene.with_overrides(ov))
            assert info["bending"] == n, (n, info)
            bending = f"{n} bending mode" + ("" if n == 1 else "s")
            label = f"{n} bending + {info['static']} static modes" if static else \
                f"{bending}, no static"
            rows.append(Setting(label, "modes", ov, info))
        out += rows
    return out


def analyse_modes(plan: AccuracyPlan, rows: list[Setting], outcomes: list) -> dict:
    """Cost and errors of each mode row against the row with the most modes (the first), drop
    by drop; whole-run errors over every drop (the runs differ in their model, not in their
    integration: no drop is left out as chaotic, so a late whirl's peaks may dominate)."""
    by = {(o.run.label["setting"], o.run.label["member"]): o for o in outcomes}
    ref_row = rows[0]
    refs = {k: by[(ref_row.label, k)] for k in range(plan.members)}
    bad = [k for k, o in refs.items() if not o.ok]
    if bad:
        raise AccuracyError(f"the mode sweep's reference ({ref_row.label}) failed for drop(s) "
                            f"{', '.join(map(str, bad))}: {refs[bad[0]].error.splitlines()[0]}")
    table = []
    for s in rows:
        runs = [by[(s.label, k)] for k in range(plan.members)]
        per = [dict(member=k, wall_time_s=o.metrics["wall_time_s"], steps=o.metrics["steps"],
                    rhs_evaluations=o.metrics["rhs_evaluations"], chaotic=False, **score(o, refs[k]))
               for k, o in enumerate(runs) if o.ok]
        row = dict(setting=s.label, kind=s.kind, overrides=s.overrides, **s.info,
                   failed=[dict(member=k, error=o.error.splitlines()[0])
                           for k, o in enumerate(runs) if not o.ok])
        if per:
            row.update(wall_time_s=float(np.median([p["wall_time_s"] for p in per])),
                       steps=int(np.median([p["steps"] for p in per])),
                       rhs_evaluations=int(np.median([p["rhs_evaluations"] for p in per])),
                       errors=_aggregate(per, []), per_member=per)
        table.append(row)
    return dict(reference=ref_row.label, rows=table, members=plan.members)


def check_fault_in_span(scene, plan: AccuracyPlan) -> None:
    """Every drop's fault (jittered by up to ``JITTER_S``) and the ``CAPTURE_S`` scored after it
    must lie inside the compared runs."""
    from .study.ensemble import JITTER_S
    if scene.effects.amb == "none":                 # no AMBs: the rotor drops at t = 0
        return
    t_end = scene.solver.t_end if plan.t_end is None else plan.t_end
    limit = t_end - CAPTURE_S - JITTER_S
    if scene.amb.off_time > limit:
        span, fix = (("--quick runs", "drop --quick") if plan.t_end is not None else
                     ("solver.t_end =", "raise solver.t_end"))
        raise AccuracyError(
            f"amb.off_time = {scene.amb.off_time:g} s: the fault (± {JITTER_S * 1e3:g} ms between"
            f" drops) and the {CAPTURE_S * 1e3:g} ms scored after it must lie inside the compared"
            f" span ({span} {t_end:g} s); set amb.off_time <= {max(limit, 0.0):g} s or {fix}")


# ------------------------------------------------------------------------------ scoring --
def _window(o, t0: float) -> tuple[np.ndarray, dict, dict]:
    t = np.asarray(o.extra["t"])
    sel = (t >= t0 - 1e-12) & (t <= t0 + WINDOW_S + 1e-12)
    orbit = {p: np.asarray(v)[sel] for p, v in o.extra["orbit"].items()}
    force = {p: np.asarray(v)[sel] for p, v in o.extra["force"].items()}
    return t[sel], orbit, force


def score(o, ref) -> dict:
    """Errors of one run against the reference run of the same drop."""
    t_fc = ref.metrics["first_contact_time_s"]
    # the drop's numbers up to the end of its validity (the same drop at each setting)
    err = {f"{name}_rel": _rel(worst_plane(o.metrics, key, True), worst_plane(ref.metrics, key, True))
           for name, key in EXTREMES}
    err["whirl_agrees"] = whirled(o.metrics) == whirled(ref.metrics)
    fc = o.metrics["first_contact_time_s"]
    err["first_contact_time_abs_us"] = (abs(fc - t_fc) * 1e6 if fc is not None and t_fc is not None
                                        else None)
    if t_fc is None:
        err.update(trajectory_um=None, early_peak_force_rel=None, early_max_displacement_rel=None)
        return err
    t_a, orb_a, f_a = _window(o, t_fc)
    t_b, orb_b, f_b = _window(ref, t_fc)
    n = min(len(t_a), len(t_b))
    if n == 0 or not np.allclose(t_a[:n], t_b[:n]):
        raise ValueError("runs were sampled at different times; compare at one output rate")
    err["trajectory_um"] = max(float(np.hypot(*(orb_a[p][:n] - orb_b[p][:n]).T).max() * 1e6)
                               for p in orb_a)
    err["early_peak_force_rel"] = _rel(max(f_a[p][:n].max() for p in f_a),
                                       max(f_b[p][:n].max() for p in f_b))
    err["early_max_displacement_rel"] = _rel(
        max(np.hypot(*orb_a[p][:n].T).max() for p in orb_a),
        max(np.hypot(*orb_b[p][:n].T).max() for p in orb_b))
    return err


def _na(x: float | None) -> str:
    """A whole-run peak for the report, "n/a" where the drop left the contact laws' validity."""
    return "n/a" if x is None else f"{x:.0f}"


def _rel(a: float | None, b: float | None) -> float | None:
    """Relative error of ``a`` against ``b``; None where either is missing (no ball loads)."""
    if a is None or b is None:
        return None
    return abs(a - b) / abs(b) if b else abs(a - b)


ERROR_KEYS = WHOLE_KEYS + ("first_contact_time_abs_us", "trajectory_um", "early_peak_force_rel",
                           "early_max_displacement_rel")


def analyse(plan: AccuracyPlan, rows: list, outcomes: list) -> dict:
    """Per-setting cost and errors against the reference; the recommended setting."""
    by = {(o.run.label["setting"], o.run.label["member"]): o for o in outcomes}
    ref_label = rows[0].label
    refs = {k: by[(ref_label, k)] for k in range(plan.members)}
    _check_references(refs, plan.reference_rtol)
    # drops whose whole-run extremes are not converged at the reference tolerance
    check = next((s.label for s in rows if s.kind == "adaptive"
                  and np.isclose(s.overrides["solver.rtol"], plan.reference_rtol * 10)), None)
    chaotic = []
    for k, ref in refs.items():
        o = by.get((check, k)) if check else None
        if o is not None and o.ok:
            s = score(o, ref)
            if max(s[key] or 0.0 for key in WHOLE_KEYS) > CHAOS_REL:
                chaotic.append(k)
    table = []
    for s in rows:
        runs = [by[(s.label, k)] for k in range(plan.members)]
        ok = [(k, o) for k, o in enumerate(runs) if o.ok]
        per = []
        for k, o in ok:
            e = score(o, refs[k])
            per.append(dict(member=k, wall_time_s=o.metrics["wall_time_s"],
                            rhs_evaluations=o.metrics["rhs_evaluations"], chaotic=k in chaotic,
                            command=o.run.to_dict()["command"], **e))
        row = dict(setting=s.label, kind=s.kind, overrides=s.overrides,
                   failed=[dict(member=k, error=o.error.splitlines()[0]) for k, o in enumerate(runs)
                           if not o.ok])
        if per:
            row.update(wall_time_s=float(np.median([p["wall_time_s"] for p in per])),
                       rhs_evaluations=int(np.median([p["rhs_evaluations"] for p in per])),
                       errors=_aggregate(per, chaotic), per_member=per)
        table.append(row)
    best, why = recommend(table)
    ref_rows = [dict(member=k, command=o.run.to_dict()["command"],
                     wall_time_s=o.metrics["wall_time_s"], rhs_evaluations=o.metrics["rhs_evaluations"],
                     **{key: worst_plane(o.metrics, key, True) for _, key in EXTREMES},
                     first_contact_time_s=o.metrics["first_contact_time_s"],
                     backward_whirl=whirled(o.metrics), chaotic=k in chaotic)
                for k, o in refs.items()]
    return dict(reference=dict(setting=ref_label, rtol=plan.reference_rtol, members=ref_rows,
                               chaotic_members=chaotic, chaos_check=check),
                rows=table, recommended=best, recommended_reason=why,
                criterion=(f"cheapest full-fidelity setting (fewest rhs evaluations) whose peak contact "
                           f"force, max displacement, peak bearing load and max ball load stay within "
                           f"{100 * TOLERANCE:g} % of the reference over the whole run for every drop "
                           f"whose reference is converged, and whose peak force and max displacement "
                           f"do over the first {WINDOW_S * 1e3:g} ms after first contact for every "
                           f"drop"))


def _check_references(refs: dict, rtol: float) -> None:
    """Without its reference run no drop can be scored: stop, naming the drop and the fix."""
    bad = [k for k, o in refs.items() if not o.ok]
    if bad:
        first = refs[bad[0]]
        raise AccuracyError(
            f"the reference runs (adaptive rtol {rtol:g}) failed for drop(s)"
            f" {', '.join(map(str, bad))}: {first.error.splitlines()[0]}. The reference tolerance is"
            f" fixed by `rotordrop accuracy`, so change the other setting named there (e.g. a larger"
            f" --set solver.max_steps); first failed drop: {first.run.to_dict()['command']}")


def _aggregate(per: list[dict], chaotic: list[int]) -> dict:
    out = {}
    for key in ERROR_KEYS:
        vals = [p[key] for p in per if p[key] is not None]
        calm = [p[key] for p in per if p[key] is not None and p["member"] not in chaotic]
        out[key] = dict(median=float(np.median(vals)) if vals else None,
                        max=float(np.max(vals)) if vals else None,
                        max_converged=float(np.max(calm)) if calm else None)
    out["whirl_agreement"] = sum(p["whirl_agrees"] for p in per) / len(per)
    return out


def _passes(row: dict) -> bool:
    e = row.get("errors")
    if not e or row["failed"]:
        return False
    whole = [e[k]["max_converged"] for k in WHOLE_KEYS]
    early = [e[k]["max"] for k in ("early_peak_force_rel", "early_max_displacement_rel")]
    return all(v is None or v <= TOLERANCE for v in whole + early)


def recommend(table: list[dict]) -> tuple[str | None, str]:
    """The cheapest full-fidelity row that meets the criterion, and why (or None)."""
    ok = [r for r in table if r["kind"] in ("adaptive", "fixed") and _passes(r)]
    if not ok:
        return None, "no solver setting met the criterion"
    best = min(ok, key=lambda r: r["rhs_evaluations"])
    return best["setting"], (f"{best['rhs_evaluations']} rhs evaluations and {best['wall_time_s']:.3f} s "
                             f"wall per run (median)")


# ------------------------------------------------------------------------------ outputs --
def write_outputs(a: dict, out: Path, meta: dict) -> list[Path]:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    paths = [out / "accuracy.json", out / "accuracy.md", out / "pareto.png"]
    paths[0].write_text(json.dumps({**a, **meta}, indent=1, default=float))

    rows = [r for r in a["rows"] if "errors" in r and r["kind"] != "reference"]   # error 0 by definition
    fig, axes = plt.subplots(1, 2, figsize=(13, 5), constrained_layout=True)
    marks = {"adaptive": "C0o", "fixed": "C1s", "reduced": "C3^"}
    panels = ((axes[0], "trajectory_um", "max orbit error, first 20 ms after contact [µm]"),
              (axes[1], "peak_contact_force_rel", "peak-force error, whole run [%] (worst converged drop)"))
    for ax, key, label in panels:
        for kind, mk in marks.items():
            pts = [(r["wall_time_s"], _plot_err(r, key)) for r in rows if r["kind"] == kind]
            pts = [p for p in pts if p[1] is not None]
            if pts:
                ax.plot(*zip(*pts), mk, label=kind, ms=6)
        for r in rows:
            v = _plot_err(r, key)
            if v is not None:
                ax.annotate(r["setting"].replace("adaptive ", "").replace("reference ", "ref "),
                            (r["wall_time_s"], v), fontsize=6, xytext=(3, 2),
                            textcoords="offset points")
        front = _pareto([(r["wall_time_s"], _plot_err(r, key)) for r in rows
                         if r["kind"] in ("adaptive", "fixed") and _plot_err(r, key) is not None])
        if front:
            ax.plot(*zip(*front), "C0-", lw=0.8, alpha=0.6)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time per run [s] (median)")
        ax.set_ylabel(label)
        ax.legend(fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
    if a["recommended"]:
        axes[1].axhline(100 * TOLERANCE, color="k", ls=":", lw=0.8)
    fig.suptitle(f"What accuracy costs: scene {meta['scene']}, {len(a['reference']['members'])} drops, "
                 f"{meta['t_end']:g} s simulated each, errors against {a['reference']['setting']}")
    fig.savefig(paths[2], dpi=110)
    plt.close(fig)
    paths[1].write_text(markdown(a, meta))
    return paths


FLOOR = 1e-6      # plotted in place of an exact zero on log axes


def _plot_err(r: dict, key: str):
    e = r["errors"][key]
    v = e["max_converged"] if key.endswith("_rel") else e["max"]
    if v is None:
        return None
    v = 100 * v if key.endswith("_rel") else v
    return max(v, FLOOR)


def _pareto(pts):
    front, best = [], float("inf")
    for x, y in sorted(pts):
        if y < best:
            front.append((x, y))
            best = y
    return front


def markdown(a: dict, meta: dict) -> str:
    ref = a["reference"]
    L = [f"# Accuracy and cost: scene `{meta['scene']}`\n",
         f"{len(ref['members'])} drops (rotor angle at the fault and fault time perturbed), "
         f"{meta['t_end']:g} s simulated each; reference: {ref['setting']}. Errors are against the "
         f"reference run of the same drop; 'worst' is over drops (for whole-run extremes, over the "
         f"drops whose reference is converged: {len(ref['members']) - len(ref['chaotic_members'])} "
         f"of {len(ref['members'])}; the others are chaotic: a peak differs by more than "
         f"{100 * CHAOS_REL:g} % between the reference and a 10× looser tolerance).\n",
         "| setting | wall per run [s] | wall per simulated s [s] | rhs evaluations | peak force err, "
         "worst [%] | max disp err, worst [%] | bearing load err, worst [%] | max ball load err, "
         "worst [%] | first contact err [µs] | orbit err, 20 ms [µm] | early peak force err [%] | "
         "whirl decision agrees |",
         "|---" * 12 + "|"]
    own = a["scene_setting"]["row"]
    for r in a["rows"]:
        mark = (" **(recommended)**" if r["setting"] == a["recommended"] else "") + (
            " *(scene's setting)*" if r["setting"] == own else "")
        if "errors" not in r:
            L.append(f"| {r['setting']}{mark} | failed: {r['failed'][0]['error']} " + "|" * 11)
            continue
        e = r["errors"]
        pct = lambda k, w="max_converged": "–" if e[k][w] is None else f"{100 * e[k][w]:.3g}"  # noqa: E731
        num = lambda k: "–" if e[k]["max"] is None else f"{e[k]['max']:.3g}"  # noqa: E731
        fail = f" ({len(r['failed'])} failed)" if r["failed"] else ""
        L.append(f"| {r['setting']}{mark}{fail} | {r['wall_time_s']:.3f} | "
                 f"{r['wall_time_s'] / meta['t_end']:.3f} | {r['rhs_evaluations']} | "
                 + "".join(f"{pct(k)} | " for k in WHOLE_KEYS)
                 + f"{num('first_contact_time_abs_us')} | {num('trajectory_um')} | "
                 f"{pct('early_peak_force_rel', 'max')} | {100 * e['whirl_agreement']:.0f} % |")
    L += ["", "![Pareto plot](pareto.png)", "",
          f"**Recommended**: {a['recommended'] or 'none'} — {a['recommended_reason']}. "
          f"Criterion: {a['criterion']}.", "", f"**Scene's setting**: {scene_setting_text(a)}.",
          "", "Reduced-fidelity rows run at the scene's own solver settings; their errors are model "
          "differences, not integration errors.", "", "Reference drops:", ""]
    for m in ref["members"]:
        L.append(f"- drop {m['member']}: peak {_na(m['peak_contact_force_N'])} N, bearing load "
                 f"{_na(m['peak_bearing_load_N'])} N, max displacement {_na(m['max_displacement_um'])} µm,"
                 f" whirl {'yes' if m['backward_whirl'] else 'no'}"
                 f"{', chaotic' if m['chaotic'] else ''}: `{m['command']}`")
    return "\n".join(L) + "\n"


def scene_setting(scene, rows: list[Setting]) -> dict:
    """The scene's own solver setting and the full-fidelity row that runs it (None if none)."""
    from .sweep import changes
    sv = scene.solver
    row = next((s.label for s in rows if s.full_fidelity and not changes(scene, s.overrides)), None)
    return dict(method=sv.method, rtol=sv.rtol, dt=sv.dt, row=row)


def scene_setting_text(a: dict) -> str:
    s = a["scene_setting"]
    own = (f"solver.method = adaptive, solver.rtol = {s['rtol']:g}" if s["method"] == "adaptive"
           else f"solver.method = fixed, solver.dt = {s['dt']:g} s")
    return own + (f" (row '{s['row']}')" if s["row"] else " (not among the rows)")


# ------------------------------------------------------------------------ mode outputs --
MODE_COLUMNS = ("setting", "bending", "static", "modes", "highest_mode_hz", "wall_time_s", "steps",
                "rhs_evaluations", "peak_contact_force_rel", "max_displacement_rel",
                "early_peak_force_rel", "trajectory_um", "whirl_agreement")


def _mode_value(r: dict, key: str):
    if key in r:
        return r[key]
    e = r.get("errors")
    if e is None:
        return None
    return e[key] if key == "whirl_agreement" else e[key]["max"]


def write_mode_outputs(m: dict, out: Path, meta: dict) -> list[Path]:
    """modes.csv (one row per mode setting, worst errors over the drops) and modes.png (error
    against wall time, and steps against the number of modes)."""
    import csv
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    paths = [out / "modes.csv", out / "modes.png"]
    with paths[0].open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(MODE_COLUMNS)
        for r in m["rows"]:
            w.writerow(["" if (v := _mode_value(r, k)) is None else v for k in MODE_COLUMNS])
    rows = [r for r in m["rows"] if "errors" in r]
    fig, axes = plt.subplots(1, 2, figsize=(13, 5), constrained_layout=True)
    for static, mk, name in ((True, "C0o-", "with static correction modes"),
                             (False, "C1s--", "bending modes only")):
        sel = sorted((r for r in rows if (r["static"] > 0) == static), key=lambda r: r["modes"])
        if not sel:
            continue
        scored = [r for r in sel if r["setting"] != m["reference"]]   # error 0 by definition
        err = [max(100 * (_mode_value(r, "peak_contact_force_rel") or 0.0), FLOOR) for r in scored]
        axes[0].plot([r["wall_time_s"] for r in scored], err, mk, label=name, ms=6)
        for r, v in zip(scored, err):
            axes[0].annotate(f"{r['bending']}+{r['static']}", (r["wall_time_s"], v), fontsize=7,
                             xytext=(3, 2), textcoords="offset points")
        axes[1].plot([r["modes"] for r in sel], [r["steps"] for r in sel], mk, label=name, ms=6)
        for r in sel:
            axes[1].annotate(f"{r['highest_mode_hz'] / 1e3:.1f} kHz", (r["modes"], r["steps"]),
                             fontsize=7, xytext=(3, -9), textcoords="offset points")
    axes[0].set_xscale("log")
    axes[0].set_yscale("log")
    axes[0].set_xlabel("wall time per run [s] (median)")
    axes[0].set_ylabel("peak contact force error, whole run [%] (worst drop)")
    axes[1].set_xlabel("elastic modes per bending plane (bending + static; labels: the highest"
                       " mode's frequency)")
    axes[1].set_ylabel("integration steps per run (median)")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"What the elastic modes cost: scene {meta['scene']}, {m['members']} drops, "
                 f"{meta['t_end']:g} s simulated each, errors against {m['reference']}")
    fig.savefig(paths[1], dpi=110)
    plt.close(fig)
    return paths


def modes_markdown(m: dict, meta: dict) -> str:
    L = ["## Retained elastic modes\n",
         f"The same {m['members']} drops on the flexible rotor with fewer elastic modes per bending "
         f"plane (`flexible.mode_cutoff_hz` between two free-free bending frequencies, "
         f"`flexible.static_modes` on and off), at the scene's own solver setting; errors against "
         f"the run with the most modes ({m['reference']}), worst over the drops. The highest "
         f"retained mode sets the explicit integrator's step: what a mode costs is its "
         f"frequency.\n",
         "| modes | bending | static | highest mode [Hz] | wall per run [s] | steps | rhs "
         "evaluations | peak force err, whole run [%] | max disp err [%] | early peak force err "
         "[%] | orbit err, 20 ms [µm] | whirl decision agrees |",
         "|---" * 12 + "|"]
    for r in m["rows"]:
        head = f"| {r['setting']} | {r['bending']} | {r['static']} | {r['highest_mode_hz']:.0f} | "
        if "errors" not in r:
            L.append(head + f"failed: {r['failed'][0]['error']} " + "|" * 8)
            continue
        e = r["errors"]
        pct = lambda k: "–" if e[k]["max"] is None else f"{100 * e[k]['max']:.3g}"  # noqa: E731
        um = "–" if e["trajectory_um"]["max"] is None else f"{e['trajectory_um']['max']:.3g}"
        fail = f" ({len(r['failed'])} failed)" if r["failed"] else ""
        L.append(head + f"{r['wall_time_s']:.3f}{fail} | {r['steps']} | {r['rhs_evaluations']} | "
                 f"{pct('peak_contact_force_rel')} | {pct('max_displacement_rel')} | "
                 f"{pct('early_peak_force_rel')} | {um} | {100 * e['whirl_agreement']:.0f} % |")
    L += ["", "![Cost of the elastic modes](modes.png)", ""]
    return "\n".join(L)


# ---------------------------------------------------------------------------------- CLI --
def run_accuracy(source: str, overrides: dict, out_dir, quick: bool = False,
                 jobs: int | None = None, progress: bool = True, modes: tuple[int, ...] = (),
                 tolerances: bool = True) -> tuple[dict, list[Path]]:
    """The accuracy study of a scene: solver settings and reduced models against a tight
    reference (``tolerances``), and with ``modes`` (bending-mode counts, a flexible rotor) the
    cost of the retained elastic modes; outputs in ``out_dir``."""
    from ..scene import load_scene
    from .sweep import run_sweep
    if not tolerances and not modes:
        raise AccuracyError("--modes-only needs mode counts (--modes)")
    plan = AccuracyPlan.make(quick)
    rows, runs = plan_runs(plan, source, overrides, modes, tolerances)
    t0 = time.perf_counter()
    outcomes = run_sweep(runs, accuracy_observables, jobs=jobs, desc="accuracy", progress=progress)
    scene = load_scene(source, overrides)
    solver_rows = [r for r in rows if r.kind != "modes"]
    a = dict(rows=[], recommended=None)
    if tolerances:
        a = analyse(plan, solver_rows, outcomes)
        a["scene_setting"] = scene_setting(scene, solver_rows)
    if modes:
        a["modes"] = analyse_modes(plan, [r for r in rows if r.kind == "modes"], outcomes)
    meta = dict(scene=source, overrides=overrides, quick=quick,
                t_end=plan.t_end if plan.t_end is not None else scene.solver.t_end,
                wall_time_s=time.perf_counter() - t0)
    out = Path(out_dir)
    if tolerances:
        paths = write_outputs(a, out, meta)
    else:
        out.mkdir(parents=True, exist_ok=True)
        paths = [out / "accuracy.json", out / "accuracy.md"]
        paths[0].write_text(json.dumps({**a, **meta}, indent=1, default=float))
        paths[1].write_text(f"# Elastic modes and cost: scene `{meta['scene']}`\n\n")
    if modes:
        paths[1].write_text(paths[1].read_text() + "\n" + modes_markdown(a["modes"], meta))
        paths += write_mode_outputs(a["modes"], out, meta)
    return a, paths
