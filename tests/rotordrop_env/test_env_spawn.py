"""Spawned worker processes (which have not imported rotordrop_env) make the environments with
the module-prefixed id, and Gymnasium's async vector env runs with the spawn start method."""
import multiprocessing as mp

import gymnasium as gym
import numpy as np

import rotordrop_env  # noqa: F401


def _make_and_step(env_id: str):
    import gymnasium
    env = gymnasium.make(env_id, episode_time=0.002)
    obs, _ = env.reset(seed=0)
    obs, reward, *_ = env.step(env.action_space.sample())
    return obs.shape, float(reward)


def test_a_spawned_worker_makes_the_env_with_the_module_prefix():
    ctx = mp.get_context("spawn")
    with ctx.Pool(1) as pool:
        shape, reward = pool.apply(_make_and_step, ("rotordrop_env:RotorDrop-Damping-v1",))
    assert shape == gym.make("RotorDrop-Damping-v1").observation_space.shape
    assert np.isfinite(reward)


def test_async_make_vec_with_spawned_workers():
    envs = gym.make_vec("RotorDrop-Passive-v1", num_envs=2, vectorization_mode="async",
                        vector_kwargs={"context": "spawn"}, episode_time=0.002)
    try:
        envs.reset(seed=0)
        *_, trunc, info = envs.step(envs.action_space.sample())
        *_, trunc, info = envs.step(envs.action_space.sample())
        assert trunc.all()                              # 2-step episodes
        assert info["kpi_episode_time_s"].shape == (2,)
    finally:
        envs.close()
