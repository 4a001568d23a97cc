"""Batched SB3 VecEnv: same results as the single env, SB3 auto-reset semantics, checkers."""
import gymnasium as gym
import numpy as np
import pytest
from stable_baselines3.common.vec_env import VecEnv

from rotordrop_env import BatchedRotorDropVecEnv, make_batched

from helpers import run_env_checkers

KW = dict(episode_time=0.004, randomize=True)


def _actions(n_envs, steps, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-1, 1, (steps, n_envs, 2)).astype(np.float32)


def test_batched_env_equals_single_envs_and_auto_resets():
    n, steps = 3, 6
    venv = BatchedRotorDropVecEnv("RotorDrop-Damping-v1", n, seed=10, **KW)
    assert isinstance(venv, VecEnv) and venv.num_envs == n
    acts = _actions(n, steps)
    obs0 = venv.reset()
    batched = [venv.step(acts[k]) for k in range(steps)]
    for e in range(n):
        env = gym.make("RotorDrop-Damping-v1", **KW)
        obs, _ = env.reset(seed=10 + e)
        assert np.array_equal(obs, obs0[e])
        for k in range(steps):
            obs, r, term, trunc, info = env.step(acts[k, e])
            b_obs, b_r, b_done, b_info = batched[k]
            assert b_r[e] == np.float32(r) and b_done[e] == (term or trunc)
            if term or trunc:                        # SB3: terminal obs in info, obs = reset obs
                assert k == 3
                assert np.array_equal(b_info[e]["terminal_observation"], obs)
                assert b_info[e]["TimeLimit.truncated"] is True
                assert b_info[e]["kpi_peak_contact_force_N"] == info["kpi_peak_contact_force_N"]
                obs, _ = env.reset()                 # continues the env's own random stream
                assert np.array_equal(b_obs[e], obs)
                assert b_obs[e][env.unwrapped.obs_names.index("time")] == 0.0
            else:
                assert np.array_equal(b_obs[e], obs)


def test_batched_env_errors_and_factory():
    venv = make_batched("RotorDrop-Relevitate-v1", 2, seed=0, n_threads=1, episode_time=0.003)
    venv.reset()
    with pytest.raises(ValueError, match="out-of-range"):
        venv.step(np.array([0, 3]))
    with pytest.raises(ValueError, match="do not fit"):
        venv.step(np.zeros(3, dtype=np.int64))
    assert venv.get_attr("obs_names")[0] == venv.envs[0].obs_names
    with pytest.raises(ValueError, match="n_envs"):
        BatchedRotorDropVecEnv("RotorDrop-Passive-v1", 0)


def test_checkers_pass_on_the_batched_envs_single_counterpart():
    venv = BatchedRotorDropVecEnv("RotorDrop-Full-v1", 2, seed=0, episode_time=0.004)
    run_env_checkers(lambda: venv.envs[0])


def test_a_batch_of_flexible_rotors_equals_single_envs():
    """machine-flexible (its 2 bending modes per plane, randomised machines): the batch steps each
    row as the single environment of the same seed, through SB3's auto-reset."""
    n, steps = 3, 8
    kw = dict(scene="machine-flexible", episode_time=0.005, randomize=True)
    venv = make_batched("RotorDrop-Damping-v1", n, seed=3, n_threads=2, **kw)
    assert venv.envs[0].model.elastic_modes == 2
    acts = _actions(n, steps, seed=1)
    obs0 = venv.reset()
    batched = [venv.step(acts[k]) for k in range(steps)]
    for e in range(n):
        env = gym.make("RotorDrop-Damping-v1", **kw)
        obs, _ = env.reset(seed=3 + e)
        assert np.array_equal(obs, obs0[e])
        for k in range(steps):
            obs, r, term, trunc, info = env.step(acts[k, e])
            b_obs, b_r, b_done, b_info = batched[k]
            assert b_r[e] == np.float32(r) and b_done[e] == (term or trunc)
            if term or trunc:
                assert np.array_equal(b_info[e]["terminal_observation"], obs)
                obs, _ = env.reset()
            assert np.array_equal(b_obs[e], obs)
