"""The batch core of the vectorised environments: N rotor-drop environments whose arrays are
rows of one stack, stepped in one numba call. Two faces use it: the Gymnasium vector
environment (:mod:`rotordrop_env.vector`, ``gymnasium.make_vec(id, vectorization_mode=
"vector_entry_point")``) and the Stable-Baselines3 ``VecEnv`` (:mod:`rotordrop_env.vec_env`).

Each environment is an ordinary rotor-drop environment whose arrays are rows of the stack;
resets (scenario sampling from each env's own ``np_random``) run per environment in Python,
steps run all rows in one numba call: on one thread (:func:`rotordrop_env.kernels.step_rows`)
or parallel over environments (:func:`rotordrop_env.kernels.step_batch`). By default the batch
picks between the two as it runs (:class:`ThreadChoice`): one thread for a few environments,
where waking other threads costs more than it saves, and on a loaded machine; threads where
they pay. Every choice gives the same numbers (each environment is one row, stepped by the same
code). All actions are checked before any environment advances; with a ``render_mode`` each
environment records its steps as a single one does; a pickled or deep-copied batch re-attaches
its environments to its own stack.

Importing this module sets ``OMP_WAIT_POLICY=PASSIVE`` unless it is already set: with numba's
OpenMP threading layer, threads that spin at the end of each parallel step steal the core of a
descheduled worker when the machine is shared, which made a 2-thread batch 5-10x slower than one
thread on a loaded 2-core machine; with passive waiting it keeps up with one thread on free
cores (on busy ones the timed trials can pick the slower count: docs/environments.md, Speed).
"""
from __future__ import annotations

import os
import statistics
import time

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")       # before numba starts its OpenMP pool

import gymnasium as gym
import numba
import numpy as np

from . import kernels as K
from .buffers import Buffers
from .env import RotorDropEnv, real_action
from .info import info_dict
from .sensors import SensingRows


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
    from physics.runs.sweep import available_cores
    return max(1, min(available_cores(), numba.config.NUMBA_NUM_THREADS,
                      n_envs // ENVS_PER_THREAD))



class Batch:
    """The environments ``envs`` (unwrapped rotor-drop environments of one id and settings)
    stepped together on one stack of arrays.

    ``n_threads``: numba threads for the batched step; default None: chosen as the batch runs
    (:class:`ThreadChoice` between one thread and :func:`auto_threads`), so the batch is never
    slower than on one thread; a number fixes it.
    """

    def __init__(self, envs: list[RotorDropEnv], n_threads: int | None = None):
        for env in envs:
            if not isinstance(env, RotorDropEnv):
                raise ValueError(f"{env!r} is not a rotordrop environment")
        self.envs = envs
        n = len(envs)
        first = envs[0]
        self.stack = Buffers(*first._b.dims, packed=first._b.packed, n_envs=n,
                             n_noise=first._b.n_noise)
        for e, env in enumerate(envs):
            env._bind(self.stack.row(e))
        self._args = self.stack.args()
        self.discrete = first._discrete
        self.relevitate = first._relevitate
        self.reward = first.reward_function
        self.sensed = any(env._sensing.active for env in envs)
        self.noisy = any(env._sensing.noise > 0.0 for env in envs)
        #: the sensing of all rows on stacked arrays (None: row by row, the Python measurement)
        self.sensing = (SensingRows([env._sensing for env in envs], self.stack)
                        if self.sensed and all(env._sensing.compiled for env in envs) else None)
        for env in envs:
            env._calls = None                   # bound again to the stacked sensing rows
        self.rendering = first.render_mode is not None
        self.latency = np.zeros(n, dtype=np.int64)        # each env's observation latency
        self.values = np.zeros((n, K.N_V))                # the info numbers (rotordrop_env.info)
        self.step_infos = [env._step_info for env in envs]  # each row's info templates
        if n_threads is not None and not 1 <= int(n_threads) <= numba.config.NUMBA_NUM_THREADS:
            raise ValueError(f"n_threads = {n_threads!r} must be in [1, "
                             f"{numba.config.NUMBA_NUM_THREADS}] (numba's NUMBA_NUM_THREADS)")
        self.n_threads = None if n_threads is None else int(n_threads)
        self.threads = ThreadChoice(auto_threads(n) if n_threads is None else 1)

    @property
    def num_envs(self) -> int:
        return len(self.envs)

    def reset_env(self, e: int, seed: int | None = None, options: dict | None = None):
        """Reset environment ``e``: its (observation, info)."""
        env = self.envs[e]
        obs, info = env.reset(seed=seed, options=options)
        self.latency[e] = env._sensing.k
        return obs, info

    def check_steppable(self) -> None:
        if any(env._needs_reset for env in self.envs):
            for env in self.envs:
                env._check_open("step")
            raise gym.error.ResetNeeded("call reset() on the vector environment before step()")

    def step(self, actions, active: np.ndarray | None = None, columns: bool = True):
        """All environments one control step (no reset): observations (float32), rewards
        (float64), terminated, truncated (bool arrays) and the info columns
        (:func:`rotordrop_env.info.info_dict`, one array entry per environment; ``columns``
        False: None, the numbers stay in ``values`` for :func:`rotordrop_env.info.row_infos`).

        ``active``: advance only these rows (bool mask); the others are left as they are (just
        reset: their observation is the kernel's reset one, their reward 0 and their info the
        reset info)."""
        self.check_steppable()
        stack = self.stack
        act = stack.act
        a = real_action(actions, self.envs[0].action_space, self.envs[0].action_names)
        try:
            if self.discrete:
                act[:, 0] = a.reshape(self.num_envs)
            else:
                act[:] = a.reshape(self.num_envs, -1)
        except ValueError:
            raise ValueError(f"actions of shape {a.shape} do not fit {self.num_envs} environments "
                             f"with action space {self.envs[0].action_space}") from None
        e, err = K.first_bad_action(act, stack.C)
        if e >= 0:                                # before any env advances; single env's message
            self.envs[e]._action_error(err, a[e])
        idx = None if active is None else np.flatnonzero(active)
        if self.noisy and self.sensing is not None:   # the step's noise draws (.sensors)
            self.sensing.draw([env.np_random for env in self.envs], idx)
        elif self.noisy:
            for e in range(self.num_envs) if active is None else idx:
                self.envs[e].draw_noise()
        if active is None:
            self._step_kernel()
        else:                                     # a few steps per episode: row by row
            for e in np.flatnonzero(active):
                K.step_one(*self.envs[e]._args)
        out = stack.out
        failed = np.flatnonzero(out[:, K.O_STATUS])
        if failed.size:                           # the single env's clear IntegrationError
            e = failed[0]
            self.envs[e]._finish(a[e])
        rows = range(self.num_envs) if active is None else idx
        if self.sensing is not None:              # noise / latency (rotordrop_env.sensors)
            sensed = self.sensing.measure(idx)
            if active is None:
                obs = sensed.copy()
            else:
                obs = stack.obs.astype(np.float32)
                obs[idx] = sensed[idx]
        else:
            obs = stack.obs.astype(np.float32)
            if self.sensed:
                for e in rows:
                    obs[e] = self.envs[e].observed()
        rewards = self.reward.step(out, stack.M, stack.C, self.relevitate)
        if active is not None:
            rewards[~active] = 0.0
        terminated = out[:, K.O_TERM] > 0.0
        truncated = out[:, K.O_TRUNC] > 0.0
        K.info_rows(out, stack.M, stack.C, self.values)
        info = info_dict(self.values, self.latency, self.relevitate) if columns else None
        if self.rendering:                        # before the auto-resets clear the views
            for e in rows:
                self.envs[e]._show_step()
        return obs, rewards, terminated, truncated, info

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
        if self.sensing is not None:
            self.sensing.attach(self.stack)
        self._args = self.stack.args()

    def close(self) -> None:
        for env in self.envs:
            env.close()
