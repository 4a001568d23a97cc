"""Where the score's points are, and how many are left above the best designed row.

A ceiling analysis of a ``rotordrop benchmark`` output (``benchmark.json`` with its per-drop
rows). The score is 100 (1 − Σ J / Σ J_passive) and J is a sum of terms
(:func:`agents.benchmarking.score.cost_terms`: whirl verdict, whirl severity, peak force, displacement,
re-levitation failure and time), so every row's score splits into the points each term costs.
Per term this reports, in points of the score:

* the reference row (default: the best designed row of the task) and the best learned row;
* ``per-drop best row``: each drop scored by whichever row did best on it (knowing the drop in
  advance; the envelope of what the rows have shown is reachable), for the designed rows and
  for every row;
* ``term-wise best``: every term of every drop at its best value over all rows at once, with the
  re-levitation time at its floor, the power-return time (nothing re-levitates before the power
  is back). No row reaches it: the terms trade against each other (lifting harder raises the
  force and the whirl risk), so it is an optimistic estimate of the room, not a bound.

Differences to the reference carry their paired-bootstrap SE over the drops.

    python -m agents.benchmarking.headroom BENCHMARK.json [--task full] [--reference NAME] \
        [--out DIR]

writes ``headroom.json``, ``headroom.csv`` and ``headroom.png`` into ``--out`` and prints the
table.
"""
from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path

import numpy as np

from ..control.controllers import BASELINES
from .score import bootstrap_scores, cost_terms, write_json

TERMS = ("whirl", "whirl_severity", "force", "displacement", "relevitation_failure",
         "relevitation_time")


def drop_table(report: dict, task: str) -> tuple[list[str], dict, dict, np.ndarray]:
    """(row names, terms[name] (n_terms, n_drops), passive costs (n_drops,), power-return times
    (n_drops,)) of one task of a benchmark report, drops in the report's scenario order."""
    rows = [r for r in report["rows"] if r["task"] == task]
    if not rows:
        raise ValueError(f"the report has no rows of task {task!r}")
    relev = any(r.get("relevitated") is not None for r in rows)
    scenarios = list(dict.fromkeys(r["scenario"] for r in rows))
    passive = {r["scenario"]: r for r in rows if r["controller"] == "passive"}
    if set(passive) != set(scenarios):
        raise ValueError("every scenario needs its passive row")
    names = list(dict.fromkeys(r["controller"] for r in rows))
    by = {(r["controller"], r["scenario"]): r for r in rows}
    T = float(report["episode_time_s"])
    terms = {}
    for n in names:
        cols = [cost_terms(by[n, s], passive[s], T, relev, report.get("score", "legacy"))
                for s in scenarios]
        terms[n] = np.array([[c.get(k, 0.0) for c in cols] for k in TERMS])
    p_cost = terms["passive"].sum(axis=0)
    power = {sc["name"]: sc.get("env_kwargs", {}).get("power_return_time")
             for sc in report.get("scenarios", [])}
    floor = np.array([(power.get(s) or report.get("power_return_s") or 0.0) / T
                      for s in scenarios])
    return names, terms, p_cost, floor


def best_rows(cost: np.ndarray) -> np.ndarray:
    """Per drop (column of ``cost``, rows x drops), the index of the row with the lowest cost
    (the first of equals): the "per-drop best row" of a pool."""
    return np.argmin(np.asarray(cost), axis=0)


def headroom(report: dict, task: str = "full", reference: str | None = None) -> dict:
    """The per-term points of the rows and the estimates of the module docstring."""
    names, terms, p_cost, floor = drop_table(report, task)
    total = p_cost.sum()
    score = {n: 100.0 * (1.0 - terms[n].sum() / total) for n in names}
    designed = [n for n in names if n in BASELINES and n != "passive"]
    learned = [n for n in names if n not in BASELINES]
    reference = reference or max(designed, key=score.get)
    if reference not in terms:
        raise ValueError(f"--reference {reference!r} is not a row of task {task!r}: "
                         f"{', '.join(names)}")
    stack = np.array([terms[n] for n in names])                    # (rows, terms, drops)
    cost = stack.sum(axis=1)                                       # (rows, drops)
    envelope = {}
    for label, pool in (("per-drop best designed row", designed),
                        ("per-drop best row", names)):
        idx = [names.index(n) for n in pool]
        best = best_rows(cost[idx])
        envelope[label] = stack[idx][best, :, np.arange(cost.shape[1])].T   # (terms, drops)
    termwise = stack.min(axis=0)
    t_r = TERMS.index("relevitation_time")
    if terms[reference][t_r].any():                 # a task that re-levitates
        termwise[t_r] = np.minimum(termwise[t_r], floor)
    estimates = dict(envelope, **{"term-wise best (optimistic)": termwise})
    columns = {reference: terms[reference]}
    if learned:
        top = max(learned, key=score.get)
        columns[top] = terms[top]
    columns.update(estimates)
    costs = np.array([c.sum(axis=0) for c in columns.values()])
    boot = bootstrap_scores(costs, p_cost, 0)
    out = []
    for i, (label, t) in enumerate(columns.items()):
        out.append(dict(row=label, score=float(boot["score"][i]),
                        score_se=float(boot["score_se"][i]),
                        diff_vs_reference=float(boot["diff"][i]), diff_se=float(boot["diff_se"][i]),
                        points=dict(zip(TERMS, (100.0 * t.sum(axis=1) / total).tolist()))))
    return dict(task=task, reference=reference, drops=int(p_cost.size), score=report.get("score"),
                columns=out, estimate_rows=list(estimates))


def table(result: dict) -> str:
    head = "| term | " + " | ".join(f"`{c['row']}`" if i < 2 and c["row"] not in
                                     result["estimate_rows"] else c["row"]
                                     for i, c in enumerate(result["columns"])) + " |"
    lines = [head, "|---|" + "---:|" * len(result["columns"])]
    for k in TERMS:
        lines.append(f"| {k.replace('_', ' ')} | " + " | ".join(
            f"{c['points'][k]:.2f}" for c in result["columns"]) + " |")
    lines.append("| **score** | " + " | ".join(f"**{c['score']:.2f}** ± {c['score_se']:.2f}"
                                               for c in result["columns"]) + " |")
    lines.append(f"| Δ vs `{result['reference']}` | " + " | ".join(
        f"{c['diff_vs_reference']:+.2f} ± {c['diff_se']:.2f}" for c in result["columns"]) + " |")
    return "\n".join(lines)


def plot(result: dict, path: Path) -> Path:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cols = result["columns"]
    fig, ax = plt.subplots(figsize=(9, 3.2 + 0.35 * len(cols)))
    left = np.zeros(len(cols))
    for k in TERMS:
        v = np.array([c["points"][k] for c in cols])
        ax.barh(range(len(cols)), v, left=left, label=k.replace("_", " "))
        left += v
    ax.set_yticks(range(len(cols)), [c["row"] for c in cols])
    ax.invert_yaxis()
    ax.set_xlabel("points of the score lost to each term (score = 100 - total)")
    ax.legend(fontsize=8, loc="lower right")
    ax.set_title(f"Where the points go: task {result['task']}, {result['drops']} drops")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("benchmark", help="a rotordrop benchmark benchmark.json (with its rows)")
    ap.add_argument("--task", default="full", help="damping, relevitate or full (default full)")
    ap.add_argument("--reference", default=None, help="row compared with (default: the best "
                                                      "designed row)")
    ap.add_argument("--out", default="out/headroom")
    args = ap.parse_args(argv)
    report = json.loads(Path(args.benchmark).read_text())
    result = headroom(report, args.task, args.reference)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "headroom.json", result)
    with open(out / "headroom.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["row", "score", "score_se", "diff_vs_reference", "diff_se", *TERMS])
        for c in result["columns"]:
            w.writerow([c["row"], c["score"], c["score_se"], c["diff_vs_reference"],
                        c["diff_se"], *(c["points"][k] for k in TERMS)])
    plot(result, out / "headroom.png")
    print(table(result))
    print(f"wrote {out / 'headroom.json'}, headroom.csv, headroom.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
