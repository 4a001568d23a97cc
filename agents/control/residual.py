"""Residual policy learning (config key ``residual: <baseline>``): the agent corrects a baseline.

The environment receives ``clip(base(obs) + s a, -1, 1)`` with ``a`` the agent's action and
``s`` the config's ``residual_scale`` (default ``RESIDUAL_SCALE`` = 2), so a freshly initialised
policy (a ≈ 0) is the baseline controller and learning changes it only where that pays
(Johannink et al. 2019). :class:`agents.learning.policies.LearnedPolicy` applies the same correction
(:func:`residual_action`) when a saved residual policy is loaded.
"""
from __future__ import annotations

import numpy as np
from stable_baselines3.common.vec_env import VecEnvWrapper

RESIDUAL_SCALE = 2.0


def residual_action(base, raw_obs: np.ndarray, a: np.ndarray, scale: float,
                    episode_start=None) -> np.ndarray:
    """``clip(base(obs) + scale * a, -1, 1)`` as float32: the action a residual policy sends,
    in training (:func:`make_residual`) and when a saved policy drives an env."""
    b, _ = base.predict(raw_obs, episode_start=episode_start)
    return np.clip(b + scale * np.asarray(a), -1.0, 1.0).astype(np.float32)


class ResidualAction(VecEnvWrapper):
    """Residual actions on an SB3 VecEnv (config key ``residual: <baseline>``; in an rl-zoo3
    config ``vec_env_wrapper: [{agents.control.residual.ResidualAction: {base: NAME, scale: S}}]``):
    see :func:`residual_action`. A freshly initialised policy (a ≈ 0) reproduces the baseline;
    learning changes it only where that pays (residual policy learning, Johannink et al.
    2019). Box action spaces only. Works on the batched VecEnv and on SB3's DummyVecEnv (rl-zoo3's
    default) or SubprocVecEnv of ``gym.make`` environments."""

    def __init__(self, venv, base: str | dict, scale: float = RESIDUAL_SCALE):
        from .controllers import make_baseline
        from .plant import Plant
        super().__init__(venv)
        self.base_name, self.scale = base, float(scale)
        self.base = make_baseline(base, Plant.from_env(venv))
        self.obs = None
        self.starts = np.ones(self.num_envs, dtype=bool)

    def reset(self):
        self.obs = self.venv.reset()
        self.starts[:] = True
        return self.obs

    def step_async(self, actions):
        self.venv.step_async(residual_action(self.base, self.obs, actions, self.scale, self.starts))

    def step_wait(self):
        obs, rewards, dones, infos = self.venv.step_wait()
        self.obs, self.starts = obs, np.asarray(dones, dtype=bool)
        return obs, rewards, dones, infos


def make_residual(venv, base: str, scale: float = RESIDUAL_SCALE) -> ResidualAction:
    """:class:`ResidualAction` around ``venv``."""
    return ResidualAction(venv, base, scale)


def residual_of(venv) -> tuple[str | None, float | None]:
    """(baseline, scale) of the :class:`ResidualAction` wrapper in ``venv``'s wrapper chain, or
    (None, None)."""
    while isinstance(venv, VecEnvWrapper):
        if isinstance(venv, ResidualAction):
            return venv.base_name, venv.scale
        venv = venv.venv
    return None, None
