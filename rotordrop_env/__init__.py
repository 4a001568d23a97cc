"""Gymnasium environments of the AMB rotor drop, registered on import.

    import gymnasium as gym, rotordrop_env
    env = gym.make("RotorDrop-Damping-v0", overrides={"contact.friction": 0.4})

Ids: ``RotorDrop-Passive-v0``, ``RotorDrop-Damping-v0``, ``RotorDrop-Relevitate-v0``,
``RotorDrop-Full-v0`` (see docs/environments.md). ``BatchedRotorDropVecEnv`` / ``make_batched``
step N rotors in one parallel numba call as a Stable-Baselines3 ``VecEnv``.
"""
from gymnasium.envs.registration import WrapperSpec, register, registry

ENV_IDS = {
    "RotorDrop-Passive-v0": "rotordrop_env.env:PassiveEnv",
    "RotorDrop-Damping-v0": "rotordrop_env.env:DampingEnv",
    "RotorDrop-Relevitate-v0": "rotordrop_env.env:RelevitateEnv",
    "RotorDrop-Full-v0": "rotordrop_env.env:FullEnv",
}

#: outermost wrapper of every gym.make: KPIs also when a TimeLimit ends the episode early
_WRAPPERS = (WrapperSpec("EpisodeKPIs", "rotordrop_env.wrappers:EpisodeKPIs", {}),)

for _id, _entry in ENV_IDS.items():
    if _id not in registry:
        register(id=_id, entry_point=_entry, additional_wrappers=_WRAPPERS)


def __getattr__(name):
    if name in ("BatchedRotorDropVecEnv", "make_batched"):
        from . import vec_env
        return getattr(vec_env, name)
    if name in ("RotorDropEnv", "PassiveEnv", "DampingEnv", "RelevitateEnv", "FullEnv"):
        from . import env
        return getattr(env, name)
    raise AttributeError(f"module 'rotordrop_env' has no attribute {name!r}")


__all__ = ["ENV_IDS", "BatchedRotorDropVecEnv", "make_batched", "RotorDropEnv", "PassiveEnv",
           "DampingEnv", "RelevitateEnv", "FullEnv"]
