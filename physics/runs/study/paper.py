"""The paper's three studies (spec §7) as one batch of drops: friction, support stiffness,
support damping, plus the sensitivity of the results to every assumed [A] parameter.

:func:`plan_runs` turns a :class:`Plan` into :class:`physics.runs.sweep.Run` s (each labelled with the
study it belongs to), :func:`run_study` simulates them on a backend (keeping the full results of
the nominal drops the figures draw) and :func:`analyse` reduces
the outcomes to the numbers written to ``study.json``; :mod:`physics.runs.study.report` draws the
figures and writes the Markdown report.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...laws import slip_kinematic, slip_paper
from ...metrics import whirl_decision, worst_plane
from ...results import Result
from ...scene import Scene, SceneError, load_scene
from ...simulate import IntegrationError, simulate
from ..backend import Backend, Dispatch, run_drops
from ..sweep import Outcome, Run, changes, outcome_of, reproduce_command
from .checks import as_drop, beyond_validity, split_valid, warning_counts
from .ensemble import ENSEMBLE_KEYS, onset, perturbations, probability_curve
from .observables import drop_observables

SLIPS = (slip_paper.NAME, slip_kinematic.NAME)      # the study compares the two slip laws
#: the slip law the claims, the reproduce commands and the response figures use: the scenes'
#: default, whose friction only dissipates; the paper's eq. 19 runs beside it for comparison
PRIMARY_SLIP = slip_kinematic.NAME
STIFFNESS = (5e6, 5e7, 5e8)               # support stiffness study [N/m] (paper §V)
SOFT, BASE, STIFF = STIFFNESS             # soft (the ~600 µm statement), base case, stiff
DAMPING = (2790.0, 27900.0)               # support damping study [N s/m] (paper §V): low, high
# the keys the studies set themselves (a --set on them would be replaced in some drops and
# mislabel the rest); the scene's own values of HELD_KEYS are the ones the other studies hold
HELD_KEYS = ("contact.friction", "support.stiffness", "support.damping")
STUDY_KEYS = HELD_KEYS + ("effects.friction", "effects.bearing_friction") + ENSEMBLE_KEYS


@dataclass(frozen=True)
class Factor:
    """An assumed [A] parameter (or unit reading) and the plausible values tried for it."""
    name: str
    why: str                                    # what makes these values plausible
    settings: tuple[tuple[str, dict], ...]      # (label, overrides)


SENSITIVITY = (
    Factor("sleeve spin inertia [kg m²]",
           "steel sleeve 60.6/80 mm and 6016 inner ring, 22-40 mm long, plus a share of balls "
           "and cage: 0.7e-3 to 3e-3",
           (("0.7e-3", {"sleeve.spin_inertia": 0.7e-3}), ("3e-3", {"sleeve.spin_inertia": 3e-3}))),
    Factor("sleeve + inner ring mass [kg]", "same geometry: 0.5 to 1.2 kg",
           (("0.5", {"sleeve.mass": 0.5}), ("1.2", {"sleeve.mass": 1.2}))),
    Factor("housing + outer ring mass [kg]",
           "a bare bearing carrier (2-5 kg) up to the participating mass of an end shield of a "
           "100 kg-rotor machine (~30 kg)",
           tuple((f"{m:g}", {"support.housing_mass": m}) for m in (2.0, 5.0, 10.0, 20.0, 30.0))),
    Factor("bearing drag (Palmgren f_0)",
           "f_0 = 0.7 (grease, spec default) to 2 (oil bath, deep-groove); drag switched off",
           (("f0 = 2", {"bearing.f0": 2.0}), ("no drag", {"effects.bearing_friction": False}))),
    Factor("retainer-bearing planes [m]", "Fig. 2 is not dimensioned: ±0.30 to ±0.45 m, and an "
           "asymmetric rotor (RB2 at +0.30 m)",
           (("±0.30", {"positions.rb1": -0.30, "positions.rb2": 0.30}),
            ("±0.45", {"positions.rb1": -0.45, "positions.rb2": 0.45}),
            ("-0.38/+0.30", {"positions.rb1": -0.38, "positions.rb2": 0.30}))),
    Factor("AMB planes [m]", "inside the retainer planes: ±0.20 to ±0.33 m",
           (("±0.20", {"positions.amb1": -0.20, "positions.amb2": 0.20}),
            ("±0.33", {"positions.amb1": -0.33, "positions.amb2": 0.33}))),
    Factor("contact stiffness unit reading [N/m^1.1]",
           "the paper's 1e8 read in SI (1e8) or entered as 1e5 N/mm in an N-mm model (2.0e8)",
           (("1e8 (SI)", {"contact.stiffness": 1e8}), ("2e8 (N-mm)", {"contact.stiffness": 2e8}))),
)


@dataclass(frozen=True)
class Plan:
    """Grid and ensemble sizes of a study run (``full`` or ``quick``)."""
    frictions: tuple[float, ...]
    members: int
    sens_frictions: tuple[float, ...]
    sens_members: int
    soft_members: int
    figure_frictions: tuple[float, ...] = (0.10, 0.20, 0.30, 0.36, 0.39, 0.50)
    seed: int = 7

    @classmethod
    def make(cls, quick: bool = False) -> "Plan":
        if quick:
            return cls(_grid(0.10, 0.60, 0.05), 4, _grid(0.10, 0.50, 0.10), 2, 1)
        return cls(_grid(0.10, 0.60, 0.01), 16, _grid(0.10, 0.50, 0.02), 8, 4)


def _grid(lo: float, hi: float, step: float) -> tuple[float, ...]:
    n = int(round((hi - lo) / step))
    return tuple(round(lo + i * step, 4) for i in range(n + 1))


@dataclass
class StudyInput:
    """The base scene of the study and how to name it on a command line."""
    source: str = "paper"
    overrides: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        clash = [k for k in STUDY_KEYS if k in self.overrides]
        if clash:
            raise SceneError(f"study paper sets {', '.join(clash)} itself: --set is refused on "
                             f"{', '.join(STUDY_KEYS)} (the studies vary or perturb them); for other "
                             "values use `rotordrop study sweep --vary`")

    @property
    def scene(self) -> Scene:
        return load_scene(self.source, self.overrides)

    def run(self, extra: dict, observe: bool = True, **labels) -> Run:
        return Run.of(self.source, {**self.overrides, **extra}, observe=observe, **labels)


def plan_runs(plan: Plan, base: StudyInput) -> list[Run]:
    """Every drop of the study, labelled ``study`` = friction | stiffness | damping | sensitivity.
    The sensitivity drops are analysed by their metrics alone (:func:`_sensitivity`), so they skip
    the observables (``Run.observe``)."""
    scene = base.scene
    members = perturbations(plan.members, scene.amb.off_time, plan.seed)
    runs: list[Run] = []
    for slip in SLIPS:
        for drag in (True, False):
            for mu in plan.frictions:
                for k, m in enumerate(members):
                    runs.append(base.run({"effects.friction": slip, "effects.bearing_friction": drag,
                                          "contact.friction": mu, **m}, study="friction",
                                         slip=slip, drag=drag, friction=mu, member=k))
    for key, values, study in (("support.stiffness", STIFFNESS, "stiffness"),
                               ("support.damping", DAMPING, "damping")):
        for v in values:
            runs.append(base.run({key: v}, study=study, value=v, member=-1))
            for k, m in enumerate(members):
                runs.append(base.run({key: v, **m}, study=study, value=v, member=k))
    sens = perturbations(plan.sens_members, scene.amb.off_time, plan.seed + 1)
    soft = perturbations(plan.soft_members, scene.amb.off_time, plan.seed + 2)
    for factor, label, ov in sensitivity_settings(scene):
        for mu in plan.sens_frictions:
            for k, m in enumerate(sens):
                runs.append(base.run({**ov, "contact.friction": mu, **m}, False, study="sensitivity",
                                     factor=factor, setting=label, friction=mu, member=k))
        for k, m in enumerate(soft):
            runs.append(base.run({**ov, "support.stiffness": SOFT, **m}, False, study="sensitivity",
                                 factor=factor, setting=label, friction="soft", member=k))
    return runs


def sensitivity_settings(scene: Scene) -> list[tuple[str, str, dict]]:
    """(factor, label, overrides): the nominal scene first, then every value that differs from it."""
    out = [("nominal", "nominal", {})]
    for f in SENSITIVITY:
        out += [(f.name, label, ov) for label, ov in f.settings if changes(scene, ov)]
    return out


def run_study(plan: Plan, base: StudyInput, jobs: int | None = None, progress: bool = True,
              backend: Backend = Backend(), out=None, resume: bool = False
              ) -> tuple[list[Outcome], dict[str, dict[float, Result]], Dispatch]:
    """Simulate every drop of the plan; outcomes in plan order.

    The nominal drops of the support studies (``member`` -1) are drawn in the figures, so they
    run here in this process and their full results come back too, as ``{study: {value:
    result}}``; an error in one of them stops the study, as a figure cannot be drawn without it.
    The rest run on ``backend`` (:func:`physics.runs.backend.run_drops`; with ``out`` each finished
    drop is kept in ``out/drops``, and with ``resume`` only the missing ones run). A run that
    ended before the fault is a failed drop (:func:`physics.runs.study.checks.as_drop`).
    """
    runs = plan_runs(plan, base)
    nominal = {r: simulate_figure_drop(r, f"the nominal drop of the support {r.label['study']} study"
                                          f" (support.{r.label['study']} = {r.label['value']:g})")
               for r in runs if r.label["member"] == -1}
    swept, dispatch = run_drops([r for r in runs if r not in nominal], drop_observables, backend,
                                jobs=jobs, out=out, resume=resume, desc="study paper",
                                progress=progress)
    swept = iter(swept)
    outcomes = [as_drop(outcome_of(r, nominal[r], drop_observables) if r in nominal else next(swept))
                for r in runs]
    results: dict[str, dict[float, Result]] = {}
    for r, result in nominal.items():
        results.setdefault(r.label["study"], {})[r.label["value"]] = result
    return outcomes, results, dispatch


def simulate_figure_drop(run: Run, what: str) -> Result:
    """Simulate a drop a figure needs; its error stops the study, naming the drop (``what``)
    and the ``rotordrop drop`` command that re-runs it alone."""
    try:
        return simulate(run.to_scene())
    except (SceneError, IntegrationError) as exc:
        raise type(exc)(f"study paper: {what} (drawn in a figure) failed: {exc}; re-run it alone:"
                        f" {reproduce_command(run)}") from None


# ------------------------------------------------------------------------------ analysis --
def analyse(plan: Plan, base: StudyInput, outcomes: list[Outcome]) -> dict:
    """Reduce the outcomes to the study's numbers (everything in study.json except the claims)."""
    by = _index(outcomes)
    friction = _friction(plan, by.get("friction", []))
    scene = base.scene
    return dict(
        scene=base.source, overrides=base.overrides,
        held={k: scene.get(k) for k in HELD_KEYS},
        plan=dict(frictions=list(plan.frictions), members=plan.members,
                  sensitivity_frictions=list(plan.sens_frictions),
                  sensitivity_members=plan.sens_members, soft_members=plan.soft_members,
                  seed=plan.seed),
        friction_threshold={s: friction["onset"][f"{s}, drag on"]["threshold"] for s in SLIPS},
        friction_onset=friction["onset"],
        whirl_probability=friction["probability"],
        friction_observables=friction["observables"],
        slip_law_agreement=friction["slip_agreement"],
        support_stiffness=_support(by.get("stiffness", []), "stiffness"),
        support_damping=_support(by.get("damping", []), "damping"),
        sensitivity=_sensitivity(by.get("sensitivity", []), sensitivity_settings(scene)),
        runs=dict(total=len(outcomes), failed=sum(not o.ok for o in outcomes)),
        warnings=dict(total=warning_counts(outcomes),
                      **{study: warning_counts(outs) for study, outs in by.items()}),
        failures=[dict(command=o.run.to_dict()["command"], error=o.error, labels=o.run.label)
                  for o in outcomes if not o.ok],
    )


def _index(outcomes: list[Outcome]) -> dict[str, list[Outcome]]:
    by: dict[str, list[Outcome]] = {}
    for o in outcomes:
        by.setdefault(o.run.label["study"], []).append(o)
    return by


def _whirl(o: Outcome) -> bool | None:
    return whirl_decision(o.metrics)


def _friction(plan: Plan, outs: list[Outcome]) -> dict:
    probability, onsets, observables = [], {}, {}
    for slip in SLIPS:
        for drag in (True, False):
            grp = [o for o in outs if o.run.label["slip"] == slip and o.run.label["drag"] == drag]
            ran = [o for o in grp if o.ok]
            ok = [o for o in ran if _whirl(o) is not None]     # the undecided count apart
            mus = [o.run.label["friction"] for o in ok]
            whirls = [_whirl(o) for o in ok]
            curve = probability_curve(mus, whirls)
            decided = {c["value"]: c for c in curve}
            # every μ of the grid gets a row: one whose drops all left validity before their whirl
            # verdict has no probability (None) but its undecided count
            for mu in sorted({round(o.run.label["friction"], 6) for o in grp}):
                c = decided.get(mu, dict(value=mu, probability=None, runs=0, whirls=0))
                at = [o for o in grp if round(o.run.label["friction"], 6) == mu]
                c["failed"] = sum(1 for o in at if not o.ok)
                probability.append(dict(friction=c["value"], slip=slip, bearing_friction=drag,
                                        probability=c["probability"], runs=c["runs"],
                                        whirls=c["whirls"], failed=c["failed"],
                                        undecided=sum(1 for o in at if o.ok and _whirl(o) is None)))
            key = f"{slip}, drag {'on' if drag else 'off'}"
            if curve:
                onsets[key] = onset([c["value"] for c in curve], [c["probability"] for c in curve],
                                    mus, whirls).to_dict()
            else:
                onsets[key] = dict(threshold=None)
            observables[key] = _per_friction(ok)
    return dict(probability=probability, onset=onsets, observables=observables,
                slip_agreement=_slip_agreement(outs))


def _slip_agreement(outs: list[Outcome]) -> float | None:
    """Fraction of drops (same mu, drag and member) whose whirl decision both slip laws share."""
    dec = {(o.run.label["slip"], o.run.label["drag"], o.run.label["friction"], o.run.label["member"]):
           _whirl(o) for o in outs if o.ok}
    paper, kinematic = SLIPS
    pairs = [(v, dec[(kinematic,) + k[1:]]) for k, v in dec.items()
             if k[0] == paper and (kinematic,) + k[1:] in dec]
    return sum(a == b for a, b in pairs) / len(pairs) if pairs else None


def _per_friction(ok: list[Outcome]) -> list[dict]:
    """Medians per friction value, split into whirling and non-whirling members."""
    rows = []
    for mu in sorted({o.run.label["friction"] for o in ok}):
        row: dict = dict(friction=mu)
        for tag, sel in (("whirl", True), ("no_whirl", False)):
            grp = [o for o in ok if o.run.label["friction"] == mu and _whirl(o) == sel]
            row[tag] = _medians(grp) if grp else None
        rows.append(row)
    return rows


def _medians(grp: list[Outcome]) -> dict:
    """Medians over the drops of ``grp`` within the contact laws' validity; ``runs`` counts them
    all, ``beyond_validity`` those left out."""
    runs = len(grp)
    grp, beyond = split_valid(grp)

    def med(vals):
        vals = [v for v in vals if v is not None]
        return float(np.median(vals)) if vals else None
    return dict(
        runs=runs, beyond_validity=beyond,
        max_displacement_um=med([worst_plane(o.metrics, "max_displacement_um") for o in grp]),
        max_y_displacement_um=med([worst_plane(o.metrics, "max_y_displacement_um") for o in grp]),
        max_x_um=med([o.extra["max_x_um"] for o in grp]),
        peak_contact_force_N=med([worst_plane(o.metrics, "peak_contact_force_N") for o in grp]),
        mean_late_force_N=med([o.extra["mean_late_force_N"] for o in grp]),
        t_max_response_s=med([o.extra["t_max_response_s"] for o in grp]),
        sleeve_spin_up_s=med([o.extra["sleeve_spin_up_s"] for o in grp]),
        bounces_after_drop=med([o.extra["planes"]["RB1"]["bounces_after_drop"] for o in grp]),
        force_settling_s=med([o.extra["force_settling_s"] for o in grp]),
        radial_speed_rms_mm_s=med([o.extra["radial_speed_rms_mm_s"] for o in grp]),
        separations=med([o.extra["separations"] for o in grp]),
    )


def _support(outs: list[Outcome], what: str) -> list[dict]:
    """Nominal run and ensemble statistics for each support stiffness / damping value. A nominal
    drop beyond the contact laws' validity keeps only its whirl decision and
    ``beyond_validity_at_s``; ensemble statistics are over the drops within it (``beyond_validity``
    counts the others, which the whirl probability includes)."""
    rows = []
    for v in sorted({o.run.label["value"] for o in outs}):
        grp = [o for o in outs if o.run.label["value"] == v]
        nominal = next((o for o in grp if o.run.label["member"] == -1), None)
        ens = [o for o in grp if o.run.label["member"] >= 0 and o.ok]
        row: dict = {what: v}
        if nominal is not None and nominal.ok and beyond_validity(nominal.metrics):
            row.update(beyond_validity_at_s=nominal.metrics["left_validity_at_s"],
                       backward_whirl=whirl_decision(nominal.metrics),
                       command=nominal.run.to_dict()["command"])
        elif nominal is not None and nominal.ok:
            m, x = nominal.metrics, nominal.extra
            row.update(
                max_displacement_um=worst_plane(nominal.metrics, "max_displacement_um"),
                max_y_displacement_um=worst_plane(nominal.metrics, "max_y_displacement_um"),
                peak_contact_force_N=worst_plane(nominal.metrics, "peak_contact_force_N"),
                backward_whirl=whirl_decision(m),
                t_max_response_s=x["t_max_response_s"], force_settling_s=x["force_settling_s"],
                mean_late_force_N=x["mean_late_force_N"], separations=x["separations"],
                radial_speed_rms_mm_s=x["radial_speed_rms_mm_s"],
                command=nominal.run.to_dict()["command"])
        else:
            row.update(error=nominal.error if nominal is not None else "missing")
        if ens:
            valid, beyond = split_valid(ens)
            decided = [w for w in map(_whirl, ens) if w is not None]
            row["ensemble"] = dict(members=len(ens), beyond_validity=beyond,
                                   whirl_probability=(sum(decided) / len(decided) if decided
                                                      else None),
                                   whirl_undecided=len(ens) - len(decided),
                                   **_ensemble_stats(valid))
            for tag, sel in (("whirl", True), ("no_whirl", False)):
                grp_ = [o for o in valid if _whirl(o) == sel]
                row["ensemble"][tag] = dict(
                    members=len(grp_), beyond_validity=sum(_whirl(o) == sel for o in ens) - len(grp_),
                    **_ensemble_stats(grp_))
        rows.append(row)
    return rows


def _ensemble_stats(ens: list[Outcome]) -> dict:
    return {**{k: _stats([worst_plane(o.metrics, k) for o in ens]) for k in
               ("max_displacement_um", "max_y_displacement_um", "peak_contact_force_N")},
            **{k: _stats([o.extra[k] for o in ens]) for k in
               ("force_settling_s", "radial_speed_rms_mm_s", "separations", "mean_late_force_N")}}


def _stats(vals: list[float]) -> dict:
    a = np.asarray([v for v in vals if v is not None], float)
    if a.size == 0:
        return {}
    return dict(median=float(np.median(a)), min=float(a.min()), max=float(a.max()))


def _sensitivity(outs: list[Outcome], settings: list[tuple[str, str, dict]]) -> list[dict]:
    rows = []
    for factor, setting, overrides in settings:
        grp = [o for o in outs if (o.run.label["factor"], o.run.label["setting"]) == (factor, setting)]
        sweep = [o for o in grp if o.run.label["friction"] != "soft" and o.ok
                 and _whirl(o) is not None]                 # the undecided count apart
        soft, soft_beyond = split_valid(o for o in grp if o.run.label["friction"] == "soft" and o.ok)
        mus = [o.run.label["friction"] for o in sweep]
        whirls = [_whirl(o) for o in sweep]
        curve = probability_curve(mus, whirls)
        ons = onset([c["value"] for c in curve], [c["probability"] for c in curve], mus,
                    whirls).to_dict() if curve else {}
        rows.append(dict(
            factor=factor, setting=setting, overrides=overrides,
            onset=ons, probability=[dict(friction=c["value"], probability=c["probability"],
                                         runs=c["runs"]) for c in curve],
            soft_max_y_displacement_um=_median_worst(soft, "max_y_displacement_um"),
            soft_peak_contact_force_N=_median_worst(soft, "peak_contact_force_N"),
            soft_beyond_validity=soft_beyond,
            failed=sum(not o.ok for o in grp)))
    return rows


def _median_worst(outs: list[Outcome], key: str) -> float | None:
    """Median over the drops of the worst plane's ``key`` (None without drops)."""
    return float(np.median([worst_plane(o.metrics, key) for o in outs])) if outs else None
