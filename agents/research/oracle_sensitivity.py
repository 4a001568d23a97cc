"""Does the oracle's gain survive a change of the scenario that no sensor can resolve?

``rotordrop oracle`` optimises one open-loop command sequence per scenario, knowing the scenario
exactly. Its gain over the best designed row is the headroom that issue 15's "80 % of the
oracle's gain" rule measures learning against. This probe replays each scenario's oracle
sequence, and the designed row's, on copies of the scenario changed by far less than a
controller could ever tell apart (``PERTURBATIONS``: the unbalance phase by 1°, the friction by
0.001, the housing stiffness by 0.1 %, the speed by 1 rpm), each scored against the passive
drop of the same copy with the benchmark's formula, score = 100 (1 − ΣJ / ΣJ_passive).

If the oracle's gain is a property of the scenario (a command sequence that suits a friction,
a speed, a power-return time), it stays; if it comes from steering the exact bounce sequence of
that one drop, it vanishes on the copies, and no causal controller, which acts on sensed
signals with noise and latency, can collect it. The unchanged copy reproduces the oracle's
own J (checked).

    python -m agents.research.oracle_sensitivity runs/oracle-robust --out runs/oracle-robust/sensitivity.json
"""
from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from agents.benchmark import controller_entry, episode_kwargs
from agents.controllers import Passive
from agents.oracle import (ENV_ID, check_constants, constant_theta, episode_cost, kpi_row, rollout, search_kwargs,
                           suite_scenarios)
from agents.rollout import run_episodes
from agents.score import write_json

#: name -> (scene key, change, relative): copies of a scenario no sensor tells apart
PERTURBATIONS = {"none": None,
                 "phase +1 deg": ("unbalance.angle_deg", 1.0, False),
                 "phase -1 deg": ("unbalance.angle_deg", -1.0, False),
                 "friction +0.001": ("contact.friction", 0.001, False),
                 "friction -0.001": ("contact.friction", -0.001, False),
                 "stiffness +0.1 %": ("support.stiffness", 1e-3, True),
                 "speed +1 rpm": ("rotor.speed_rpm", 1.0, False)}


def perturbed(sc, phase: float, change) -> tuple[object, float]:
    """(scenario, unbalance phase) with ``change`` (a ``PERTURBATIONS`` value) applied."""
    if change is None:
        return sc, phase
    key, delta, relative = change
    if key == "contact.friction":
        return replace(sc, friction=sc.friction + delta), phase
    if key == "unbalance.angle_deg" and key not in sc.overrides:
        return sc, phase + delta
    base = sc.overrides.get(key)
    if base is None:                            # the scene's own value (the Full env's default)
        from physics.scene import load_scene
        base = load_scene().get(key)
    value = base * (1.0 + delta) if relative else base + delta
    return replace(sc, overrides={**sc.overrides, key: value}), phase


def replay(sc, phase: float, thetas: np.ndarray) -> tuple[list[float], float]:
    """(J of each command sequence, J_passive = 1's reference) on one scenario."""
    from rotordrop_env import BatchedRotorDropVecEnv
    entry = controller_entry(Passive, ENV_ID)
    passive = kpi_row(run_episodes(ENV_ID, entry.make, [sc.seed],
                                   episode_kwargs(entry, sc, phase))[0].kpis)
    venv = BatchedRotorDropVecEnv(ENV_ID, len(thetas), seed=0, **search_kwargs(sc, phase))
    try:
        kpis = rollout(venv, thetas, sc.env_kwargs["power_return_time"])
    finally:
        venv.close()
    return [episode_cost(kpi_row(k), passive) for k in kpis], episode_cost(passive, passive)


def sensitivity(report: dict, designed=(0.5, -0.5), progress: bool = True) -> dict:
    """Per perturbation: score of the oracle's sequences and of the designed constant law
    ``designed`` (gain, radial offset) over the oracle's scenarios, and the oracle's gain."""
    from tqdm.auto import tqdm
    s = report["settings"]
    drawn = suite_scenarios(s.get("suite", "full"), s["scenarios"], s["scenario_seed"],
                            tuple(s["ranges"]["contact.friction"]))
    found = [(d, p["search"]) for d, p in zip(drawn, report["per_scenario"]) if p.get("search")]
    sums = {name: np.zeros(3) for name in PERTURBATIONS}        # oracle, designed, passive
    reproduced = []
    bar = tqdm(total=len(found) * len(PERTURBATIONS), desc="replays", disable=not progress)
    for (sc, phase, _), search in found:
        thetas = np.array([search["theta"], constant_theta(*designed)])
        for name, change in PERTURBATIONS.items():
            (j_oracle, j_designed), j_passive = replay(*perturbed(sc, phase, change), thetas)
            sums[name] += (j_oracle, j_designed, j_passive)
            if change is None:
                reproduced.append(abs(j_oracle - search["J"]))
            bar.update(1)
    bar.close()
    rows = []
    for name, (jo, jd, jp) in sums.items():
        so, sd = 100 * (1 - jo / jp), 100 * (1 - jd / jp)
        rows.append(dict(perturbation=name, oracle=so, designed=sd, gain=so - sd))
    return dict(scenarios=len(found), designed=list(designed), rows=rows,
                max_reproduction_error_J=max(reproduced) if reproduced else None)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("oracle_dir", help="an output folder of rotordrop oracle (its oracle.json)")
    ap.add_argument("--designed", default="0.5:-0.5",
                    help="GAIN:OFFSET_R of the designed constant law (default: inner-loop-lift)")
    ap.add_argument("--out", required=True)
    a = ap.parse_args(argv)
    path = Path(a.oracle_dir) / "oracle.json"
    try:
        designed = check_constants([a.designed.split(":")])[0]
    except ValueError as exc:
        ap.error(f"--designed {a.designed!r}: {exc} (GAIN:OFFSET_R, e.g. 0.5:-0.5)")
    if not path.is_file():
        ap.error(f"{path} does not exist: give an output folder of rotordrop oracle")
    report = json.loads(path.read_text())
    if not any(p.get("search") for p in report["per_scenario"]):
        ap.error(f"{path} has no oracle search (a --no-search run): nothing to replay")
    out = sensitivity(report, designed)
    write_json(Path(a.out), out)
    print(f"{out['scenarios']} scenarios; oracle's own J reproduced to "
          f"{out['max_reproduction_error_J']:.2g}")
    print("| copy of each scenario | oracle | designed | oracle's gain |")
    print("|---|---:|---:|---:|")
    for r in out["rows"]:
        print(f"| {r['perturbation']} | {r['oracle']:.2f} | {r['designed']:.2f} | {r['gain']:+.2f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
