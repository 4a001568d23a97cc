"""The wrapper ``gym.make`` puts outermost around every rotor-drop environment (registered in
the ids' ``additional_wrappers``): a step that a wrapper ends before the environment's own end,
e.g. the ``TimeLimit`` of ``gym.make(id, max_episode_steps=N)``, gets the episode KPIs too, so
the final step's ``info`` always carries them (``Monitor(env, info_keywords=...)``). Assigning
a reward weight or a construction setting to it goes to the environment (Gymnasium 1.x wrappers
would otherwise keep the value themselves and the environment would never see it)."""
from __future__ import annotations

import gymnasium as gym

#: a key of :meth:`rotordrop_env.env.RotorDropEnv.kpis`: present when the env added them
KPI_MARK = "kpi_episode_time_s"


class EpisodeKPIs(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Adds ``env.unwrapped.kpis()`` to the final step's ``info`` when they are missing."""

    def __init__(self, env: gym.Env):
        gym.utils.RecordConstructorArgs.__init__(self)
        gym.Wrapper.__init__(self, env)

    def __setattr__(self, name: str, value) -> None:
        env = self.__dict__.get("env")
        if env is not None and (name.startswith("w_") or
                                name in getattr(env.unwrapped, "fixed_settings", ())):
            setattr(env.unwrapped, name, value)     # validated there (or refused)
        else:
            super().__setattr__(name, value)

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        if (terminated or truncated) and KPI_MARK not in info:
            info.update(self.env.unwrapped.kpis())
        return obs, reward, terminated, truncated, info
