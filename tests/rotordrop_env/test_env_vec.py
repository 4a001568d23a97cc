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


def assert_rows_are_single_envs(venv, env_id, kw, seed, acts, on_end=None):
    """Each row of the batch ``venv`` steps as ``gym.make(env_id, **kw)`` reset with seed
    ``seed + row``, under the actions ``acts`` (steps, rows, dims), through SB3's auto-reset
    (terminal obs in info, obs = the reset obs); ``on_end(k, b_info, info)`` checks an end."""
    obs0 = venv.reset()
    batched = [venv.step(acts[k]) for k in range(len(acts))]
    for e in range(venv.num_envs):
        env = gym.make(env_id, **kw)
        obs, _ = env.reset(seed=seed + e)
        assert np.array_equal(obs, obs0[e])
        for k in range(len(acts)):
            obs, r, term, trunc, info = env.step(acts[k, e])
            b_obs, b_r, b_done, b_info = batched[k]
            assert b_r[e] == np.float32(r) and b_done[e] == (term or trunc)
            if term or trunc:
                assert np.array_equal(b_info[e]["terminal_observation"], obs)
                if on_end is not None:
                    on_end(k, b_info[e], info)
                obs, _ = env.reset()                 # continues the env's own random stream
            assert np.array_equal(b_obs[e], obs)


def test_batched_env_equals_single_envs_and_auto_resets():
    n, steps = 3, 6
    venv = BatchedRotorDropVecEnv("RotorDrop-Damping-v1", n, seed=10, **KW)
    assert isinstance(venv, VecEnv) and venv.num_envs == n

    ends = []

    def on_end(k, b_info, info):
        ends.append(k)
        assert b_info["TimeLimit.truncated"] is True
        assert b_info["kpi_peak_contact_force_N"] == info["kpi_peak_contact_force_N"]
    assert_rows_are_single_envs(venv, "RotorDrop-Damping-v1", KW, 10, _actions(n, steps), on_end)
    assert ends == [3] * n                           # every row's time limit, after 4 steps
    run_env_checkers(lambda: venv.envs[0])


def test_a_batch_of_flexible_rotors_equals_single_envs():
    """machine-flexible (its 2 bending modes per plane, randomised machines): the batch steps each
    row as the single environment of the same seed, through SB3's auto-reset."""
    n, steps = 3, 8
    kw = dict(scene="machine-flexible", episode_time=0.005, randomize=True)
    venv = make_batched("RotorDrop-Damping-v1", n, seed=3, n_threads=2, **kw)
    assert venv.envs[0].model.elastic_modes == 2
    assert_rows_are_single_envs(venv, "RotorDrop-Damping-v1", kw, 3, _actions(n, steps, seed=1))
