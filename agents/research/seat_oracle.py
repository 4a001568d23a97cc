"""``rotordrop research seat-oracle``: how much a plan that knows the drop gains in the
``controller`` seat, measured as a search over ``whirl-brake``'s gains.

Per test drop of a suite (the first ``--scenarios`` drops of ``rotordrop benchmark --suite
robust``), every member of a fixed pool of ``whirl-brake`` gain sets runs in the law's own seat
(inside the AMB controller: raw currents and C_max at the seat's 0.2 ms step, the suite's
sensing, no transport latency), and the drop is scored by the member that did best on it
(:func:`agents.benchmarking.headroom.headroom`'s "per-drop best row"), as if the gains had
been picked for that drop in advance. The pool (:func:`gain_sets`): the gains the benchmark
runs on the suite (the reference row, ``whirl-brake`` tuned on the suite's validation drops),
the class defaults, ``whirl-brake-robust``'s, and ``--draws`` draws around the tuned gains
(Gaussian, ``--spread`` x each gain's tuning range, clipped to it, from ``--seed``).

It is a search, not a bound: a larger pool, another law or a time-varying plan may find more;
the envelope is what this pool reaches on each drop. Every drop's best member is at least the
reference (the reference is in the pool), so the difference to it is >= 0 by construction; its
paired-bootstrap SE over the drops says how much of it is more than a few lucky drops.

    rotordrop research seat-oracle --scenarios 50 --draws 8 --out out/seat-oracle

writes ``seat_oracle.json`` (settings, the pool, per-drop rows, the headroom table and the
index of each drop's best member), ``seat_oracle.csv`` (per drop: reference and best cost and
member) and ``seat_oracle.png`` (the headroom figure).
"""
from __future__ import annotations

import csv
import time
from pathlib import Path

import numpy as np

from ..benchmarking.benchmark import EPISODE_TIME, TASKS, Entry, controller_entry, entry_rows
from ..benchmarking.headroom import best_rows, drop_table, headroom, plot, table
from ..benchmarking.robust import scenario_record
from ..benchmarking.score import DEFAULT_SCORE, write_json
from ..benchmarking.suites import SUITES
from ..benchmarking.tuned import tuned_gains
from ..control.controllers import Passive, WhirlBrake, WhirlBrakeRobust
from .tune_whirl_brake import HIGH, LOW, NAMES

ENV_ID = TASKS["full"]
REFERENCE = WhirlBrake.name


def gain_sets(tuned: dict, draws: int, spread: float, seed: int) -> list[tuple[str, dict]]:
    """The pool (module doc): (name, gains) of the tuned gains (named ``whirl-brake``, the
    reference), the class defaults, ``whirl-brake-robust``'s and ``draws`` Gaussian draws
    around the tuned gains (``spread`` x each gain's range in
    :mod:`agents.research.tune_whirl_brake`, clipped to it). ValueError for ``draws`` < 0 or
    ``spread`` outside (0, 1]."""
    if int(draws) != draws or draws < 0:
        raise ValueError(f"--draws = {draws!r} must be an integer >= 0")
    if not 0.0 < spread <= 1.0:
        raise ValueError(f"--spread = {spread!r} must be in (0, 1] (a fraction of each gain's range)")
    centre = np.array([tuned[n] for n in NAMES], dtype=float)
    rng = np.random.default_rng(seed)
    pool = [(REFERENCE, dict(tuned)),
            ("whirl-brake-defaults", {n: WhirlBrake.GAINS[n] for n in NAMES}),
            ("whirl-brake-robust-gains", {n: WhirlBrakeRobust.GAINS[n] for n in NAMES})]
    for i in range(int(draws)):
        theta = np.clip(centre + spread * (HIGH - LOW) * rng.standard_normal(len(NAMES)), LOW, HIGH)
        pool.append((f"whirl-brake-draw{i}", dict(zip(NAMES, theta.tolist()))))
    return pool


def pool_entries(pool: list[tuple[str, dict]], suite) -> list[Entry]:
    """The passive reference and every member of the pool as benchmark entries in
    ``whirl-brake``'s seat (its env kwargs: raw currents at the controller seat's step)."""
    ref = controller_entry(WhirlBrake, ENV_ID, suite)
    entries = [controller_entry(Passive, ENV_ID, suite)]
    for name, gains in pool:
        entries.append(Entry(name, ref.task, _maker(gains), dict(ref.env_kwargs), ref.seat))
    return entries


def _maker(gains: dict):
    return lambda plant: WhirlBrake(plant, **gains)


def seat_oracle(out, suite: str = "robust", scenarios: int = 50, draws: int = 8,
                spread: float = 0.1, seed: int = 0, progress: bool = True, backend=None) -> dict:
    """Run the pool on the first ``scenarios`` test drops of ``suite`` and write the outputs of
    the module doc into ``out``; returns the report."""
    from physics.runs.backend import Backend
    from tqdm.auto import tqdm
    chosen = SUITES.get(suite, "oracle")
    if chosen.draw is None:
        raise ValueError(f"--suite {suite}: the seat oracle runs a drawn suite's test drops")
    if int(scenarios) != scenarios or scenarios < 1:
        raise ValueError(f"--scenarios = {scenarios!r} must be an integer >= 1")
    t0 = time.perf_counter()
    tuned = tuned_gains(chosen, REFERENCE, ENV_ID) or {n: WhirlBrake.GAINS[n] for n in NAMES}
    pool = gain_sets(tuned, draws, spread, seed)
    entries = pool_entries(pool, chosen)
    drops = chosen.scenarios(int(scenarios))
    backend = backend if backend is not None else Backend()
    with backend.session() as session:
        bar = tqdm(total=len(entries) * len(drops), desc="seat oracle", unit="ep",
                   disable=not progress)
        rows = entry_rows(session, entries, drops, (0.0,), bar)
        bar.close()
    report = dict(suite=chosen.name, score=DEFAULT_SCORE, episode_time_s=EPISODE_TIME,
                  scenarios=[scenario_record(s) for s in drops], rows=rows)
    result = headroom(report, "full", REFERENCE)
    names, terms, _, _ = drop_table(report, "full")
    members = [n for n in names if n != "passive"]
    cost = np.array([terms[n].sum(axis=0) for n in members])
    best = best_rows(cost)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    record = dict(settings=dict(suite=chosen.name, scenarios=int(scenarios), draws=int(draws),
                                spread=spread, seed=seed, seat=entries[1].seat,
                                env_kwargs=entries[1].env_kwargs),
                  pool=[dict(name=n, gains=g) for n, g in pool], headroom=result,
                  best_member=[members[i] for i in best], rows=rows,
                  scenarios=report["scenarios"], wall_time_s=time.perf_counter() - t0)
    write_json(out / "seat_oracle.json", record)
    with open(out / "seat_oracle.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["scenario", "seed", "reference_cost", "best_cost", "best_member"])
        ref = members.index(REFERENCE)
        for j, sc in enumerate(report["scenarios"]):
            w.writerow([sc["name"], sc["seed"], cost[ref, j], cost[best[j], j], members[best[j]]])
    plot(result, out / "seat_oracle.png")
    print(table(result))
    print(f"wrote {out / 'seat_oracle.json'}, seat_oracle.csv, seat_oracle.png in "
          f"{record['wall_time_s']:.0f} s")
    return record


def run(a) -> None:
    """``rotordrop research seat-oracle`` with its parsed options ``a`` (agents/research)."""
    from physics.runs.backend import Backend
    seat_oracle(a.out, a.suite, a.scenarios, a.draws, a.spread, a.seed, not a.quiet,
                Backend.from_args(a))
