"""Residual policy learning (config key ``residual: <baseline>``): the agent corrects a baseline.

The environment receives ``clip(base(obs) + 2 a, -1, 1)`` with ``a`` the agent's action, so a
freshly initialised policy (a ≈ 0) is the baseline controller and learning changes it only where
that pays (Johannink et al. 2019). :class:`agents.policies.LearnedPolicy` applies the same
correction when a saved residual policy is loaded (``RESIDUAL_SCALE``).
"""
from __future__ import annotations

import numpy as np

RESIDUAL_SCALE = 2.0


def make_residual(venv, base: str, scale: float = RESIDUAL_SCALE):
    """Residual actions (config key ``residual: <baseline>``): the environment receives
    ``clip(base(obs) + scale * a, -1, 1)``, with ``a`` the agent's action and ``base`` a baseline
    controller of :mod:`agents.controllers`. A freshly initialised policy (a ≈ 0) reproduces the
    baseline; learning changes it only where that pays (residual policy learning, Johannink et
    al. 2019). Box action spaces only."""
    from stable_baselines3.common.vec_env import VecEnvWrapper

    from .controllers import make_baseline
    from .plant import Plant

    class ResidualAction(VecEnvWrapper):
        def __init__(self, venv):
            super().__init__(venv)
            self.base = make_baseline(base, Plant.from_env(venv))
            self.obs = None

        def reset(self):
            self.obs = self.venv.reset()
            self.base.reset(self.num_envs)
            return self.obs

        def step_async(self, actions):
            b, _ = self.base.predict(self.obs)
            self.venv.step_async(np.clip(b + scale * np.asarray(actions), -1.0, 1.0))

        def step_wait(self):
            obs, rewards, dones, infos = self.venv.step_wait()
            if np.any(dones):
                self.base.reset(self.num_envs, np.asarray(dones, dtype=bool))
            self.obs = obs
            return obs, rewards, dones, infos

    return ResidualAction(venv)
