"""How much of the oracle's gain can a controller collect that cannot tell the friction apart?

``rotordrop oracle`` searches one command sequence per scenario knowing the scenario exactly,
its friction included. :mod:`agents.research.oracle_sensitivity` found that its gain shrinks
most when the friction is changed by 0.001, far below what any sensor or estimator resolves
over the robust range 0.3-0.6. This probe asks the fairer question: the *blind oracle* runs the
same cross-entropy search (:func:`agents.research.oracle.search_scenario`, same population and
iterations) but scores every candidate sequence by its mean J over three copies of the
scenario, friction mu - delta, mu and mu + delta, so it must find one sequence that suits all
three, as a controller that knows everything but the friction to within delta must. It starts
from the designed constant law (``inner-loop-lift``), so it never ends worse than that on the
copies' mean.

Per scenario (the ``--top`` K where the oracle gains most over the designed row, from an
``oracle.json`` or the compact JSON of ``docs/img``) it reports on each copy the J of the
designed law, of the exact oracle's sequence and of the blind oracle's, and sums them as points
of the whole suite's score, 100 x sum(J_designed - J) / sum(J_passive of every scenario in the
report). The blind oracle bounds open-loop plans from below, not feedback: a controller that
sees the bounce sequence diverge could react; the probe measures what knowing the drop to the
last 0.001 of friction is worth to a plan.

    python -m agents.research.blind_oracle docs/img/oracle-robust-200-start.json --top 8 --out runs/blind-oracle.json
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from agents.research.oracle import check_constants, constant_theta, search_scenario, suite_scenarios
from agents.research.oracle_sensitivity import (largest_gains, passive_row, perturbed, replay, row_J,
                                                searches)
from agents.benchmarking.score import write_json

COPIES = (0.0, -1.0, 1.0)          # friction of each copy: mu + k delta (the scenario first)


def suite_passive_J(report: dict) -> float:
    """Sum of the passive drops' J over every scenario of the report (the score's denominator)."""
    return float(sum(row_J(p, "passive") for p in report["per_scenario"]))


def blind_oracle(report: dict, top: int = 8, delta: float = 1e-3, population: int | None = None,
                 iterations: int | None = None, designed=(0.5, -0.5), seed: int = 0,
                 progress: bool = True) -> dict:
    """The blind oracle on the ``top`` scenarios of ``report`` (module doc)."""
    from tqdm.auto import tqdm
    if not 0.0 < delta <= 0.05:
        raise ValueError(f"delta = {delta!r} must be in (0, 0.05] (a friction change)")
    s = report["settings"]
    population = population or s["population"]
    iterations = iterations or s["iterations"]
    drawn = suite_scenarios(s.get("suite", "full"), s["scenarios"], s["scenario_seed"],
                            tuple(s["ranges"]["contact.friction"]))
    found = largest_gains(searches(report, designed), top, designed)
    scale = 100.0 / suite_passive_J(report)
    per_scenario = []
    for f in tqdm(found, desc="blind oracle", disable=not progress):
        sc, phase, _ = drawn[f["position"]]
        copies = [perturbed(sc, phase, ("contact.friction", k * delta, False)) for k in COPIES]
        drops = [(c, ph, passive_row(c, ph)) for c, ph in copies]
        found_blind = search_scenario(*drops[0], population, iterations, seed, False,
                                      start=constant_theta(*designed), copies=tuple(drops[1:]))
        thetas = np.array([constant_theta(*designed), f["theta"], found_blind["theta"]])
        rows = []
        for k, (c, ph) in zip(COPIES, copies):
            (j_d, j_o, j_b), (w_d, w_o, w_b), j_p = replay(c, ph, thetas)
            rows.append(dict(friction_change=k * delta, J_designed=j_d, J_oracle=j_o, J_blind=j_b,
                             J_passive=j_p, whirl_designed=w_d, whirl_oracle=w_o, whirl_blind=w_b))
        per_scenario.append(dict(position=f["position"], seed=sc.seed, friction=sc.friction,
                                 copies=rows, blind_theta=found_blind["theta"],
                                 blind_rollouts=found_blind["rollouts"]))
    summary = {}
    for k in COPIES:
        rows = [r for p in per_scenario for r in p["copies"] if r["friction_change"] == k * delta]
        summary[f"{k * delta:+g}"] = dict(
            oracle_gain_points=scale * sum(r["J_designed"] - r["J_oracle"] for r in rows),
            blind_gain_points=scale * sum(r["J_designed"] - r["J_blind"] for r in rows),
            whirls=dict(designed=sum(r["whirl_designed"] for r in rows),
                        oracle=sum(r["whirl_oracle"] for r in rows),
                        blind=sum(r["whirl_blind"] for r in rows)))
    mean = {key: float(np.mean([v[key] for v in summary.values()]))
            for key in ("oracle_gain_points", "blind_gain_points")}
    return dict(scenarios=len(found), delta=delta, population=population, iterations=iterations,
                designed=list(designed), points_per_unit_J=scale, per_copy=summary,
                mean_over_copies=mean, per_scenario=per_scenario)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("oracle", help="an output folder of rotordrop oracle (its oracle.json), or "
                                   "a compact oracle JSON as in docs/img")
    ap.add_argument("--top", type=int, default=8, metavar="K",
                    help="the K scenarios where the oracle gains most over the designed row")
    ap.add_argument("--delta", type=float, default=1e-3,
                    help="friction change of the copies (default 0.001)")
    ap.add_argument("--population", type=int, default=None, help="default: the oracle's")
    ap.add_argument("--iterations", type=int, default=None, help="default: the oracle's")
    ap.add_argument("--designed", default="0.5:-0.5",
                    help="GAIN:OFFSET_R of the designed constant law (default: inner-loop-lift)")
    ap.add_argument("--out", required=True)
    a = ap.parse_args(argv)
    path = Path(a.oracle)
    path = path / "oracle.json" if path.is_dir() else path
    if not path.is_file():
        ap.error(f"{path} does not exist: give an output folder of rotordrop oracle or its JSON")
    if a.top < 1:
        ap.error(f"--top must be >= 1, got {a.top}")
    for flag, v in (("--population", a.population), ("--iterations", a.iterations)):
        if v is not None and v < 2:
            ap.error(f"{flag} must be >= 2, got {v}")
    try:
        designed = check_constants([a.designed.split(":")])[0]
        out = blind_oracle(json.loads(path.read_text()), a.top, a.delta, a.population,
                           a.iterations, designed)
    except ValueError as exc:
        ap.error(str(exc))
    write_json(Path(a.out), out)
    print(f"{out['scenarios']} scenarios, friction copies ±{out['delta']:g}, "
          f"{out['population']} x {out['iterations']} search; gains in points of the suite score")
    print("| friction of the copy | exact oracle's gain | blind oracle's gain | whirls: designed | oracle | blind |")
    print("|---|---:|---:|---:|---:|---:|")
    for key, v in out["per_copy"].items():
        w = v["whirls"]
        print(f"| {key} | {v['oracle_gain_points']:+.2f} | {v['blind_gain_points']:+.2f} "
              f"| {w['designed']} | {w['oracle']} | {w['blind']} |")
    m = out["mean_over_copies"]
    print(f"| mean | {m['oracle_gain_points']:+.2f} | {m['blind_gain_points']:+.2f} | | | |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
