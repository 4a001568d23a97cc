"""Learning curves of several training runs (seeds) on one axis: mean ± std over the runs of the
validation score and of the evaluation backward-whirl rate against environment steps.

    python -m agents.training.learning_curves --group ppo=runs/ppo-scratch-0,runs/ppo-scratch-1 \\
        --group sac=runs/sac-scratch-0 --out docs/img/learning-scratch.png

Writes the PNG (mean ± std per label, each run as a thin line) and two CSVs next to it: the
mean and std per label (label, steps, number of runs, mean and std of each quantity) and, in
``<name>-runs.csv``, every run's own values (label, run, steps, each quantity). Runs of one label are aligned on the evaluation steps they share (the shortest run
decides the end). ``--quantity KEY`` (repeatable) plots other entries of the learning curve,
e.g. ``--quantity mean_relevitated --quantity mean_reward`` (:data:`TITLES` names the usual).
"""
from __future__ import annotations

import argparse
import csv
import json
import warnings
from pathlib import Path

import numpy as np

QUANTITIES = (("validation_score", "validation score"),
              ("mean_backward_whirl", "evaluation backward-whirl rate"))
#: axis titles of learning-curve entries
TITLES = dict(QUANTITIES, mean_relevitated="evaluation re-levitation rate",
              mean_reward="evaluation return", mean_stator_contact="evaluation stator-contact rate")


def curve(run: str | Path) -> list[dict]:
    """The learning curve of a run directory (its ``training.json``)."""
    path = Path(run) / "training.json"
    if not path.is_file():
        raise FileNotFoundError(f"{run}: no training.json (not a `rotordrop train` run directory)")
    return json.loads(path.read_text())["learning_curve"]


def aggregate(runs: list[str | Path], quantities=QUANTITIES) -> dict[str, np.ndarray]:
    """Steps and, per quantity, (runs, steps) values on the steps all runs evaluated."""
    curves = [curve(r) for r in runs]
    common = sorted(set.intersection(*({e["timesteps"] for e in c} for c in curves)))
    out = {"steps": np.array(common, dtype=float)}
    for key, _ in quantities:
        out[key] = np.array([[next(e.get(key, np.nan) for e in c if e["timesteps"] == s)
                              for s in common] for c in curves], dtype=float)
    return out


def _nan_stats(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and std over runs (axis 0) of the entries they have; NaN where none has one (a
    quantity a run does not record, e.g. validation_score without validation), silently."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmean(values, axis=0), np.nanstd(values, axis=0)


def write(groups: dict[str, list[str]], out: Path, quantities=QUANTITIES) -> list[Path]:
    """PNG and CSV of the labelled groups of runs (``quantities``: (key, axis title) pairs)."""
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(quantities), 1, figsize=(7, 3 * len(quantities)), sharex=True,
                             squeeze=False)
    axes = axes[:, 0]
    rows, per_run = [], []
    for i, (label, runs) in enumerate(groups.items()):
        data = aggregate(runs, quantities)
        steps = data["steps"]
        for r, run in enumerate(runs):
            per_run += [[label, str(run), int(s)] + [f"{data[k][r, j]:.6g}" for k, _ in quantities]
                        for j, s in enumerate(steps)]
        for ax, (key, title) in zip(axes, quantities):
            mean, std = _nan_stats(data[key])
            if len(runs) > 1:
                for values in data[key]:
                    ax.plot(steps, values, color=f"C{i % 10}", linewidth=0.6, alpha=0.45)
            # markers: a run that evaluated once (a short wall-clock budget) still shows; past
            # ten curves the colours repeat with another line style
            ax.plot(steps, mean, color=f"C{i % 10}", linestyle=("-", "--", ":")[i // 10 % 3],
                    marker="o", markersize=3, label=f"{label} ({len(runs)} run"
                    f"{'s' if len(runs) > 1 else ''})")
            if len(runs) > 1:
                ax.fill_between(steps, mean - std, mean + std, color=f"C{i % 10}", alpha=0.2)
            ax.set_ylabel(title)
            ax.grid(alpha=0.3)
        for j, s in enumerate(steps):
            rows.append([label, int(s), len(runs)] + [f"{v[j]:.6g}" for k, _ in quantities
                                                      for v in _nan_stats(data[k])])
    axes[0].legend(fontsize=8)
    axes[-1].set_xlabel("environment steps")
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    csv_path = out.with_suffix(".csv")
    with csv_path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["label", "timesteps", "runs"] + [f"{k}_{s}" for k, _ in quantities
                                                     for s in ("mean", "std")])
        w.writerows(rows)
    runs_path = out.with_name(f"{out.stem}-runs.csv")
    with runs_path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["label", "run", "timesteps"] + [k for k, _ in quantities])
        w.writerows(per_run)
    return [out, csv_path, runs_path]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--group", action="append", required=True, metavar="LABEL=RUN[,RUN...]",
                   help="a label and its run directories (repeatable)")
    p.add_argument("--out", required=True, help="PNG path (the CSV goes next to it)")
    p.add_argument("--quantity", action="append", default=None, metavar="KEY",
                   help="a learning-curve entry to plot (repeatable; default: "
                        + ", ".join(k for k, _ in QUANTITIES) + ")")
    args = p.parse_args(argv)
    groups = {}
    for g in args.group:
        label, _, runs = g.partition("=")
        if not label or not runs:
            p.error(f"--group {g!r}: write LABEL=RUN[,RUN...]")
        groups[label] = runs.split(",")
    quantities = (QUANTITIES if args.quantity is None
                  else tuple((k, TITLES.get(k, k)) for k in args.quantity))
    print("wrote " + ", ".join(str(f) for f in write(groups, Path(args.out), quantities)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
