"""The KPI-aligned training reward (config key ``reward: kpi``).

The reward itself belongs to the environments: ``gym.make(id, reward="kpi", reward_kwargs=...)``
(:mod:`rotordrop_env.reward`, which explains it). ``rotordrop train`` passes ``reward="kpi"``
and the config's ``reward_kwargs`` to its batched environments (:mod:`agents.training.training_env`).
:class:`KpiReward` is the same reward as an SB3 ``VecEnvWrapper`` over environments made with
the default reward (rl-zoo3: ``vec_env_wrapper: agents.learning.reward.KpiReward``), computed by the
same functions from the running KPIs every step's ``info`` carries.
"""
from __future__ import annotations

import numpy as np
from stable_baselines3.common.vec_env import VecEnvWrapper

from rotordrop_env.reward import (KPI_WEIGHTS, PEAK_KEYS, REFERENCES, check_kpi_weights,  # noqa: F401
                                  kpi_potential, kpi_reward)

from .config_checks import ConfigError

#: the ``reward_kwargs`` and their defaults
WEIGHTS = KPI_WEIGHTS


def check_reward_kwargs(kwargs: dict) -> None:
    """ConfigError unless ``kwargs`` are known weights >= 0 and references > 0."""
    try:
        check_kpi_weights(kwargs)
    except ValueError as e:
        raise ConfigError(str(e)) from None


class KpiReward(VecEnvWrapper):
    """The KPI-aligned reward (:mod:`rotordrop_env.reward`) on an SB3 VecEnv of rotor-drop
    environments with the default reward: the batched VecEnv or SB3's DummyVecEnv /
    SubprocVecEnv of ``gym.make`` environments (rl-zoo3: ``vec_env_wrapper:
    agents.learning.reward.KpiReward``, weights as its keyword arguments). It equals the environments'
    own ``reward="kpi"``."""

    def __init__(self, venv, **weights):
        super().__init__(venv)
        check_reward_kwargs(weights)
        self.w = check_kpi_weights(weights)
        dt, horizon = (np.asarray(venv.get_attr(a), dtype=float) for a in ("dt", "episode_time"))
        self.time_cost = self.w["w_time"] * dt / horizon
        self.phi = np.zeros(self.num_envs)
        self.relevitated = np.zeros(self.num_envs, dtype=bool)

    def reset(self):
        obs = self.venv.reset()
        self.phi[:] = 0.0
        self.relevitated[:] = False
        return obs

    def step_wait(self):
        obs, _, dones, infos = self.venv.step_wait()      # a done env's info is its final step's
        phi = kpi_potential(*(np.array([i[k] for i in infos], dtype=float) for k in PEAK_KEYS),
                            **self.w)
        if "relevitated" in infos[0]:
            now = np.array([bool(i["relevitated"]) for i in infos])
            rewards = kpi_reward(self.phi, phi, now & ~self.relevitated, ~now,
                                 self.w["w_relevitate"], self.time_cost)
            self.relevitated = now & ~dones
        else:
            rewards = self.phi - phi
        self.phi = np.where(dones, 0.0, phi)
        return obs, rewards.astype(np.float32), dones, infos


def make_kpi_reward(venv, **kwargs) -> KpiReward:
    """:class:`KpiReward` around ``venv``."""
    return KpiReward(venv, **kwargs)
