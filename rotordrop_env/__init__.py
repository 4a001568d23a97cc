"""Gymnasium environments of the AMB rotor drop, registered on import.

    import gymnasium as gym, rotordrop_env
    env = gym.make("RotorDrop-Damping-v1", overrides={"contact.friction": 0.4})
    envs = gym.make_vec("RotorDrop-Damping-v1", num_envs=16, vectorization_mode="vector_entry_point")

Ids: ``RotorDrop-Passive-v1``, ``RotorDrop-Damping-v1``, ``RotorDrop-Relevitate-v1``,
``RotorDrop-Full-v1``, ``RotorDrop-Recover-v1`` (see docs/environments.md), one declaration each in
:mod:`rotordrop_env.tasks` (``TASKS``, where a new task is registered). Each id's ``vector_entry_point`` is the
batched Gymnasium vector environment (:mod:`rotordrop_env.vector`); ``BatchedRotorDropVecEnv`` /
``make_batched`` are the same batch as a Stable-Baselines3 ``VecEnv``. In a process that has not
imported ``rotordrop_env`` (e.g. a spawned worker) write the id as
``"rotordrop_env:RotorDrop-Damping-v1"``: Gymnasium imports the module first.
"""
from .tasks import TASKS

#: id -> entry point of every registered task (``rotordrop_env.tasks.TASKS``, kept in step)
ENV_IDS = TASKS.entry_points


def __getattr__(name):
    if name in ("RotorDropVectorEnv", "PassiveVectorEnv", "DampingVectorEnv",
                "RelevitateVectorEnv", "FullVectorEnv"):
        from . import vector
        return getattr(vector, name)
    if name in ("BatchedRotorDropVecEnv", "make_batched"):
        from . import vec_env
        return getattr(vec_env, name)
    if name in ("RotorDropEnv", "PassiveEnv", "DampingEnv", "RelevitateEnv", "FullEnv"):
        from . import env
        return getattr(env, name)
    raise AttributeError(f"module 'rotordrop_env' has no attribute {name!r}")


__all__ = ["ENV_IDS", "RotorDropVectorEnv", "BatchedRotorDropVecEnv", "make_batched", "RotorDropEnv", "PassiveEnv",
           "DampingEnv", "RelevitateEnv", "FullEnv"]
