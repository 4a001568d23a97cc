"""The per-drop checks of ``rotordrop drop`` carried into the studies.

:func:`physics.metrics.compute_metrics` already checks every drop (:func:`~physics.metrics.check_metrics`)
and words each failed check (:func:`~physics.metrics.warnings_of`, ``metrics["warnings"]``). A study
reads the same flags, counts them per kind, and does not take a run without a fault for a drop:
:func:`as_drop` turns it into a failed run (its statistics would be those of the levitated rotor,
e.g. a "no whirl").
"""
from __future__ import annotations

from dataclasses import replace
from typing import Callable, Iterable

from ..sweep import Outcome

# kind -> (the metrics flag that raises it, as a predicate; what the note calls it)
WARNING_KINDS: dict[str, tuple[Callable[[dict], bool], str]] = {
    "no_fault": (lambda m: not m["fault_simulated"], "without a fault (counted as failed)"),
    "pre_fault_contact": (lambda m: m["contact_before_fault"], "in contact before the fault"),
    "stator_contact": (lambda m: m["stator_contact"] and not m.get("stator_contact_modelled"),
                       "reaching the AMB stator"),
    "coarse_output": (lambda m: m["output_rate_too_coarse"], "with too coarse an output rate"),
    "missed_peaks": (lambda m: bool(m["sampled_peaks_missed"]), "whose samples miss impact peaks"),
    "aliased_whirl": (lambda m: any(p["whirl_sampling_aliased"] for p in m["planes"].values()),
                      "with an aliased whirl"),
    "penetration": (lambda m: bool(m.get("penetration_beyond_validity")),
                    "past the contact law's penetration bound"),
    "film_play": (lambda m: bool(m.get("film_exceeds_play")), "with an EHL film above the play"),
    "dry_whip": (lambda m: bool(m.get("stator_beyond_validity")),
                 "rolling on the stator past its penetration bound (dry whip)"),
}
NO_FAULT = "NoFault"


def beyond_validity(metrics: dict | None) -> bool:
    """The drop passed a validity bound (``left_validity_at_s``, :func:`physics.metrics.mark_validity`:
    a contact law's penetration bound, or the AMB air gap without stator contact): its numbers
    of the motion after that time are None, so a study counts it apart and keeps it out of every
    ratio, median and peak table. Its whirl decision is the one within validity
    (:func:`physics.metrics.whirl_decision`): a whirl once its backward revolutions were counted
    before that time, else undecided, and counted apart from the whirl probability."""
    return bool(metrics) and metrics.get("left_validity_at_s") is not None


def split_valid(outcomes: Iterable[Outcome]) -> tuple[list[Outcome], int]:
    """The outcomes within validity, and how many others left it (:func:`beyond_validity`)."""
    outcomes = list(outcomes)
    valid = [o for o in outcomes if not beyond_validity(o.metrics)]
    return valid, len(outcomes) - len(valid)


def warning_kinds(metrics: dict) -> list[str]:
    """The kinds of :data:`WARNING_KINDS` whose check this drop's metrics fail."""
    return [k for k, (failed, _) in WARNING_KINDS.items() if failed(metrics)]


def warning_counts(outcomes: Iterable[Outcome]) -> dict[str, int]:
    """Drops per warning kind, over the runs that have metrics (every kind listed, 0 included)."""
    counts = dict.fromkeys(WARNING_KINDS, 0)
    for o in outcomes:
        for k in warning_kinds(o.metrics) if o.metrics else ():
            counts[k] += 1
    return counts


def counts_text(counts: dict[str, int]) -> str:
    """The flagged kinds in short: "stator_contact 2, coarse_output 1" ("" when none)."""
    return ", ".join(f"{k} {n}" for k, n in counts.items() if n)


def warnings_note(counts: dict[str, int]) -> str:
    """One line: "drop checks: 2 drops reaching the AMB stator, ..." ("" when no drop was flagged)."""
    parts = [f"{n} drop{'s' if n > 1 else ''} {WARNING_KINDS[k][1]}" for k, n in counts.items() if n]
    return ("drop checks: " + ", ".join(parts)) if parts else ""


def as_drop(outcome: Outcome) -> Outcome:
    """``outcome``, or a failed one when its run ended before the fault: no drop happened, so it
    must count neither as a whirl nor as a no-whirl. The error is the drop's own warning."""
    m = outcome.metrics
    if not outcome.ok or m["fault_simulated"]:
        return outcome
    text = next((w for w in m["warnings"] if w.startswith("no fault")), "no fault in the simulated time")
    return replace(outcome, ok=False, error=f"{NO_FAULT}: {text}")
