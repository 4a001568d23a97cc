"""Diagnose a supervisor training run on the robust validation set (docs/experiments/2026-11-26-robust-collapse.md): every checkpoint of ``RUN/checkpoints`` (and ``inner-loop`` in the same
interface) on the 20 validation drops, with the score's terms split and the mean command.

    python -m agents.research.diagnose_run runs/diag-0 --out runs/diag-0/diagnosis.json
    python -m agents.research.diagnose_run runs/diag-0 --stochastic --steps 10000,40000,80000 \
        --out runs/diag-0/diagnosis-stochastic.json       # the exploring policy of training

Per row: validation score, re-levitated rate, re-levitation time after the power return
(median over the re-levitated drops), whirl rate, peak force and displacement over the passive
drop's, the mean benchmark cost J, the episode return of the KPI reward (``reward: kpi``, from
the episode's KPIs: −Φ_T + w_relevitate [re-levitated] − (time without re-levitation) / T) and
the mean action per entry (damping1, damping2, levitate, gain, offset_r1, offset_t1, offset_r2,
offset_t2) before and after the power return, the mean commanded damping of each damper as the
fraction (C - C_min) / (C_max - C_min) under the run's ``damping_action`` map (1: C_max; with
``from_max`` the raw action's mean does not say this), and when ``levitate`` first goes > 0 after
the power is observed.
"""
from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

import numpy as np

from agents.benchmarking.benchmark import EPISODE_TIME
from agents.control.controllers import InnerLoop
from agents.learning.policies import LearnedPolicy
from agents.learning.reward import WEIGHTS, kpi_potential
from agents.benchmarking.robust import robust_validator
from agents.benchmarking.score import write_json
from rotordrop_env.env import DAMPING_ACTIONS
from rotordrop_env.kernels import damper_fraction


class Recorder:
    """An actor whose actions are kept, with the observed ``amb_power`` flag of each step."""

    def __init__(self, actor, log: list, power_index: int, stochastic: bool = False):
        self.actor, self.log, self.power_index, self.stochastic = actor, log, power_index, stochastic

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        action, state = self.actor.predict(obs, state=state, episode_start=episode_start,
                                           deterministic=deterministic and not self.stochastic)
        if episode_start is not None and bool(np.asarray(episode_start).ravel()[0]):
            self.log.append([])                         # a new episode
        self.log[-1].append((float(obs[0, self.power_index]), np.atleast_1d(np.asarray(action[0], float))))
        return action, state


def kpi_return(row: dict) -> float:
    """The KPI reward's episode return from a validation row's KPIs (agents/learning/reward.py)."""
    w = {k: v for k, v in WEIGHTS.items() if k not in ("w_relevitate", "w_time")}
    phi = kpi_potential(min(row["peak_whirl_revolutions"], 3.0), row["peak_contact_force_N"],
                        row["max_displacement_um"], **w)
    relev = bool(row["relevitated"])
    pending = (row["relevitation_time_s"] + 0.02) if relev else EPISODE_TIME
    return float(-phi + WEIGHTS["w_relevitate"] * relev - WEIGHTS["w_time"] * pending / EPISODE_TIME)


def diagnose(name: str, make, env_kwargs: dict, validator, names: list[str],
             stochastic: bool = False) -> dict:
    log: list = []
    power_index = names.index("amb_power")
    score, rows = validator.score(lambda plant: Recorder(make(plant), log, power_index, stochastic),
                                  env_kwargs)
    passive = {r["scenario"]: r for r in validator.passive}
    pr = {s.name: s.env_kwargs["power_return_time"] for s in validator.scenarios}
    relev = [r for r in rows if r["relevitated"]]
    steps = [s for ep in log for s in ep]
    power = np.array([p for p, _ in steps]) > 0.5
    acts = np.array([a for _, a in steps])
    delays = [switch_delay_ms(ep, env_kwargs["control_dt"]) for ep in log]
    frac = damper_fractions(acts[:, :2], env_kwargs.get("damping_action", "linear"))
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
        kpi_return=float(np.mean([kpi_return(r) for r in rows])),
        mean_action_before_power=acts[~power].mean(axis=0).round(3).tolist(),
        mean_action_after_power=acts[power].mean(axis=0).round(3).tolist(),
        mean_abs_action_after_power=np.abs(acts[power]).mean(axis=0).round(3).tolist(),
        mean_damper_fraction_before_power=frac[~power].mean(axis=0).round(3).tolist(),
        mean_damper_fraction_after_power=frac[power].mean(axis=0).round(3).tolist(),
        never_switched_on=float(np.mean([d is None for d in delays])),
        switch_on_after_power_ms_median=(float(np.median([d for d in delays if d is not None]))
                                         if any(d is not None for d in delays) else None))


def damper_fractions(actions: np.ndarray, damping_action: str) -> np.ndarray:
    """(C - C_min) / (C_max - C_min) commanded by each damper action under the env's map."""
    mode = DAMPING_ACTIONS[damping_action]
    return np.vectorize(lambda a: damper_fraction(a, mode), otypes=[float])(actions)


def switch_delay_ms(episode, dt: float):
    """Time from the first step that observes the power until ``levitate`` > 0 (None: never)."""
    on = [i for i, (p, a) in enumerate(episode) if p > 0.5]
    hit = [i for i in on if episode[i][1][2] > 0.0]
    return 1e3 * dt * (hit[0] - on[0]) if on and hit else None


def step_of(checkpoint: Path) -> int:
    """The training step of an SB3 checkpoint ``..._<step>_steps.zip``."""
    return int(re.search(r"_(\d+)_steps\.zip$", checkpoint.name)[1])


def checkpoints(run: Path) -> list[Path]:
    return sorted((run / "checkpoints").glob("*_steps.zip"), key=step_of)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run", type=Path)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--every", type=int, default=1, help="every k-th checkpoint")
    ap.add_argument("--steps", default=None, help="only these checkpoints (comma-separated steps)")
    ap.add_argument("--stochastic", action="store_true",
                    help="sample the policies' actions (the exploring policy of training)")
    args = ap.parse_args(argv)
    validator = robust_validator()
    ckpts = checkpoints(args.run)[::args.every]
    if args.steps:
        wanted = {int(s) for s in args.steps.split(",")}
        ckpts = [p for p in checkpoints(args.run) if step_of(p) in wanted]
    if (args.run / "best" / "best_model.zip").is_file():
        ckpts.append(args.run / "best" / "best_model.zip")
    first = LearnedPolicy.load(ckpts[0])
    env_kwargs = first.env_kwargs
    from agents.control.plant import Plant
    from agents.benchmarking.rollout import make_env
    env = make_env(first.env_id, command="supervisor", control_dt=env_kwargs["control_dt"])
    names = list(Plant.from_env(env).obs_names)
    env.close()
    out = [diagnose("inner-loop", InnerLoop, env_kwargs, validator, names)]
    print(json.dumps(out[-1]))
    for p in ckpts:
        pol = LearnedPolicy.load(p, name=p.stem)
        out.append(diagnose(p.stem if p.parent.name != "best" else "best", pol.bound, pol.env_kwargs,
                            validator, names, args.stochastic))
        print(json.dumps(out[-1]), flush=True)
    write_json(args.out, dict(run=str(args.run), rows=out))


if __name__ == "__main__":
    main()
