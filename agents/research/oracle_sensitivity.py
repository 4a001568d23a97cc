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

The input is an output folder of ``rotordrop oracle`` (its ``oracle.json``) or a compact
per-scenario JSON as kept in ``docs/img`` (``oracle_theta`` and ``J`` per scenario). ``--top K``
replays only the K scenarios where the oracle gains most over the designed row, where most of
its headroom sits (the per-scenario J, passive J and whirl of every copy are in the output).
"""
from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from agents.benchmarking.benchmark import controller_entry, episode_kwargs
from agents.control.controllers import Passive
from agents.research.oracle import (ENV_ID, check_constants, constant_name, constant_theta, episode_cost, kpi_row,
                           rollout, search_kwargs, suite_scenarios)
from agents.benchmarking.rollout import run_episodes
from agents.benchmarking.score import write_json

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
        return sc, (phase + delta) % 360.0
    base = sc.overrides.get(key)
    if base is None:                            # the scene's own value (the Full env's default)
        from physics.scene import load_scene
        base = load_scene().get(key)
    value = base * (1.0 + delta) if relative else base + delta
    if key == "unbalance.angle_deg":
        value %= 360.0                          # 359.5 deg + 1 deg is 0.5 deg
    return replace(sc, overrides={**sc.overrides, key: value}), phase


def passive_row(sc, phase: float) -> dict:
    """The benchmark row of the passive drop of one scenario (the reference of its J)."""
    entry = controller_entry(Passive, ENV_ID)
    return kpi_row(run_episodes(ENV_ID, entry.make, [sc.seed],
                                episode_kwargs(entry, sc, phase))[0].kpis)


def replay(sc, phase: float, thetas: np.ndarray) -> tuple[list[float], list[bool], float]:
    """(J of each command sequence, whether it whirls, J_passive = 1's reference) on one
    scenario."""
    from rotordrop_env import BatchedRotorDropVecEnv
    passive = passive_row(sc, phase)
    venv = BatchedRotorDropVecEnv(ENV_ID, len(thetas), seed=0, **search_kwargs(sc, phase))
    try:
        rows = [kpi_row(k) for k in rollout(venv, thetas, sc.env_kwargs["power_return_time"],
                                            sc.seed)]
    finally:
        venv.close()
    return ([episode_cost(r, passive) for r in rows], [bool(r["backward_whirl"]) for r in rows],
            episode_cost(passive, passive))


def row_J(scenario: dict, name: str) -> float | None:
    """J of row ``name`` in one ``per_scenario`` entry of an ``oracle.json`` (``rows``) or of the
    compact form of ``docs/img`` (``J``); None if the report does not hold that row."""
    if "rows" in scenario:
        return scenario["rows"].get(name, {}).get("J")
    return scenario.get("J", {}).get(name)


def searches(report: dict, designed=(0.5, -0.5)) -> list[dict]:
    """Per searched scenario: its position in the suite, the oracle's sequence and J, and the
    designed row's J where the report holds it (None otherwise). Reads both an ``oracle.json``
    (``search`` and ``rows`` per scenario) and the compact form of ``docs/img``
    (``oracle_theta`` and ``J``)."""
    name = constant_name(*designed)
    found = []
    for pos, p in enumerate(report["per_scenario"]):
        if p.get("search"):
            theta, j = p["search"]["theta"], p["search"]["J"]
        elif p.get("oracle_theta") is not None:
            theta, j = p["oracle_theta"], p["J"]["oracle"]
        else:
            continue
        found.append(dict(position=pos, theta=theta, J=j, J_designed=row_J(p, name)))
    return found


def largest_gains(found: list[dict], top: int | None, designed=(0.5, -0.5)) -> list[dict]:
    """The ``top`` searches of :func:`searches` with the largest oracle gain over the designed
    row, largest first (all of them, in suite order, when ``top`` is None)."""
    if top is None:
        return found
    if any(f["J_designed"] is None for f in found):
        raise ValueError(f"top={top} needs the designed row {constant_name(*designed)!r} "
                         "in the report (run rotordrop oracle with --constant)")
    return sorted(found, key=lambda f: f["J_designed"] - f["J"], reverse=True)[:top]


def sensitivity(report: dict, designed=(0.5, -0.5), top: int | None = None,
                progress: bool = True) -> dict:
    """Per perturbation: score of the oracle's sequences and of the designed constant law
    ``designed`` (gain, radial offset) over the oracle's scenarios (the ``top`` ones by the
    oracle's gain over it, if given), and the oracle's gain."""
    from tqdm.auto import tqdm
    s = report["settings"]
    drawn = suite_scenarios(s.get("suite", "full"), s["scenarios"], s["scenario_seed"],
                            tuple(s["ranges"]["contact.friction"]))
    found = largest_gains(searches(report, designed), top, designed)
    sums = {name: np.zeros(3) for name in PERTURBATIONS}        # oracle, designed, passive
    reproduced, per_scenario = [], []
    bar = tqdm(total=len(found) * len(PERTURBATIONS), desc="replays", disable=not progress)
    for f in found:
        sc, phase, _ = drawn[f["position"]]
        thetas = np.array([f["theta"], constant_theta(*designed)])
        copies = {}
        for name, change in PERTURBATIONS.items():
            (j_oracle, j_designed), (w_oracle, w_designed), j_passive = replay(
                *perturbed(sc, phase, change), thetas)
            sums[name] += (j_oracle, j_designed, j_passive)
            copies[name] = dict(J_oracle=j_oracle, J_designed=j_designed, J_passive=j_passive,
                                whirl_oracle=w_oracle, whirl_designed=w_designed)
            if change is None:
                reproduced.append(abs(j_oracle - f["J"]))
            bar.update(1)
        per_scenario.append(dict(position=f["position"], seed=sc.seed, copies=copies))
    bar.close()
    rows = []
    for name, (jo, jd, jp) in sums.items():
        so, sd = 100 * (1 - jo / jp), 100 * (1 - jd / jp)
        whirl = [sum(p["copies"][name][k] for p in per_scenario)
                 for k in ("whirl_oracle", "whirl_designed")]
        rows.append(dict(perturbation=name, oracle=so, designed=sd, gain=so - sd,
                         oracle_whirls=whirl[0], designed_whirls=whirl[1]))
    return dict(scenarios=len(found), top=top, designed=list(designed), rows=rows,
                max_reproduction_error_J=max(reproduced) if reproduced else None,
                per_scenario=per_scenario)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("oracle", help="an output folder of rotordrop oracle (its oracle.json), or "
                                   "a compact oracle JSON as in docs/img")
    ap.add_argument("--designed", default="0.5:-0.5",
                    help="GAIN:OFFSET_R of the designed constant law (default: inner-loop-lift)")
    ap.add_argument("--top", type=int, default=None, metavar="K",
                    help="replay only the K scenarios where the oracle gains most over the "
                         "designed row (default: every searched scenario)")
    ap.add_argument("--out", required=True)
    a = ap.parse_args(argv)
    path = Path(a.oracle)
    path = path / "oracle.json" if path.is_dir() else path
    try:
        designed = check_constants([a.designed.split(":")])[0]
    except ValueError as exc:
        ap.error(f"--designed {a.designed!r}: {exc} (GAIN:OFFSET_R, e.g. 0.5:-0.5)")
    if a.top is not None and a.top < 1:
        ap.error(f"--top must be >= 1, got {a.top}")
    if not path.is_file():
        ap.error(f"{path} does not exist: give an output folder of rotordrop oracle or its JSON")
    report = json.loads(path.read_text())
    found = searches(report, designed)
    if not found:
        ap.error(f"{path} has no oracle search (a --no-search run): nothing to replay")
    if a.top is not None and any(f["J_designed"] is None for f in found):
        ap.error(f"--top needs the designed row {a.designed} in {path} (run rotordrop oracle "
                 f"with --constant {a.designed})")
    out = sensitivity(report, designed, a.top)
    write_json(Path(a.out), out)
    print(f"{out['scenarios']} scenarios; oracle's own J reproduced to "
          f"{out['max_reproduction_error_J']:.2g}")
    print("| copy of each scenario | oracle | designed | oracle's gain | whirls: oracle | designed |")
    print("|---|---:|---:|---:|---:|---:|")
    for r in out["rows"]:
        print(f"| {r['perturbation']} | {r['oracle']:.2f} | {r['designed']:.2f} | {r['gain']:+.2f} "
              f"| {r['oracle_whirls']} | {r['designed_whirls']} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
