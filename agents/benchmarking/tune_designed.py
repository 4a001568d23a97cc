"""Designed rows tuned like learned ones: ``rotordrop research tune-designed --suite robust``.

Every designed law with constants (:data:`DESIGNED`) is tuned on the suite's **validation**
drops only (:meth:`agents.benchmarking.suites.Suite.validator`; on a recover suite the
recovery laws on its validation events, scored by the recovered percentage, ties broken by the
mean peak contact force: :class:`agents.benchmarking.recover.RecoverValidator`), in its seat
(:mod:`agents.control.seats`), under the current environment and sensing, by a cross-entropy
search (:mod:`agents.benchmarking.search`) that maximises the validation score. The budget is
stated in validation episodes and is at least what one learned configuration spends on its
model selection (:data:`LEARNED_SELECTION_EPISODES`: ``rotordrop train`` scores its model on
the 20 validation drops after every evaluation, every 10 000 of its 1e6 steps).

The tuned constants are stored with a record of what they were tuned under
(``agents/benchmarking/tuned/<suite>.json``, package data, read by :mod:`agents.benchmarking.tuned`): the env id (its version is the
``-vN`` suffix), the package version (for the reader: not compared), the seat and control step,
the suite's sensing and a *sensing fingerprint* (:func:`sensing_fingerprint`: a hash of the observations of one short
validation drop, which changes whenever the sensing model or the plant does). The benchmark
runs a designed row with its tuned constants (:func:`tuned_gains`); the test suite fails when a
shipped record no longer matches the current environment, so a change of the sensing or the
plant means re-running this command.
"""
from __future__ import annotations

import hashlib
import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .tuned import load_records, record_path

#: one learned configuration's model selection on the validation drops: 1e6 steps scored every
#: 10 000 (``rotordrop train``'s default ``eval_freq``) on 20 drops (agents/training/validation.py)
LEARNED_SELECTION_EPISODES = (1_000_000 // 10_000) * 20


@dataclass(frozen=True)
class Designed:
    """A designed law with constants to tune: its baseline name, the constants' ranges (the
    search box), the search's population per generation and whether it is a recovery law
    (tuned on a recover suite's validation events, the others on a drop suite's drops)."""
    name: str
    ranges: dict[str, tuple[float, float]]
    population: int
    recover: bool = False


#: the synchronous recovery laws' watch and search constants (revolutions, fractions of the
#: clearance): the box around agents.control.controllers.SEARCH
WATCH_RANGES = {"r_contact": (0.5, 0.95), "revolutions": (2.0, 16.0), "fraction": (0.1, 0.9),
                "release": (2.0, 12.0)}
#: the designed laws with constants, in the order they are tuned
DESIGNED: dict[str, Designed] = {d.name: d for d in (
    Designed("inner-loop-lift", {"gain": (0.0, 1.0), "offset_r": (-1.0, 0.0)}, 12),
    Designed("whirl-brake", {"kp": (0.0, 30.0), "kd": (0.0, 5.0), "kc": (-3.0, 3.0),
                             "kt": (-0.5, 0.5), "kr": (-1.0, 1.0), "ff": (0.0, 2.0)}, 20),
    Designed("sync-phase-search", {"amplitude": (0.05, 1.0), "dwell": (1.0, 10.0),
                                   **WATCH_RANGES}, 8, recover=True),
    Designed("sync-motion-comp", {"gain": (0.0, 1.0), "lead": (-1.0, 1.0), **WATCH_RANGES}, 8,
             recover=True),
)}


def laws_for(suite) -> list[str]:
    """The designed laws tuned on ``suite``: the recovery laws on a recover suite, the others
    on a drop suite."""
    from .suites import RecoverSuite
    return [n for n, d in DESIGNED.items() if d.recover == isinstance(suite, RecoverSuite)]


#: recorded for the reader, not compared: a release that changes neither the plant nor the
#: sensing (the fingerprint says) leaves a tuning valid
INFORMATIVE = ("package_version",)


def package_version() -> str:
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("rotordrop")
    except PackageNotFoundError:
        return "unknown"


def sensing_fingerprint(suite, cls, env_id: str, duration: float = 0.01) -> str:
    """A hash of what law ``cls`` observes, in its seat, over the first ``duration`` [s]
    of the suite's first validation drop with the actions held at zero (observations
    rounded to 6 significant digits, so that a reordered sum does not change it): it changes
    when the sensing model, its noise or delay, or the plant changes."""
    from ..control.controllers import controller_env_kwargs
    from ..control.plant import make_env
    from .benchmark import Entry, episode_kwargs, task_of
    from .suites import RecoverSuite
    if isinstance(suite, RecoverSuite):         # its first validation event
        kw, seed = {**suite.env_kwargs, **controller_env_kwargs(cls, env_id)}, suite.validation_seed
    else:
        sc = suite.validation()[0]
        entry = Entry(cls.name, task_of(env_id), None, controller_env_kwargs(cls, env_id))
        kw, seed = episode_kwargs(entry, sc, 0.0), sc.seed
    env = make_env(env_id, **kw)
    steps = int(round(duration / kw.get("control_dt", 1e-3)))
    try:
        obs, _ = env.reset(seed=seed)
        rows = [obs]
        zero = np.zeros(env.action_space.shape, dtype=env.action_space.dtype) \
            if env.action_space.shape else 0
        for _ in range(steps):
            obs, *_ = env.step(zero)
            rows.append(obs)
    finally:
        env.close()
    text = "\n".join(" ".join(f"{v:.6g}" for v in r) for r in rows)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def environment_record(suite, cls, env_id: str) -> dict:
    """What a tuning is valid for (module doc); the test compares it with the shipped one."""
    from ..control.controllers import controller_env_kwargs
    from ..control.seats import seat_of
    return dict(env_id=env_id, package_version=package_version(), seat=seat_of(cls).name,
                env_kwargs=controller_env_kwargs(cls, env_id),
                sensing=(suite.describe(suite, suite.size) if getattr(suite, "describe", None)
                         else getattr(suite, "env_kwargs", None)),
                sensing_fingerprint=sensing_fingerprint(suite, cls, env_id))


def stale(suite, name: str) -> list[str]:
    """The keys in which the stored record of ``name`` on ``suite`` differs from the current
    environment (empty: up to date); ValueError when there is no record."""
    from ..control.controllers import BASELINES
    rec = load_records(suite).get(name)
    if rec is None:
        raise ValueError(f"no tuned record of {name} on the {suite.name} suite")
    now = environment_record(suite, BASELINES[name], rec["env_id"])
    return [k for k, v in now.items()
            if k not in INFORMATIVE and json.loads(json.dumps(v)) != rec["tuned_under"].get(k)]


def budget_plan(designed: Designed, episodes: int, drops: int) -> int:
    """Generations of ``designed.population`` candidates so that the search scores at least
    ``episodes`` validation episodes (the start and every candidate on ``drops`` drops)."""
    per_generation = designed.population * drops
    return max(1, -(-(episodes - drops) // per_generation))


def tune_designed(suite, names: list[str] | None = None, episodes: int = LEARNED_SELECTION_EPISODES,
                  seed: int = 0, progress: bool = True, out: Path | None = None,
                  store: bool = True) -> dict:
    """Tune every law of ``names`` (default the suite's, :func:`laws_for`) on ``suite``'s
    validation drops (a recover suite: its validation events) with at least ``episodes``
    validation episodes each (module doc); store the records under :data:`TUNED_DIR`
    (``store``) and return them with their costs."""
    from ..control.controllers import BASELINES, controller_env_kwargs
    from .benchmark import TASKS
    from .search import cross_entropy
    from .tune import GainObjective
    env_id = suite.env_id or TASKS["full"]
    own = laws_for(suite)
    names = own if names is None else names
    unknown = [n for n in names if n not in own]
    if unknown:
        raise ValueError(f"--law {unknown}: the designed laws with constants tuned on the "
                         f"{suite.name} suite are {', '.join(own)}")
    if episodes < LEARNED_SELECTION_EPISODES:
        raise ValueError(f"--episodes = {episodes} is below a learned configuration's model "
                         f"selection ({LEARNED_SELECTION_EPISODES} validation episodes)")
    validator = suite.validator(env_id)
    drops = validator.episodes
    records = load_records(suite)
    for name in names:
        d, cls = DESIGNED[name], BASELINES[name]
        keys = list(d.ranges)
        low = np.array([d.ranges[k][0] for k in keys])
        high = np.array([d.ranges[k][1] for k in keys])
        start = np.clip([cls.GAINS[k] for k in keys], low, high)
        iterations = budget_plan(d, episodes, drops)
        objective = GainObjective(name, env_id, controller_env_kwargs(cls, env_id), keys, validator)
        t0, c0 = time.perf_counter(), time.process_time()
        best_cost, best, history = cross_entropy(
            objective, mean=start, std=0.15 * (high - low), low=low, high=high,
            iterations=iterations, population=d.population, elite=max(2, d.population // 4),
            rng=np.random.default_rng(seed), min_std=0.01 * (high - low), progress=progress,
            desc=f"tuning {name} on {suite.name} validation")
        scored = (1 + iterations * d.population) * drops
        records[name] = dict(
            gains={k: float(v) for k, v in zip(keys, best)},
            validation_score=-float(best_cost), start=dict(zip(keys, start.tolist())),
            start_validation_score=-float(history[0]["best_cost"]),
            env_id=env_id, ranges={k: list(v) for k, v in d.ranges.items()},
            budget=dict(validation_episodes=scored, generations=iterations,
                        population=d.population, validation_drops=drops,
                        validation_seeds=[suite.validation_seed,
                                          suite.validation_seed + suite.validation_size - 1],
                        learned_selection_episodes=LEARNED_SELECTION_EPISODES, seed=seed),
            cost=dict(wall_time_s=round(time.perf_counter() - t0, 1),
                      cpu_time_s=round(time.process_time() - c0, 1)),
            tuned_under=environment_record(suite, cls, env_id))
        print(f"{name}: validation score {records[name]['start_validation_score']:.2f} -> "
              f"{records[name]['validation_score']:.2f} with {records[name]['gains']} "
              f"({scored} validation episodes, {records[name]['cost']['cpu_time_s']:.0f} CPU-s)")
        if store:                   # re-read: one process per law may tune in parallel
            path = record_path(suite)
            path.parent.mkdir(parents=True, exist_ok=True)
            stored = {**load_records(suite), name: records[name]}
            path.write_text(json.dumps(stored, indent=1, sort_keys=True) + "\n")
        if out is not None:
            Path(out).mkdir(parents=True, exist_ok=True)
            (Path(out) / f"tune-designed-{suite.name}.json").write_text(json.dumps(records, indent=1))
    return records
