"""The SB3 callbacks of ``rotordrop train`` (:func:`agents.training.train.train` builds them
in :func:`~agents.training.train._training_callbacks`), one small class each:

* :class:`KpiEvalCallback`: SB3's evaluation, also recording the episodes' KPIs and the wall time;
* :class:`SaveBest`: a new best evaluation's model as a self-contained zip in ``best/``;
* :class:`TqdmCallback`: a progress bar over environment steps;
* :class:`FinalCheckpoint`: checkpoints, and the final model as one;
* :class:`RecordCallback`: ``training.json`` after every evaluation and at the end;
* :class:`WallClockLimit`: the ``--time-limit`` budget.

Importing this module imports Stable-Baselines3 (:mod:`agents.training.train` imports it only when a
run starts).
"""
from __future__ import annotations

import time
from pathlib import Path
from typing import Callable

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback, CheckpointCallback, EvalCallback

from ..benchmarking.rollout import final_kpis
from ..benchmarking.score import mean_finite, write_json


def _run_now(cb, freq_attr: str) -> None:
    """Run a periodic SB3 callback's action at the current step (``n_calls % n_calls == 0``)
    unless it is disabled, no step was taken or this step already ran it."""
    freq = getattr(cb, freq_attr)
    if freq <= 0 or cb.n_calls == 0 or cb.n_calls % freq == 0:
        return
    cb.num_timesteps = cb.model.num_timesteps
    setattr(cb, freq_attr, cb.n_calls)
    try:
        cb._on_step()
    finally:
        setattr(cb, freq_attr, freq)


class SaveBest(BaseCallback):
    """On a new best evaluation: ``save(model, best_dir / "best_model.zip")`` (the training
    saves a self-contained zip over the plain one EvalCallback wrote, and its VecNormalize
    statistics next to it: :func:`agents.training.train.save_policy`)."""

    def __init__(self, best_dir: Path, save: Callable[[object, Path], None]):
        super().__init__()
        self.best_dir, self.save = Path(best_dir), save

    def _on_step(self) -> bool:
        self.save(self.model, self.best_dir / "best_model.zip")
        return True

class KpiEvalCallback(EvalCallback):
    """EvalCallback that also records the episode KPIs (backward whirl, peak force...) and
    the wall-clock time since this session's training started (``wall_time_s``)."""

    def __init__(self, *args, eval_seed: int = 0, **kwargs):
        super().__init__(*args, **kwargs)
        self.eval_seed = eval_seed
        self.kpi_history: list[dict] = []
        self._kpis: list[dict] = []
        self.t0 = time.perf_counter()

    def _on_training_start(self):
        super()._on_training_start()
        self.t0 = time.perf_counter()

    def _log_success_callback(self, locals_, globals_):
        super()._log_success_callback(locals_, globals_)
        if locals_["done"]:
            kpis = {k: None if v is None else float(v)      # None: the KPI does not exist
                    for k, v in final_kpis(locals_["info"]).items()}
            kpis["failure"] = float(any(kpis.get(k, 0.0) for k in
                                        ("backward_whirl", "stator_contact", "bearing_overload")))
            self._kpis.append(kpis)

    def _on_step(self) -> bool:
        self._kpis = []
        if self.eval_freq > 0 and self.n_calls % self.eval_freq == 0:
            self.eval_env.seed(self.eval_seed)      # the same scenarios at every evaluation
        n_before = len(self.evaluations_timesteps)
        cont = super()._on_step()
        if len(self.evaluations_timesteps) > n_before:
            rewards = self.evaluations_results[-1]
            entry = dict(timesteps=int(self.num_timesteps), mean_reward=float(np.mean(rewards)),
                         std_reward=float(np.std(rewards)),
                         wall_time_s=time.perf_counter() - self.t0)
            for key in sorted({k for d in self._kpis for k in d}):
                mean = mean_finite(d.get(key) for d in self._kpis)      # None (no value) skipped
                if mean is not None:
                    entry[f"mean_{key}"] = mean
                    self.logger.record(f"eval/{key}", mean)
            self.kpi_history.append(entry)
        return cont

    def _on_training_end(self):
        _run_now(self, "eval_freq")          # the final model, unless just evaluated

class TqdmCallback(BaseCallback):
    """A tqdm progress bar over environment steps (no `rich` dependency)."""

    def __init__(self, total: int, eval_cb=None):
        super().__init__()
        self.total, self.eval_cb, self.bar = total, eval_cb, None

    def _on_training_start(self):
        from tqdm.auto import tqdm
        self.bar = tqdm(total=self.total, initial=self.model.num_timesteps, unit="step",
                        desc="train", dynamic_ncols=True, mininterval=1.0)

    def _on_step(self) -> bool:
        self.bar.update(self.training_env.num_envs)
        if self.eval_cb is not None and self.eval_cb.kpi_history and self.n_calls % 50 == 0:
            last = self.eval_cb.kpi_history[-1]
            extra = ({"validation": f"{last['validation_score']:.1f}"}
                     if "validation_score" in last else {})
            self.bar.set_postfix(eval_reward=f"{last['mean_reward']:.1f}",
                                 failure=f"{last.get('mean_failure', float('nan')):.2f}", **extra)
        return True

    def _on_training_end(self):
        self.bar.close()

class FinalCheckpoint(CheckpointCallback):
    """CheckpointCallback that also saves the final model, so that a run shorter than
    ``checkpoint_freq`` or between two checkpoints can be resumed where it ended."""

    def _on_training_end(self):
        _run_now(self, "save_freq")

class RecordCallback(BaseCallback):
    """Writes ``training.json`` (``record``, steps, wall time, learning curve) after every
    evaluation and, with :meth:`write`, at the end: an interrupted run keeps its record."""

    def __init__(self, path: Path, record: dict, eval_cb):
        super().__init__()
        self.path, self.record, self.eval_cb = path, record, eval_cb
        self.seen = len(eval_cb.kpi_history)
        self.t0, self.start = time.perf_counter(), 0

    def _on_training_start(self):
        self.t0, self.start = time.perf_counter(), self.model.num_timesteps

    def _on_step(self) -> bool:
        if len(self.eval_cb.kpi_history) != self.seen:
            self.seen = len(self.eval_cb.kpi_history)
            self.write(finished=False)
        return True

    def write(self, finished: bool) -> float:
        wall = time.perf_counter() - self.t0
        steps = self.model.num_timesteps - self.start
        summary = dict(self.record, timesteps=int(self.model.num_timesteps), wall_time_s=wall,
                       steps_per_s=steps / wall if wall > 0 else None, finished=finished,
                       learning_curve=self.eval_cb.kpi_history)
        write_json(self.path, summary)                # strict JSON, as every report
        return wall

class WallClockLimit(BaseCallback):
    """Ends training once ``limit`` seconds of wall-clock time have passed since it started
    (checked every step; SB3 then ends ``learn`` as at its last step, so the final
    evaluation, ``best/`` and the model are written as usual). Marks ``record``."""

    def __init__(self, limit: float, record: dict):
        super().__init__()
        self.limit, self.record, self.t0 = float(limit), record, time.perf_counter()

    def _on_training_start(self):
        self.t0 = time.perf_counter()
        self.record["stopped_by_time_limit"] = False

    def _on_step(self) -> bool:
        if time.perf_counter() - self.t0 < self.limit:
            return True
        self.record["stopped_by_time_limit"] = True
        return False
