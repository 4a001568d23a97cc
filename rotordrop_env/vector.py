"""The Gymnasium vector environment of every id: N rotors stepped in one numba call.

    envs = gymnasium.make_vec("RotorDrop-Full-v1", num_envs=16,
                              vectorization_mode="vector_entry_point", command="supervisor")

It is the Gymnasium face of the batch core :class:`rotordrop_env.batch.Batch` (the SB3
``VecEnv`` of :mod:`rotordrop_env.vec_env` is the other): environment i is the environment
``gym.make(id, **kwargs)`` would make, seeded ``seed + i`` by ``reset(seed=seed)``, and steps
to the same numbers.

Autoreset (kwarg ``autoreset_mode``, in ``metadata["autoreset_mode"]``):

* ``AutoresetMode.SAME_STEP`` (default): a finished environment is reset within the step that
  ends its episode: ``obs[i]`` and ``info`` entry i belong to the new episode, the final
  observation is ``info["final_obs"][i]`` and the final step's info (with the episode's
  ``kpi_*``) is ``info["final_info"]`` (entries where ``info["_final_info"]`` is True). Every
  step advances every rotor (no step whose action is ignored, no zero-reward transition to mask
  out) and the final info is at hand in the step the episode ends, as in the SB3 ``VecEnv``.
* ``AutoresetMode.NEXT_STEP`` (Gymnasium's default, the only mode its vector observation
  wrappers such as ``NormalizeObservation`` accept): the step after an episode's end resets
  that environment (its action is ignored, reward 0, flags False, the reset observation and
  info); the final step's info is the ordinary step info.

Info: a dict of arrays, one entry per environment, with Gymnasium's ``_key`` masks (all True:
every environment has every key at every step, see :mod:`rotordrop_env.info`).
"""
from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from . import env as _env
from .batch import Batch


class RotorDropVectorEnv(VectorEnv):
    """``num_envs`` environments of ``env_class`` (with the environment kwargs; for a task
    registered by :mod:`rotordrop_env.tasks`, ``RotorDropEnv`` with its ``task``) stepped together.
    ``n_threads``: numba threads of the batched step (default: chosen as it runs, see
    :class:`rotordrop_env.batch.ThreadChoice`)."""

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 30,
                "autoreset_mode": AutoresetMode.SAME_STEP}
    env_class: type = _env.RotorDropEnv

    def __init__(self, num_envs: int = 1, *, n_threads: int | None = None,
                 autoreset_mode: AutoresetMode | str = AutoresetMode.SAME_STEP, **kwargs: Any):
        if isinstance(num_envs, bool) or int(num_envs) != num_envs or num_envs < 1:
            raise ValueError(f"num_envs = {num_envs!r} must be a positive integer")
        try:
            mode = AutoresetMode(autoreset_mode)
        except ValueError:
            mode = None
        if mode not in (AutoresetMode.SAME_STEP, AutoresetMode.NEXT_STEP):
            raise ValueError(f"autoreset_mode = {autoreset_mode!r} must be AutoresetMode.SAME_STEP "
                             "or AutoresetMode.NEXT_STEP")
        if "max_episode_steps" in kwargs:
            raise ValueError("max_episode_steps does not apply to the rotor-drop vector "
                             "environment; set the episode length with episode_time "
                             "(= steps x control_dt)")
        self.batch = Batch([self.env_class(**kwargs) for _ in range(int(num_envs))], n_threads)
        self.envs = self.batch.envs
        first = self.envs[0]
        self.num_envs = int(num_envs)
        self.single_observation_space = first.observation_space
        self.single_action_space = first.action_space
        self.observation_space = batch_space(first.observation_space, self.num_envs)
        self.action_space = batch_space(first.action_space, self.num_envs)
        self.render_mode = first.render_mode
        self.metadata = dict(self.metadata)
        self.metadata["autoreset_mode"] = self.autoreset_mode = mode
        self._ended = np.zeros(self.num_envs, dtype=bool)       # NEXT_STEP: reset at the next step

    def reset(self, *, seed: int | list[int | None] | None = None,
              options: dict[str, Any] | None = None):
        """Reset every environment: ``seed`` an int (environment i gets ``seed + i``), a list
        (one seed each) or None; ``options`` as a single environment's (the same for all)."""
        if seed is None:
            seeds = [None] * self.num_envs
        elif isinstance(seed, (int, np.integer)):
            seeds = [int(seed) + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(f"{len(seeds)} seeds for {self.num_envs} environments")
        if seed is not None:
            self._np_random, self._np_random_seed = gym.utils.seeding.np_random(seeds[0])
        self._ended[:] = False
        obs = np.empty((self.num_envs, *self.single_observation_space.shape), dtype=np.float32)
        infos: dict = {}
        for e in range(self.num_envs):
            obs[e], info = self.batch.reset_env(e, seeds[e], options)
            if not infos:
                infos = {k: np.empty(self.num_envs, dtype=np.asarray(v).dtype)
                         for k, v in info.items()}
            for k, v in info.items():
                infos[k][e] = v
        return obs, _masked(infos, self.num_envs)

    def step(self, actions):
        if self.autoreset_mode is AutoresetMode.NEXT_STEP:
            return self._step_next(actions)
        obs, rewards, terminated, truncated, info = self.batch.step(actions)
        dones = terminated | truncated
        if dones.any():
            final_info = _masked({k: v.copy() for k, v in info.items()}, self.num_envs, dones)
            final_obs = np.full(self.num_envs, None, dtype=object)
            for e in np.flatnonzero(dones):
                final_obs[e] = obs[e].copy()
                obs[e], reset_info = self.batch.reset_env(e)
                for k, v in reset_info.items():
                    info[k][e] = v
            info = _masked(info, self.num_envs)
            info.update(final_obs=final_obs, _final_obs=dones.copy(), final_info=final_info,
                        _final_info=dones.copy())
            return obs, rewards, terminated, truncated, info
        return obs, rewards, terminated, truncated, _masked(info, self.num_envs)

    def _step_next(self, actions):
        """NEXT_STEP autoreset: the environments that ended at the last step are reset instead
        of stepped (reward 0, flags False, their reset observation and info)."""
        if not self._ended.any():
            obs, rewards, terminated, truncated, info = self.batch.step(actions)
        else:
            self.batch.check_steppable()
            rows = np.flatnonzero(self._ended)
            reset_obs = [self.batch.reset_env(e)[0] for e in rows]
            obs, rewards, terminated, truncated, info = self.batch.step(actions, ~self._ended)
            obs[rows] = reset_obs                     # the info's rows are the reset infos
        self._ended = terminated | truncated
        return obs, rewards, terminated, truncated, _masked(info, self.num_envs)

    def render(self) -> tuple | None:
        """Each environment's frame (``render_mode="rgb_array"``), as ``SyncVectorEnv``."""
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode='rgb_array' "
                            "or 'human' to gymnasium.make_vec")
            return None
        return tuple(env.render() for env in self.envs)

    def close_extras(self, **kwargs: Any) -> None:
        self.batch.close()

    # ------------------------------------------------------ SyncVectorEnv-like access --
    def get_attr(self, name: str) -> tuple:
        """Each environment's attribute ``name``."""
        return tuple(getattr(env, name) for env in self.envs)

    def set_attr(self, name: str, values: Any | list | tuple) -> None:
        """Set ``name`` on each environment (one value for all, or a list of one each); a
        reward weight (``w_whirl``...) counts from the next step, a construction setting
        raises AttributeError."""
        if not isinstance(values, (list, tuple)):
            values = [values] * self.num_envs
        if len(values) != self.num_envs:
            raise ValueError(f"{len(values)} values for {self.num_envs} environments")
        for env, value in zip(self.envs, values):
            setattr(env, name, value)

    def call(self, name: str, *args: Any, **kwargs: Any) -> tuple:
        """Call method ``name`` of each environment (or get the attribute)."""
        out = []
        for env in self.envs:
            attr = getattr(env, name)
            out.append(attr(*args, **kwargs) if callable(attr) else attr)
        return tuple(out)


def _masked(info: dict, n: int, mask: np.ndarray | None = None) -> dict:
    """Gymnasium's vector info: every key with its ``_key`` mask (all True unless ``mask``)."""
    masks = np.ones((len(info), n), dtype=bool) if mask is None else np.tile(mask, (len(info), 1))
    out = {}
    for (k, v), m in zip(info.items(), masks):           # one fresh array, a row per key
        out[k] = v
        out["_" + k] = m
    return out


class PassiveVectorEnv(RotorDropVectorEnv):
    """Vector ``PassiveEnv`` (``gymnasium.make_vec`` of the passive id)."""
    env_class = _env.PassiveEnv


class DampingVectorEnv(RotorDropVectorEnv):
    """Vector ``DampingEnv``."""
    env_class = _env.DampingEnv


class RelevitateVectorEnv(RotorDropVectorEnv):
    """Vector ``RelevitateEnv``."""
    env_class = _env.RelevitateEnv


class FullVectorEnv(RotorDropVectorEnv):
    """Vector ``FullEnv``."""
    env_class = _env.FullEnv
