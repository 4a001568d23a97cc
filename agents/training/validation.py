"""Model selection on the validation suite, for ``rotordrop train`` and for rl-zoo3.

:func:`validation_score` is the benchmark score (:class:`agents.benchmarking.benchmark.Validator`: frictions
and unbalance phases the benchmark does not use) of a model being trained, run as the saved
policy will run: its observation normalisation and, for a residual policy, its baseline. On the
Recover task it is the recovery score on the recover suite's validation events
(:class:`agents.benchmarking.recover.RecoverValidator`: recovered %, ties broken by the mean
peak contact force; ``events`` of them).

:class:`ValidationCallback` runs it as an SB3 callback, the one class for both: rl-zoo3 builds it
from a config's ``callback:`` entry (``agents.training.validation.ValidationCallback``; in
``rotordrop train`` that entry means ``validation: true``) and scores every ``eval_freq``
environment steps; ``rotordrop train`` scores after each of its KPI evaluations. Both also
score the initial policy as training starts (a fresh run), so a model that training made
worse is never kept over it. It logs ``eval/validation_score`` and, with a ``save_path``,
keeps the best-scoring model there as a self-contained zip (:mod:`agents.sb3_policy`) that
plain SB3 loads, with ``validation.json``: every score (steps, score, and on the Recover task
the events recovered) and the best.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback

#: rl-zoo3's default evaluation interval [environment steps]
EVAL_FREQ = 25_000


def validator_for(env_id: str, env_kwargs: dict | None = None, events: int | None = None):
    """The validation set of a training run on ``env_id`` with ``env_kwargs``: on the Recover
    task the recover suite's validation events (:class:`agents.benchmarking.recover.RecoverValidator`,
    the first ``events`` of them, default ``VALIDATION_EVENTS``; ``recover-robust``'s when the
    run senses with noise or delay), else the drop validation suite
    (:func:`agents.benchmarking.robust.validator_for`); ``events`` on another task is a
    ValueError."""
    from ..benchmarking import recover
    from ..benchmarking.robust import is_robust
    from ..benchmarking.robust import validator_for as drop_validator
    if env_id == recover.ENV_ID:
        from ..benchmarking.suites import SUITES
        suite = SUITES.get("recover-robust" if is_robust(env_kwargs or {}) else "recover")
        return recover.RecoverValidator(suite, recover.VALIDATION_EVENTS if events is None
                                        else events)
    if events is not None:
        raise ValueError(f"validation_events = {events!r}: only {recover.ENV_ID} validates on "
                         f"events; {env_id} validates on its validation drops (remove it)")
    return drop_validator(env_id, env_kwargs)


def validation_score(validator, model, algo: str, env_id: str, env_kwargs: dict, vecnormalize,
                     residual: str | dict | None = None, residual_scale: float | None = None,
                     frame_stack: int | None = None) -> tuple[float, list[dict]]:
    """The benchmark score of ``model`` (with its ``vecnormalize``, ``residual`` and
    ``frame_stack``; None: read from the model's training env) on the validation suite of
    ``validator``, and its rows (per validation drop or event)."""
    from ..learning.policies import LearnedPolicy
    pol = LearnedPolicy("candidate", algo, env_id, env_kwargs, model, vecnormalize,
                        frame_stack=frame_stack)
    if residual is not None:
        pol.residual, pol.residual_scale = residual, residual_scale
    return validator.score(pol.bound, env_kwargs)


class ValidationCallback(BaseCallback):
    """The validation score of the deterministic policy, logged as ``eval/validation_score``
    (and printed with ``verbose``); the best model so far is saved to ``save_path/best_model.zip``
    (self-contained) when ``save_path`` is given.

    rl-zoo3 builds it from a config's ``callback:`` entry (``callback: -
    agents.training.validation.ValidationCallback: {save_path: DIR}``): it scores every
    ``eval_freq`` environment steps and reads the env id, its kwargs, the residual and the
    algorithm from the training env and the model. ``rotordrop train`` (``validation: true``)
    passes ``evaluations``, its KPI evaluation: the score follows each of its evaluations and is
    written into that evaluation's learning-curve entry; ``policy`` (``env_id``, ``algo``,
    ``env_kwargs``, ``residual``, ``residual_scale``, ``frame_stack``) says what the run trains,
    ``best`` is a continued run's best score so far and ``save(model, path)`` saves the best model
    (default: :func:`agents.sb3_policy.export_self_contained`). ``events``: on the Recover task,
    how many of the recover suite's validation events score a model (default
    :data:`agents.benchmarking.recover.VALIDATION_EVENTS`; a ValueError on other tasks).
    """

    def __init__(self, eval_freq: int = EVAL_FREQ, save_path: str | None = None, verbose: int = 1,
                 *, evaluations=None, policy: dict | None = None, best: float = -np.inf,
                 save=None, events: int | None = None):
        super().__init__(verbose)
        if int(eval_freq) != eval_freq or eval_freq < 1:
            raise ValueError(f"ValidationCallback: eval_freq = {eval_freq!r} must be an integer >= 1")
        self.eval_freq = int(eval_freq)
        self.save_path = None if save_path is None else Path(save_path)
        self.evaluations, self.policy, self.save = evaluations, policy, save
        self.best, self.events = best, events
        self.history: list[dict] = []
        self.last = 0
        self.seen = 0 if evaluations is None else len(evaluations.kpi_history)
        self.validator = None

    def _init_callback(self) -> None:
        if self.policy is not None:
            self.env_id, self.env_kwargs = self.policy["env_id"], dict(self.policy["env_kwargs"])
            self.algo = self.policy["algo"]
        else:
            spec = self.training_env.get_attr("spec", [0])[0]
            self.env_id, self.env_kwargs = spec.id, dict(spec.kwargs)
            self.algo = type(self.model).__name__.lower()
        self.validator = validator_for(self.env_id, self.env_kwargs, self.events)
        if self.save_path is not None:
            self.save_path.mkdir(parents=True, exist_ok=True)
            kept = self.save_path / "validation.json"
            if self.model.num_timesteps > 0 and kept.is_file():     # a continued run's scores
                import json
                self.history = json.loads(kept.read_text()).get("history", [])

    def _on_training_start(self) -> None:
        if self.model.num_timesteps == 0:           # a fresh run: the initial policy is a candidate
            self.validate()

    def _on_step(self) -> bool:
        if self.evaluations is not None:
            if len(self.evaluations.kpi_history) != self.seen:
                self.seen = len(self.evaluations.kpi_history)
                self.evaluations.kpi_history[-1]["validation_score"] = self.validate()
        elif self.num_timesteps - self.last >= self.eval_freq:
            self.last = self.num_timesteps
            self.validate()
        return True

    def _on_training_end(self) -> None:
        if self.evaluations is not None:
            self._on_step()                         # scores the final evaluation, if any
            self.logger.dump(self.num_timesteps)

    def validate(self) -> float:
        vn = self.model.get_vec_normalize_env()
        if self.policy is not None:
            residual, scale = self.policy.get("residual"), self.policy.get("residual_scale")
            frame_stack = self.policy.get("frame_stack", 1)
        else:
            from ..control.residual import residual_of
            residual, scale = residual_of(self.training_env)
            frame_stack = None
        score, rows = validation_score(self.validator, self.model, self.algo, self.env_id,
                                       self.env_kwargs, vn, residual, scale, frame_stack)
        self.logger.record("eval/validation_score", score)
        entry = {"timesteps": int(self.num_timesteps), "score": float(score)}
        if rows and "recovered" in rows[0]:          # Recover events
            entry.update(recovered=int(sum(r["recovered"] for r in rows)), events=len(rows))
        self.history.append(entry)
        if self.verbose:
            print(f"validation score {score:.2f} at {self.num_timesteps} steps (best {max(score, self.best):.2f})")
        if score > self.best:
            self.best = score
            if self.save_path is not None:
                path = self.save_path / "best_model.zip"
                if self.save is not None:
                    self.save(self.model, path)
                else:
                    from ..sb3_policy import export_self_contained
                    export_self_contained(self.model, vn, path, env_id=self.env_id,
                                          env_kwargs=self.env_kwargs, residual=residual,
                                          residual_scale=scale)
        if self.save_path is not None:
            from ..benchmarking.score import write_json
            write_json(self.save_path / "validation.json",
                       {"env_id": self.env_id, "best": self.best, "history": self.history})
        return score


def _history(run: Path) -> list[dict]:
    """A run's validation scores as its callback kept them (``best/validation.json``)."""
    import json
    return json.loads((run / "best" / "validation.json").read_text())["history"]


def selection_rows(runs) -> list[dict]:
    """Per training run directory of ``runs`` (``rotordrop train --out``, with ``validation:
    true``): its steps, wall time, whether the time limit stopped it, and from
    ``best/validation.json`` the initial, kept (best) and final validation scores, the step of the
    kept one and, on the Recover task, the events each recovered."""
    import json
    out = []
    for run in map(Path, runs):
        rec = json.loads((run / "training.json").read_text())
        hist = _history(run)
        best = max(hist, key=lambda h: h["score"])      # the first of equals: the one kept
        row = {"run": run.name, "steps": rec["timesteps"], "wall_s": round(rec["wall_time_s"], 1),
               "stopped_by_time_limit": bool(rec.get("stopped_by_time_limit")),
               "checks": len(hist), "kept_step": best["timesteps"]}
        for key, h in (("initial", hist[0]), ("kept", best), ("final", hist[-1])):
            row[f"{key}_score"] = round(h["score"], 2)
            if "recovered" in h:
                row[f"{key}_recovered"] = f"{h['recovered']}/{h['events']}"
        out.append(row)
    return out


def plot_selection(runs, path) -> Path:
    """Each run's validation scores against its environment steps (``best/validation.json``),
    the kept model marked: a PNG at ``path``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 4))
    for run in map(Path, runs):
        hist = _history(run)
        best = max(hist, key=lambda h: h["score"])
        line, = ax.plot([h["timesteps"] for h in hist], [h["score"] for h in hist], "o-", ms=3,
                        label=run.name)
        ax.plot([best["timesteps"]], [best["score"]], "*", ms=12, color=line.get_color())
    ax.set_xlabel("environment steps")
    ax.set_ylabel("validation score (kept: star)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def main(argv=None) -> int:
    """``python -m agents.training.validation RUN... [--csv FILE] [--png FILE]``: the model
    selection of each run (:func:`selection_rows`) as a markdown table (and a CSV; the scores
    against the steps as a PNG, :func:`plot_selection`)."""
    import argparse
    import csv
    ap = argparse.ArgumentParser(description="what model selection kept in each training run")
    ap.add_argument("runs", nargs="+", help="rotordrop train output directories")
    ap.add_argument("--csv", default=None, help="also write the rows to this CSV file")
    ap.add_argument("--png", default=None, help="also plot the validation scores to this PNG")
    a = ap.parse_args(argv)
    if a.png:
        plot_selection(a.runs, a.png)
    rows = selection_rows(a.runs)
    keys = list(dict.fromkeys(k for r in rows for k in r))
    print("| " + " | ".join(k.replace("_", " ") for k in keys) + " |")
    print("|---|" + "---:|" * (len(keys) - 1))
    for r in rows:
        print("| " + " | ".join(str(r.get(k, "—")) for k in keys) + " |")
    if a.csv:
        with open(a.csv, "w", newline="") as fh:
            w = csv.DictWriter(fh, keys)
            w.writeheader()
            w.writerows(rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
