"""Open-loop probes of the supervisor interface on the robust validation set (docs/experiments/2026-11-26-robust-collapse.md): how often do random commands, as a fresh SAC actor samples them,
re-levitate at a given ``supervisor_authority``, and what do constant commands score?

    python -m agents.research.probe_commands --random --authority 1,0.25,0.2,0.15,0.1
    python -m agents.research.probe_commands --constant 1,1,1,0.2,-0.2,0.2,-0.2,0.2
    python -m agents.research.probe_commands --suite nominal --constant 1,1,1,0.5,-0.5,0,-0.5,0

Random: every entry tanh(N(0, std²)) each step (SAC's initial actor: std 1), the draws seeded
with 0. Constant: the 8 Full-supervisor entries (damping1, damping2, levitate, gain, offset_r1,
offset_t1, offset_r2, offset_t2), every step. Both at the 5 ms step; with ``--suite robust``
(the default) on the robust validation set with the sensing of the robust training runs
(:func:`agents.benchmarking.robust.training_env_kwargs`), with ``--suite nominal`` on the nominal validation
suite of the Full task (:class:`agents.benchmarking.benchmark.Validator`: the one ``rotordrop train`` selects
on and ``rotordrop tune`` tunes on).
"""
from __future__ import annotations

import argparse
import json

import numpy as np

from agents.benchmarking.benchmark import Validator
from agents.benchmarking.robust import ENV_ID, training_env_kwargs
from agents.benchmarking.suites import SUITES

#: the probes' control step [s]
CONTROL_DT = 0.005


class RandomCommands:
    def __init__(self, std: float, rng):
        self.std, self.rng = std, rng

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        return np.tanh(self.std * self.rng.standard_normal((1, 8))).astype(np.float32), None


class ConstantCommands:
    def __init__(self, action):
        self.action = np.asarray(action, dtype=np.float32)[None]

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        return self.action, None


def suite_validator(suite: str) -> tuple[Validator, dict]:
    """The validation set of ``suite`` (robust or nominal) and its training env kwargs at 5 ms
    (:meth:`agents.benchmarking.suites.Suite.training_env_kwargs`)."""
    chosen = SUITES.get(suite, "tune")
    return chosen.validator(ENV_ID), chosen.training_env_kwargs(CONTROL_DT)


def probe(validator, make, authority: float = 1.0, env_kwargs: dict | None = None) -> dict:
    base = training_env_kwargs(CONTROL_DT) if env_kwargs is None else env_kwargs
    kw = dict(base, command="supervisor", supervisor_authority=authority)
    score, rows = validator.score(make, kw)
    return dict(score=score,
                relevitated=float(np.mean([r["relevitated"] for r in rows])),
                whirl_rate=float(np.mean([r["backward_whirl"] for r in rows])))


def floats(text: str) -> list[float]:
    return [float(x) for x in text.split(",")]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--suite", default="robust", choices=SUITES.names("tune"),
                    help="validation set: the robust one (default) or the Full task's nominal one")
    ap.add_argument("--random", action="store_true", help="random commands at each --authority")
    ap.add_argument("--authority", type=floats, default=[1.0])
    ap.add_argument("--std", type=float, default=1.0)
    ap.add_argument("--constant", type=floats, action="append", default=[],
                    help="8 comma-separated entries in [-1, 1] (repeatable), at full authority")
    args = ap.parse_args(argv)
    if not args.random and not args.constant:
        ap.error("give --random and/or --constant")
    if any(len(c) != 8 for c in args.constant):
        ap.error("--constant needs 8 entries: damping1,damping2,levitate,gain,r1,t1,r2,t2")
    validator, kw = suite_validator(args.suite)
    if args.random:
        for a in args.authority:
            rng = np.random.default_rng(0)
            res = probe(validator, lambda plant: RandomCommands(args.std, rng), a, kw)
            print(json.dumps(dict(suite=args.suite, random_std=args.std, authority=a, **res)),
                  flush=True)
    for c in args.constant:
        res = probe(validator, lambda plant: ConstantCommands(c), 1.0, kw)
        print(json.dumps(dict(suite=args.suite, constant=c, **res)), flush=True)


if __name__ == "__main__":
    main()
