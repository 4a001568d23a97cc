"""Diagnose a supervisor training run on the robust validation set (docs/agents.md, "Why the
robust runs collapse"): every checkpoint of ``RUN/checkpoints`` (and ``inner-loop`` in the same
interface) on the 20 validation drops, with the score's terms split and the mean command.

    python -m agents.research.diagnose_run runs/diag-0 --out runs/diag-0/diagnosis.json

Per row: validation score, re-levitated rate, re-levitation time after the power return
(median over the re-levitated drops), whirl rate, peak force and displacement over the passive
drop's, the mean benchmark cost J, the episode return of the KPI reward (``reward: kpi``, from
the episode's KPIs: −Φ_T + w_relevitate [re-levitated] − (time without re-levitation) / T) and
the mean action per entry before and after the power return, with the fraction of steps that
command ``levitate`` > 0.
"""
from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

import numpy as np

from agents.benchmark import EPISODE_TIME, Entry, leaderboard, suite_rows
from agents.controllers import InnerLoop
from agents.policies import LearnedPolicy
from agents.reward import WEIGHTS, kpi_potential
from agents.robust import robust_validator
from agents.score import write_json


class Recorder:
    """An actor whose actions are kept, with the observed ``amb_power`` flag of each step."""

    def __init__(self, actor, log: list, power_index: int):
        self.actor, self.log, self.power_index = actor, log, power_index

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        action, state = self.actor.predict(obs, state=state, episode_start=episode_start,
                                           deterministic=deterministic)
        self.log.append((float(obs[0, self.power_index]), np.atleast_1d(np.asarray(action[0], float))))
        return action, state


def kpi_return(row: dict, power_return: float) -> float:
    """The KPI reward's episode return from a validation row's KPIs (agents/reward.py)."""
    w = {k: v for k, v in WEIGHTS.items() if k not in ("w_relevitate", "w_time")}
    phi = kpi_potential(min(row["peak_whirl_revolutions"], 3.0), row["peak_contact_force_N"],
                        row["max_displacement_um"], **w)
    relev = bool(row["relevitated"])
    pending = (row["relevitation_time_s"] + 0.02) if relev else EPISODE_TIME
    return float(-phi + WEIGHTS["w_relevitate"] * relev - WEIGHTS["w_time"] * pending / EPISODE_TIME)


def diagnose(name: str, make, env_kwargs: dict, validator, names: list[str]) -> dict:
    log: list = []
    power_index = names.index("amb_power")
    rows = suite_rows(Entry(name, validator.task, lambda plant: Recorder(make(plant), log, power_index),
                            env_kwargs), validator.scenarios, validator.phases)
    board = leaderboard(validator.passive + rows, validator.scenarios, None)
    score = next(e["score"] for e in board if e["controller"] == name)
    passive = {r["scenario"]: r for r in validator.passive}
    pr = {s.name: s.env_kwargs["power_return_time"] for s in validator.scenarios}
    relev = [r for r in rows if r["relevitated"]]
    power = np.array([p for p, _ in log]) > 0.5
    acts = np.array([a for _, a in log])
    return dict(
        controller=name, score=score,
        relevitated=float(np.mean([r["relevitated"] for r in rows])),
        relevitation_after_power_ms_median=(float(np.median([1e3 * (r["relevitation_time_s"] - pr[r["scenario"]])
                                                             for r in relev])) if relev else None),
        whirl_rate=float(np.mean([r["backward_whirl"] for r in rows])),
        force_ratio=float(np.mean([r["peak_contact_force_N"] / passive[r["scenario"]]["peak_contact_force_N"]
                                   for r in rows])),
        disp_ratio=float(np.mean([r["max_displacement_um"] / passive[r["scenario"]]["max_displacement_um"]
                                  for r in rows])),
        mean_cost=float(np.mean([r["cost"] for r in rows])),
        kpi_return=float(np.mean([kpi_return(r, pr[r["scenario"]]) for r in rows])),
        mean_action_before_power=acts[~power].mean(axis=0).round(3).tolist(),
        mean_action_after_power=acts[power].mean(axis=0).round(3).tolist(),
        levitate_on_after_power=float(np.mean(acts[power][:, 2] > 0.0)))


def checkpoints(run: Path) -> list[Path]:
    steps = lambda p: int(re.search(r"_(\d+)_steps\.zip$", p.name)[1])
    return sorted((run / "checkpoints").glob("*_steps.zip"), key=steps)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run", type=Path)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--every", type=int, default=1, help="every k-th checkpoint")
    args = ap.parse_args(argv)
    validator = robust_validator()
    ckpts = checkpoints(args.run)[::args.every]
    if (args.run / "best" / "best_model.zip").is_file():
        ckpts.append(args.run / "best" / "best_model.zip")
    first = LearnedPolicy.load(ckpts[0])
    env_kwargs = first.env_kwargs
    from agents.plant import Plant
    from agents.rollout import make_env
    env = make_env(first.env_id, command="supervisor", control_dt=env_kwargs["control_dt"])
    names = list(Plant.from_env(env).obs_names)
    env.close()
    out = [diagnose("inner-loop", InnerLoop, env_kwargs, validator, names)]
    print(json.dumps(out[-1]))
    for p in ckpts:
        pol = LearnedPolicy.load(p, name=p.stem)
        out.append(diagnose(p.stem if p.parent.name != "best" else "best", pol.bound, pol.env_kwargs,
                            validator, names))
        print(json.dumps(out[-1]), flush=True)
    write_json(args.out, dict(run=str(args.run), rows=out))


if __name__ == "__main__":
    main()
