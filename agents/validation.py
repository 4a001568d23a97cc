"""Model selection on the validation suite, for ``rotordrop train`` and for rl-zoo3.

:func:`validation_score` is the benchmark score (:class:`agents.benchmark.Validator`: frictions
and unbalance phases the benchmark does not use) of a model being trained, run as the saved
policy will run: its observation normalisation and, for a residual policy, its baseline.

:class:`ValidationCallback` is the same as an SB3 callback that rl-zoo3 builds from a config's
``callback:`` entry (``agents.validation.ValidationCallback``; in ``rotordrop train`` that entry
means ``validation: true``). Every ``eval_freq`` environment steps it logs
``eval/validation_score`` and, with a ``save_path``, keeps the best-scoring model there as a
self-contained zip (:mod:`agents.sb3_policy`) that plain SB3 loads.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback

#: rl-zoo3's default evaluation interval [environment steps]
EVAL_FREQ = 25_000


def validation_score(validator, model, algo: str, env_id: str, env_kwargs: dict, vecnormalize,
                     residual: str | None = None, residual_scale: float | None = None,
                     frame_stack: int | None = None) -> float:
    """The benchmark score of ``model`` (with its ``vecnormalize``, ``residual`` and
    ``frame_stack``; None: read from the model's training env) on the validation suite of
    ``validator``."""
    from .policies import LearnedPolicy
    pol = LearnedPolicy("candidate", algo, env_id, env_kwargs, model, vecnormalize,
                        frame_stack=frame_stack)
    if residual is not None:
        pol.residual, pol.residual_scale = residual, residual_scale
    score, _ = validator.score(pol.bound, env_kwargs)
    return score


class ValidationCallback(BaseCallback):
    """rl-zoo3 (``callback: - agents.validation.ValidationCallback: {save_path: DIR}``): every
    ``eval_freq`` environment steps the validation score of the deterministic policy, logged as
    ``eval/validation_score`` (and printed with ``verbose``); the best model so far is written to
    ``save_path/best_model.zip`` (self-contained) when ``save_path`` is given."""

    def __init__(self, eval_freq: int = EVAL_FREQ, save_path: str | None = None, verbose: int = 1):
        super().__init__(verbose)
        if int(eval_freq) != eval_freq or eval_freq < 1:
            raise ValueError(f"ValidationCallback: eval_freq = {eval_freq!r} must be an integer >= 1")
        self.eval_freq = int(eval_freq)
        self.save_path = None if save_path is None else Path(save_path)
        self.best = -np.inf
        self.last = 0
        self.validator = None

    def _init_callback(self) -> None:
        from .robust import validator_for
        spec = self.training_env.get_attr("spec", [0])[0]
        self.env_id, self.env_kwargs = spec.id, dict(spec.kwargs)
        self.validator = validator_for(self.env_id, self.env_kwargs)
        self.algo = type(self.model).__name__.lower()
        if self.save_path is not None:
            self.save_path.mkdir(parents=True, exist_ok=True)

    def _on_step(self) -> bool:
        if self.num_timesteps - self.last >= self.eval_freq:
            self.last = self.num_timesteps
            self.validate()
        return True

    def validate(self) -> float:
        vn = self.model.get_vec_normalize_env()
        from .residual import residual_of
        residual, scale = residual_of(self.training_env)
        score = validation_score(self.validator, self.model, self.algo, self.env_id,
                                 self.env_kwargs, vn, residual, scale)
        self.logger.record("eval/validation_score", score)
        if self.verbose:
            print(f"validation score {score:.2f} at {self.num_timesteps} steps (best {max(score, self.best):.2f})")
        if score > self.best:
            self.best = score
            if self.save_path is not None:
                from .sb3_policy import export_self_contained
                export_self_contained(self.model, vn, self.save_path / "best_model.zip",
                                      env_id=self.env_id, env_kwargs=self.env_kwargs,
                                      residual=residual, residual_scale=scale)
        return score
