"""A batched Stable-Baselines3 ``VecEnv``: N rotors stepped in one parallel numba call.

SB3 does not take Gymnasium's ``VectorEnv``, so this is an SB3 ``VecEnv`` subclass with SB3's
semantics: ``step_wait`` returns ``(obs, rewards, dones, infos)``; a finished environment is
reset at once, its last observation stored in ``infos[i]["terminal_observation"]`` and
``infos[i]["TimeLimit.truncated"]`` set when it ended at the time limit; ``infos[i]`` is the
final step's info (its ``kpi_*`` are the episode's), ``reset_infos[i]`` the new episode's.

It is the SB3 face of the batch core :class:`rotordrop_env.batch.Batch` (threads, pickling:
see there); :mod:`rotordrop_env.vector` is its Gymnasium face.
"""
from __future__ import annotations

from typing import Any, Sequence

import gymnasium as gym
import numpy as np
from stable_baselines3.common.vec_env.base_vec_env import VecEnv

from .batch import (ENVS_PER_THREAD, RECHOOSE_EVERY, TRIAL_STEPS, Batch, ThreadChoice,  # noqa: F401
                    auto_threads)
from .info import PEAK_KEYS, row_infos

#: torch threads above which the SB3 VecEnv warns (once per process, :func:`check_torch_threads`)
TORCH_THREADS_QUIET = 1
_warned_threads = False


class TorchThreadsWarning(UserWarning):
    """torch trains the small networks of these tasks on several threads: usually slower."""


def check_torch_threads() -> bool:
    """Warn once per process (:class:`TorchThreadsWarning`) when torch is imported and runs on
    more than :data:`TORCH_THREADS_QUIET` threads as an SB3 VecEnv is made: the networks that
    train on these environments (two layers of 64) are several times faster on one thread on a
    small CPU, and the batch's numba threads compete with torch's. Only the SB3 VecEnv checks
    (it exists to train), not the environments. True when it warned."""
    import sys
    import warnings
    global _warned_threads
    torch = sys.modules.get("torch")
    if _warned_threads or torch is None:
        return False
    n = torch.get_num_threads()
    if n <= TORCH_THREADS_QUIET:
        return False
    _warned_threads = True
    warnings.warn(f"torch runs on {n} threads: for the small networks of rotordrop tasks "
                  f"torch.set_num_threads(1) before training is usually several times faster "
                  f"(silence: warnings.filterwarnings('ignore', category="
                  f"rotordrop_env.vec_env.TorchThreadsWarning))", TorchThreadsWarning, stacklevel=3)
    return True


class BatchedRotorDropVecEnv(VecEnv):
    """``n_envs`` copies of ``env_id`` (with ``env_kwargs``) stepped together.

    ``seed``: environment i is seeded ``seed + i`` at the first reset (as SB3's
    ``make_vec_env``); later resets continue each environment's own random stream.
    ``n_threads``: numba threads for the batched step; default None: chosen as the batch runs
    (:class:`ThreadChoice` between one thread and :func:`auto_threads`), so the batch is never
    slower than on one thread; a number fixes it.
    """

    def __init__(self, env_id: str, n_envs: int, seed: int | None = None,
                 n_threads: int | None = None, **env_kwargs: Any):
        if int(n_envs) != n_envs or n_envs < 1:
            raise ValueError(f"n_envs = {n_envs!r} must be a positive integer")
        if "max_episode_steps" in env_kwargs:     # gym.make's TimeLimit: .unwrapped drops it
            raise ValueError("max_episode_steps does not apply to the batched VecEnv; set the "
                             "episode length with episode_time (= steps x control_dt)")
        check_torch_threads()
        self.batch = Batch([gym.make(env_id, **env_kwargs).unwrapped for _ in range(int(n_envs))],
                           n_threads)
        self.envs = self.batch.envs
        self.actions: np.ndarray | None = None
        first = self.envs[0]
        super().__init__(int(n_envs), first.observation_space, first.action_space)
        if seed is not None:
            self.seed(seed)

    @property
    def stack(self):
        return self.batch.stack

    @property
    def n_threads(self):
        return self.batch.n_threads

    @property
    def threads(self) -> ThreadChoice:
        return self.batch.threads

    # ------------------------------------------------------------------ SB3 VecEnv API --
    def reset(self):
        obs = np.empty((self.num_envs, *self.observation_space.shape), dtype=np.float32)
        for e in range(self.num_envs):
            obs[e], self.reset_infos[e] = self.batch.reset_env(e, self._seeds[e], self._options[e] or None)
        self._reset_seeds()
        self._reset_options()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self.actions = actions

    def step_wait(self):
        batch = self.batch
        obs, rewards, terminated, truncated, _ = batch.step(self.actions, columns=False)
        dones = terminated | truncated
        infos = row_infos(batch.values, batch.latency, batch.relevitate, batch.step_infos)
        for e in np.flatnonzero(dones):
            infos[e]["terminal_observation"] = obs[e].copy()
            infos[e]["TimeLimit.truncated"] = bool(truncated[e] and not terminated[e])
            obs[e], self.reset_infos[e] = self.batch.reset_env(e)
        return obs, rewards.astype(np.float32), dones, infos

    def running_kpis(self) -> dict[str, np.ndarray]:
        """Every environment's running-maximum KPIs (``rotordrop_env.info.PEAK_KEYS``) as
        arrays; after an auto-reset they belong to the new episode (the finished one's are in
        its ``info``)."""
        return {k: np.array([env.kpis()[k] for env in self.envs], dtype=float) for k in PEAK_KEYS}

    def close(self) -> None:
        self.batch.close()

    def get_attr(self, attr_name: str, indices=None) -> list[Any]:
        return [getattr(self.envs[i], attr_name) for i in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices=None) -> None:
        """As SB3's ``DummyVecEnv``: ``setattr`` on each environment. A reward weight
        (``w_whirl``...) takes effect from the next step; a setting fixed at construction
        (``control_dt``...) or an unknown ``w_*`` name raises AttributeError."""
        for i in self._get_indices(indices):
            setattr(self.envs[i], attr_name, value)

    def env_method(self, method_name: str, *method_args, indices=None, **method_kwargs) -> list[Any]:
        return [getattr(self.envs[i], method_name)(*method_args, **method_kwargs)
                for i in self._get_indices(indices)]

    def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
        return [False for _ in self._get_indices(indices)]

    def get_images(self) -> Sequence[np.ndarray | None]:
        return [env.render() for env in self.envs]


def make_batched(env_id: str, n_envs: int, seed: int | None = None,
                 n_threads: int | None = None, **env_kwargs: Any) -> BatchedRotorDropVecEnv:
    """``make_vec_env``-like factory of :class:`BatchedRotorDropVecEnv`."""
    return BatchedRotorDropVecEnv(env_id, n_envs, seed=seed, n_threads=n_threads, **env_kwargs)
