"""The recovery benchmark (``RotorDrop-Recover-v1``): the designed laws, each in its seat, on a
suite's events, scored by recovery, time to recover and contact severity.

Without its event, is an event's machine contact-free? :func:`calm_levitation` answers for
each event (the reference on the same machine, the event moved past the episode's end): after
a transient event (a shock, a load) on such a machine a contact-free steady state exists, the
one the PID held before the event.

An event is *recovered* when the episode ends with the rotor levitated without contact for the
task's hold (50 ms: ``kpi_relevitated``) and no physical event ended it (stator contact, a
bearing overload, a contact past its law's validity). An unrecovered event that nothing ended is
in contact within its last 50 ms: **persistent contact**. The time to recover is the start of
the final contact-free period after the event's start; severity is the peak contact force, the
backward-whirl revolutions and the friction energy. Every rate has its binomial SE and Wilson
95 % interval; every difference against the reference row (the standard PID, ``inner-loop``:
the built-in PID with no command) has its paired bootstrap SE over the events.
"""
from __future__ import annotations

import math
import time

import numpy as np

from physics.runs.study.ensemble import wilson

from ..control.controllers import controller_class, controller_env_kwargs, make_controller
from ..control.seats import seat_for_kwargs, seat_of
from .rollout import run_episodes
from .score import BOOTSTRAP_RESAMPLES, BOOTSTRAP_SEED, write_json

ENV_ID = "RotorDrop-Recover-v1"
#: the reference row: the built-in PID, left alone
REFERENCE = "inner-loop"
#: the designed rows, each run in its seat
DESIGNED = ("inner-loop", "sync-phase-search", "sync-motion-comp", "pid-relevitate",
            "sync-current-search", "whirl-brake")


def event_record(ep) -> dict:
    """One event's outcome from its episode (:class:`~agents.benchmarking.rollout.Episode`)."""
    k, sc = ep.kpis, ep.scenario or {}
    ended = bool(k["stator_contact"] or k["beyond_validity"] or k["bearing_overload"])
    recovered = bool(k["relevitated"]) and not ended
    t_rec = k.get("relevitation_time_s")
    return {"seed": ep.seed, "event": sc.get("event"), "event_time_s": sc.get("event_time"),
            "recovered": recovered, "ended": ended, "persistent": not recovered and not ended,
            "time_to_recover_s": (max(t_rec - sc.get("event_time", 0.0), 0.0)
                                  if recovered and t_rec is not None else None),
            "peak_contact_force_N": k["peak_contact_force_N"],
            "whirl_revolutions": k["peak_whirl_revolutions"],
            "friction_energy_J": k["friction_energy_J"], "touched": k["peak_contact_force_N"] > 0}


def rate(x: np.ndarray) -> dict:
    """A proportion with its binomial SE and Wilson 95 % interval."""
    n, p = len(x), float(np.mean(x)) if len(x) else math.nan
    return {"value": p, "se": math.sqrt(p * (1 - p) / n), "wilson95": wilson(int(np.sum(x)), n)}


def paired_bootstrap(a: np.ndarray, b: np.ndarray, rng: np.random.Generator) -> dict:
    """mean(a − b) over paired events with its bootstrap SE and 95 % percentile interval."""
    d = np.asarray(a, float) - np.asarray(b, float)
    idx = rng.integers(0, len(d), size=(BOOTSTRAP_RESAMPLES, len(d)))
    boot = d[idx].mean(axis=1)
    return {"delta": float(d.mean()), "se": float(boot.std(ddof=1)),
            "ci95": [float(np.percentile(boot, 2.5)), float(np.percentile(boot, 97.5))]}


def row_summary(records: list[dict], ref: list[dict], seed: int = BOOTSTRAP_SEED) -> dict:
    """A row's figures against the reference row's ``ref`` (the same events, in order)."""
    rng = np.random.default_rng(seed)
    col = lambda rs, key: np.array([float(r[key]) for r in rs])     # noqa: E731
    times = [r["time_to_recover_s"] for r in records if r["time_to_recover_s"] is not None]
    out = {"events": len(records), "recovered": rate(col(records, "recovered")),
           "persistent": rate(col(records, "persistent")), "ended": rate(col(records, "ended")),
           "time_to_recover_ms_median": 1e3 * float(np.median(times)) if times else None}
    for key in ("peak_contact_force_N", "whirl_revolutions", "friction_energy_J"):
        v = col(records, key)
        out[key] = {"mean": float(v.mean()), "se": float(v.std(ddof=1) / math.sqrt(len(v)))}
    out["vs_reference"] = {key: paired_bootstrap(col(records, key), col(ref, key), rng)
                           for key in ("recovered", "peak_contact_force_N", "friction_energy_J")}
    return out


def learned_kwargs(policy_kwargs: dict, suite_kwargs: dict) -> dict:
    """The env kwargs a learned policy trained with ``policy_kwargs`` runs a suite's events
    with: its own interface (:func:`~agents.benchmarking.benchmark.interface_kwargs`: command,
    control step), the suite's ``suite_kwargs`` for the rest (machine, events, sensing)."""
    from .benchmark import interface_kwargs
    return {**interface_kwargs(policy_kwargs), **suite_kwargs}


def run_row(name: str, seeds, env_kwargs: dict, policy=None, law=None) -> tuple[list[dict], float]:
    """A designed law's events in its seat (``law``: that controller class, else the baseline
    called ``name``), or with ``policy`` (a :class:`~agents.learning.policies.LearnedPolicy`)
    that policy's, through its own interface (:func:`learned_kwargs`) on the suite's
    ``env_kwargs``: (records, CPU seconds)."""
    if policy is not None:
        if policy.env_id != ENV_ID:
            raise ValueError(f"--policy {name}: trained on {policy.env_id}, not {ENV_ID}")
        kw, make_actor = learned_kwargs(policy.env_kwargs, env_kwargs), policy.bound
    else:
        cls = law or controller_class(name)
        if cls is None:
            raise ValueError(f"{name!r} is not a designed law (a baseline controller name) "
                             f"nor a learned policy (a training run or model zip)")
        kw = {**env_kwargs, **controller_env_kwargs(cls, ENV_ID)}
        make_actor = lambda plant: make_controller(cls, plant)     # noqa: E731
    t0 = time.process_time()
    eps = run_episodes(ENV_ID, make_actor, seeds, kw)
    return [event_record(e) for e in eps], time.process_time() - t0


#: model selection: how many of a suite's validation events score a model by default
VALIDATION_EVENTS = 30
#: the tie-break's force scale [N]: a mean peak contact force F costs F / (F + this) < 1 point
TIE_FORCE_N = 1e4


def selection_score(records: list[dict]) -> float:
    """A model's validation score on its events: the recovered percentage, ties broken by the
    mean peak contact force F (lower is better): 100 · recovered − F / (F + 10 kN). The
    tie-break is under 1 point and one event is at least 1 point for up to 100 events, so it
    never outranks a recovery."""
    force = float(np.mean([r["peak_contact_force_N"] for r in records]))
    return 100.0 * float(np.mean([r["recovered"] for r in records])) - force / (force + TIE_FORCE_N)


class RecoverValidator:
    """Model selection on the Recover task (the training validation callback,
    :func:`agents.training.validation.validator_for`): a model's :func:`selection_score` on the
    first ``events`` validation events of ``suite`` (its seeds apart from the test events),
    the model run through its own interface on the suite's env kwargs (:func:`learned_kwargs`),
    as the benchmark will run it. ``score`` returns (score, event records)."""

    def __init__(self, suite, events: int = VALIDATION_EVENTS):
        n = suite.validation_size
        if isinstance(events, bool) or int(events) != events or not 1 <= events <= min(n, 100):
            raise ValueError(f"validation_events = {events!r} must be an integer in "
                             f"[1, {min(n, 100)}] (the {suite.name} suite's validation events)")
        self.suite, self.seeds = suite, suite.validation_seeds()[:int(events)]

    @property
    def episodes(self) -> int:
        """Validation episodes per score."""
        return len(self.seeds)

    def score(self, make_actor, env_kwargs: dict) -> tuple[float, list[dict]]:
        eps = run_episodes(ENV_ID, make_actor, self.seeds,
                           learned_kwargs(env_kwargs, self.suite.env_kwargs))
        records = [event_record(e) for e in eps]
        return selection_score(records), records


def tuned_law(suite, name: str):
    """Designed row ``name`` as it runs on ``suite``: the law with the constants tuned on the
    suite's validation events (``rotordrop research tune-designed --suite SUITE``,
    :func:`agents.benchmarking.tuned.tuned_gains`) where a record has them, else None (the
    law's own constants)."""
    from ..control.controllers import with_constants
    from .tuned import tuned_gains
    cls = controller_class(name)
    gains = tuned_gains(suite, name, ENV_ID) if cls is not None else None
    return with_constants(cls, gains) if gains else None


def learned_rows(specs: list[str], names: list[str] | None = None) -> dict:
    """The learned policies among ``specs`` (``--policy``: a training run, its ``best/`` or a
    model zip; ``names``: ``--name``, one per such path) by display name; designed law names
    are left out (they are rows of their own)."""
    from ..learning.policies import shipped_names
    from .benchmark import extras
    paths = [s for s in specs if controller_class(s) is None]
    shipped = [s for s in paths if s in shipped_names()]
    if shipped:
        raise ValueError(f"--policy {', '.join(shipped)}: no shipped policy runs {ENV_ID}")
    learned, _ = extras(paths, ENV_ID, names)
    return {p.name: p for p in learned}


def seed_groups(rows: dict, learned: list[str]) -> dict:
    """The learned rows named ``GROUP-sSEED`` (two seeds or more of a group) as seed groups:
    each seed's recovered rate, their mean ± std (ddof 1) and mean − std, and the seed-mean's
    per-event recovery against the reference and against the best designed row of ``rows``
    (paired bootstrap over events). ``rows``: each row's event records, the same events."""
    import re
    groups: dict[str, list[str]] = {}
    for name in learned:
        m = re.fullmatch(r"(.+)-s(\d+)", name)
        if m:
            groups.setdefault(m.group(1), []).append(name)
    designed = [n for n in rows if n not in learned]
    recovered = {n: np.array([float(r["recovered"]) for r in rows[n]]) for n in rows}
    best = max(designed, key=lambda n: recovered[n].mean())
    out = {}
    for group, names in groups.items():
        if len(names) < 2:
            continue
        rates = np.array([recovered[n].mean() for n in names])
        mean = np.mean([recovered[n] for n in names], axis=0)
        out[group] = {"rows": names, "rates": rates.tolist(), "mean": float(rates.mean()),
                      "std": float(rates.std(ddof=1)),
                      "mean_minus_std": float(rates.mean() - rates.std(ddof=1)),
                      "vs": {n: paired_bootstrap(mean, recovered[n],
                                                 np.random.default_rng(BOOTSTRAP_SEED))
                             for n in dict.fromkeys([REFERENCE, best])}}
    return out


def calm_levitation(suite, seeds) -> list[bool]:
    """Per event of ``seeds``: whether the reference (the built-in PID) holds the event's
    machine contact-free for the task's hold at the end of an episode *without* the event (its
    start moved past the episode's end; the machine draw is the same, it comes first)."""
    events = {**(suite.env_kwargs.get("events") or {}), "delay": (1.0, 1.0)}
    records, _ = run_row(REFERENCE, seeds, {**suite.env_kwargs, "events": events})
    return [r["recovered"] for r in records]


def add_calm(report: dict, suite) -> dict:
    """The report with ``calm``: :func:`calm_levitation` of its events."""
    a, b = report["seeds"]
    report["calm"] = calm_levitation(suite, range(a, b + 1))
    return report


def recover_benchmark(out, suite, quick: bool = False, policies: list[str] | None = None,
                      progress: bool = True, max_scenarios: int | None = None,
                      validation: bool = False, names: list[str] | None = None,
                      **_ignored) -> dict:
    """``rotordrop benchmark --suite recover | recover-robust``: every designed law (or
    ``policies``: designed law names and learned policies, :func:`learned_rows`, named by
    ``names``) in its seat, with its constants tuned on the suite's validation events where
    they were (:func:`tuned_law`), on the suite's test events (``validation``: its validation events),
    the report written to ``out/benchmark.json`` and ``out/leaderboard.md``."""
    from pathlib import Path
    n = suite.quick_size if quick else suite.size
    if max_scenarios is not None:
        n = min(n, max_scenarios)
    seeds = suite.validation_seeds() if validation else suite.test_seeds(n)
    learned = learned_rows(list(policies or []), names)
    rows_asked = [p for p in policies or DESIGNED if controller_class(p) is not None]
    names = list(dict.fromkeys([REFERENCE, *rows_asked, *learned]))
    rows, cost, laws = {}, {}, {n: tuned_law(suite, n) for n in names if n not in learned}
    for name in names:
        rows[name], cost[name] = run_row(name, seeds, suite.env_kwargs, learned.get(name),
                                         laws.get(name))
        if progress:
            print(f"{name}: {sum(r['recovered'] for r in rows[name])}/{len(seeds)} recovered "
                  f"({cost[name]:.1f} CPU s)", flush=True)
    board = []
    for name in names:
        s = row_summary(rows[name], rows[REFERENCE])
        seat = (seat_for_kwargs(learned[name].env_kwargs) if name in learned
                else seat_of(controller_class(name)))
        law = laws.get(name)
        board.append({"controller": name, "seat": seat.name, "learned": name in learned,
                      "tuned_constants": None if law is None else law.GAINS,
                      "cpu_s": cost[name], **s})
    board.sort(key=lambda r: (-r["recovered"]["value"], r["peak_contact_force_N"]["mean"]))
    report = add_calm({"env_id": ENV_ID, "suite": suite.name,
                       "seeds": [seeds.start, seeds.stop - 1], "env_kwargs": suite.env_kwargs,
                       "reference": REFERENCE, "board": board, "events": rows,
                       "groups": seed_groups(rows, list(learned)),
                       "cpu_s_total": sum(cost.values())}, suite)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "benchmark.json", report)
    (out / "leaderboard.md").write_text(recover_markdown(report) + "\n")
    return report


def _pct(r: dict) -> str:
    lo, hi = r["wilson95"]
    return f"{100 * r['value']:.1f} ± {100 * r['se']:.1f} [{100 * lo:.0f}, {100 * hi:.0f}]"


def recover_markdown(report: dict) -> str:
    """The leaderboard table of a recovery benchmark report."""
    ref = report["reference"]
    head = ("| rank | controller | seat | recovered % ± SE [Wilson 95 %] | Δ recovered vs "
            f"`{ref}` ± SE | persistent contact % | ended (stator / validity) % | "
            "time to recover, median [ms] | peak contact force [kN] | Δ vs ref ± SE [kN] | "
            "backward-whirl rev. | friction energy [J] |")
    lines = [head, "|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for i, r in enumerate(report["board"], 1):
        d, df = r["vs_reference"]["recovered"], r["vs_reference"]["peak_contact_force_N"]
        t = r["time_to_recover_ms_median"]
        lines.append(
            f"| {i} | `{r['controller']}` | {r['seat']} | {_pct(r['recovered'])} | "
            f"{100 * d['delta']:+.1f} ± {100 * d['se']:.1f} | {100 * r['persistent']['value']:.1f} | "
            f"{100 * r['ended']['value']:.1f} | {'—' if t is None else f'{t:.1f}'} | "
            f"{r['peak_contact_force_N']['mean'] / 1e3:.2f} | "
            f"{df['delta'] / 1e3:+.2f} ± {df['se'] / 1e3:.2f} | "
            f"{r['whirl_revolutions']['mean']:.2f} | {r['friction_energy_J']['mean']:.2f} |")
    if report.get("groups"):
        lines += ["", groups_markdown(report["groups"])]
    return "\n".join(lines)


def groups_markdown(groups: dict) -> str:
    """The seed groups' table (:func:`seed_groups`): recovered % per seed, mean ± std, mean −
    std, and the seed-mean's difference against each compared row (points ± paired SE [95 %])."""
    against = list(dict.fromkeys(n for g in groups.values() for n in g["vs"]))
    lines = ["| learned group | seeds: recovered % | mean ± std | mean − std | "
             + " | ".join(f"seed-mean Δ vs `{n}` ± SE [95 %]" for n in against) + " |",
             "|---|---|---:|---:|" + "---:|" * len(against)]
    for name, g in groups.items():
        cells = []
        for n in against:
            d = g["vs"].get(n)
            cells.append("—" if d is None else f"{100 * d['delta']:+.1f} ± {100 * d['se']:.1f} "
                         f"[{100 * d['ci95'][0]:+.1f}, {100 * d['ci95'][1]:+.1f}]")
        lines.append(f"| `{name}` | {', '.join(f'{100 * r:.1f}' for r in g['rates'])} | "
                     f"{100 * g['mean']:.1f} ± {100 * g['std']:.1f} | {100 * g['mean_minus_std']:.1f} | "
                     + " | ".join(cells) + " |")
    return "\n".join(lines)



def print_table(render, argv, what: str) -> int:
    """Print ``render(report)`` of the JSON report named on the command line ``argv``
    (``what`` it is, for the help)."""
    import argparse
    import json
    from pathlib import Path
    ap = argparse.ArgumentParser(description=f"print the tables of {what}")
    ap.add_argument("report", help=what)
    print(render(json.loads(Path(ap.parse_args(argv).report).read_text())))
    return 0


def main(argv=None) -> int:
    """``python -m agents.benchmarking.recover BENCHMARK.json``: print a recovery report's
    leaderboard (and its seed groups' table)."""
    return print_table(recover_markdown, argv, "a recovery benchmark report (benchmark.json)")


if __name__ == "__main__":
    raise SystemExit(main())
