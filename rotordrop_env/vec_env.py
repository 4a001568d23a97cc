"""A batched Stable-Baselines3 ``VecEnv``: N rotors stepped in one parallel numba call.

SB3 does not take Gymnasium's ``VectorEnv``, so this is an SB3 ``VecEnv`` subclass with SB3's
semantics: ``step_wait`` returns ``(obs, rewards, dones, infos)``; a finished environment is
reset at once, its last observation stored in ``infos[i]["terminal_observation"]`` and
``infos[i]["TimeLimit.truncated"]`` set when it ended at the time limit.

Each of the N environments is an ordinary ``gym.make(env_id, **env_kwargs)`` environment whose
arrays are rows of one stack; resets (scenario sampling from each env's own ``np_random``) run
per environment in Python, steps run all rows in one numba call: on one thread
(:func:`rotordrop_env.kernels.step_rows`) or parallel over environments
(:func:`rotordrop_env.kernels.step_batch`). By default the batch picks between the two as it
runs (:class:`ThreadChoice`): one thread for a few environments, where waking other threads
costs more than it saves, and on a loaded machine; threads where they pay. Every choice gives
the same numbers (each environment is one row, stepped by the same code).
All actions are checked before any environment advances; with a ``render_mode`` each environment
records its steps as a single one does; a pickled or deep-copied batch re-attaches its
environments to its own stack.

Importing this module sets ``OMP_WAIT_POLICY=PASSIVE`` unless it is already set: with numba's
OpenMP threading layer, threads that spin at the end of each parallel step steal the core of a
descheduled worker when the machine is shared, which made a 2-thread batch 5-10x slower than one
thread on a loaded 2-core machine; with passive waiting it is never slower than one thread.
"""
from __future__ import annotations

import os
import statistics
import time
from typing import Any, Sequence

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")       # before numba starts its OpenMP pool

import gymnasium as gym
import numba
import numpy as np
from stable_baselines3.common.vec_env.base_vec_env import VecEnv

from . import kernels as K
from .buffers import Buffers
from .env import RotorDropEnv, peak_kpis, real_action, step_infos


ENVS_PER_THREAD = 4      # fewer environments per thread than this never pay the parallel launch
TRIAL_STEPS = 8          # batch steps timed per candidate when the batch (re)chooses its threads
RECHOOSE_EVERY = 2000    # batch steps between two choices (the machine's load changes)


class ThreadChoice:
    """The thread count of the batched step, chosen by timing: ``TRIAL_STEPS`` steps on one
    thread, as many on ``most`` threads, then the faster (median wall time per step) for the
    next ``RECHOOSE_EVERY`` steps, and again. With ``most`` = 1 it is always one thread."""

    def __init__(self, most: int):
        self.most = max(1, int(most))
        self.trials: dict[int, list[float]] = {1: [], self.most: []}
        self.chosen = 1
        self.left = 0                                   # steps before the next choice

    def next(self) -> int:
        """Threads for the coming step."""
        if self.most == 1 or self.left > 0:
            return self.chosen
        return 1 if len(self.trials[1]) < TRIAL_STEPS else self.most

    def record(self, threads: int, seconds: float) -> None:
        """The wall time of a step on ``threads`` threads."""
        if self.most == 1:
            return
        if self.left > 0:
            self.left -= 1
            return
        self.trials[threads].append(seconds)
        if len(self.trials[self.most]) >= TRIAL_STEPS:
            self.chosen = min(self.trials, key=lambda n: statistics.median(self.trials[n]))
            self.trials = {1: [], self.most: []}
            self.left = RECHOOSE_EVERY


def auto_threads(n_envs: int) -> int:
    """The most threads worth trying for ``n_envs`` environments: the cores this process may
    use and numba's threads, at most one per ``ENVS_PER_THREAD`` environments."""
    from physics.sweep import available_cores
    return max(1, min(available_cores(), numba.config.NUMBA_NUM_THREADS,
                      n_envs // ENVS_PER_THREAD))


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
        self.envs: list[RotorDropEnv] = []
        for _ in range(int(n_envs)):
            env = gym.make(env_id, **env_kwargs).unwrapped
            if not isinstance(env, RotorDropEnv):
                raise ValueError(f"{env_id!r} is not a rotordrop environment")
            self.envs.append(env)
        first = self.envs[0]
        self.stack = Buffers(*first._b.dims, n_envs=int(n_envs))
        for e, env in enumerate(self.envs):
            env._bind(self.stack.row(e))
        self._args = self.stack.args()
        self._discrete = first._discrete
        self._sensed = any(env._sensing.active for env in self.envs)
        if n_threads is not None and not 1 <= int(n_threads) <= numba.config.NUMBA_NUM_THREADS:
            raise ValueError(f"n_threads = {n_threads!r} must be in [1, "
                             f"{numba.config.NUMBA_NUM_THREADS}] (numba's NUMBA_NUM_THREADS)")
        self.n_threads = None if n_threads is None else int(n_threads)
        self.threads = ThreadChoice(auto_threads(int(n_envs)) if n_threads is None else 1)
        self.actions: np.ndarray | None = None
        super().__init__(int(n_envs), first.observation_space, first.action_space)
        if seed is not None:
            self.seed(seed)

    # ------------------------------------------------------------------ SB3 VecEnv API --
    def reset(self):
        obs = np.empty((self.num_envs, *self.observation_space.shape), dtype=np.float32)
        for e, env in enumerate(self.envs):
            options = {"options": self._options[e]} if self._options[e] else {}
            obs[e], self.reset_infos[e] = env.reset(seed=self._seeds[e], **options)
        self._reset_seeds()
        self._reset_options()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self.actions = actions

    def step_wait(self):
        if any(env._needs_reset for env in self.envs):
            for env in self.envs:
                env._check_open("step")
            raise gym.error.ResetNeeded("call reset() on the VecEnv before step()")
        act = self.stack.act
        a = real_action(self.actions, self.action_space, self.envs[0].action_names)
        try:
            if self._discrete:
                act[:, 0] = a.reshape(self.num_envs)
            else:
                act[:] = a.reshape(self.num_envs, -1)
        except ValueError:
            raise ValueError(f"actions of shape {a.shape} do not fit {self.num_envs} environments "
                             f"with action space {self.action_space}") from None
        e, err = K.first_bad_action(act, self.stack.C)
        if e >= 0:                                # before any env advances; single env's message
            self.envs[e]._action_error(err, a[e])
        self._step_kernel()
        out = self.stack.out
        failed = np.flatnonzero(out[:, K.O_STATUS])
        if failed.size:                           # the single env's clear IntegrationError
            e = failed[0]
            self.envs[e]._finish(a[e])
        obs = self.stack.obs.astype(np.float32)
        if self._sensed:                          # noise / latency (rotordrop_env.sensors)
            for e, env in enumerate(self.envs):
                obs[e] = env.observed()
        rewards = out[:, K.O_REWARD].astype(np.float32)
        terminated = out[:, K.O_TERM] > 0.0
        truncated = out[:, K.O_TRUNC] > 0.0
        dones = terminated | truncated
        infos = step_infos(out, self.stack.M, self.stack.C, self.envs[0]._relevitate)
        if self.render_mode is not None:          # before the auto-resets clear the views
            for env in self.envs:
                env._show_step()
        for e in np.flatnonzero(dones):
            infos[e].update(self.envs[e].kpis())
            infos[e]["terminal_observation"] = obs[e].copy()
            infos[e]["TimeLimit.truncated"] = bool(truncated[e] and not terminated[e])
            new_obs, self.reset_infos[e] = self.envs[e].reset()
            obs[e] = new_obs
        return obs, rewards, dones, infos

    def _step_kernel(self) -> None:
        """All rows one control step on the fixed or the chosen number of threads (the chosen
        one at most numba's current setting, e.g. a training run's ``--threads``)."""
        if self.n_threads is not None:
            n = self.n_threads
        elif self.threads.most == 1:        # nothing to choose (N < 8, one core): the one-thread
            K.step_rows(*self._args)        # step as is (numba.get_num_threads() costs ~3 µs)
            return
        else:
            n = min(self.threads.next(), numba.get_num_threads())
        t0 = time.perf_counter()
        if n == 1:
            K.step_rows(*self._args)
        else:
            previous = numba.get_num_threads()
            numba.set_num_threads(n)
            try:
                K.step_batch(*self._args)
            finally:
                numba.set_num_threads(previous)
        if self.n_threads is None:
            self.threads.record(n, time.perf_counter() - t0)

    def __setstate__(self, state: dict) -> None:
        """A copy (pickle, deepcopy) steps on its own stack: its environments' arrays are
        views of that stack's rows again (copying breaks the views into separate arrays)."""
        self.__dict__.update(state)
        for e, env in enumerate(self.envs):
            env._use(self.stack.row(e))
        self._args = self.stack.args()

    def running_kpis(self) -> dict[str, np.ndarray]:
        """Every environment's running-maximum KPIs as arrays (see ``env.peak_kpis``); after an
        auto-reset they belong to the new episode (the finished one's are in its ``info``)."""
        return {k: np.array(v, dtype=float) for k, v in peak_kpis(self.stack.M).items()}

    def close(self) -> None:
        for env in self.envs:
            env.close()

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
