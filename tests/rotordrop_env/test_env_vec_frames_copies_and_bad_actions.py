"""Batched VecEnv: rendering, copies, all-or-nothing bad actions; KPIs at a gym.make TimeLimit."""
import copy
import pickle
from unittest import mock

import gymnasium as gym
import numpy as np
import pytest
from stable_baselines3.common.monitor import Monitor

from rotordrop_env import make_batched
from rotordrop_env.env import RotorDropEnv

KW = dict(episode_time=0.004, n_threads=1)


def _acts(n_envs, steps, width=2, seed=0):
    return np.random.default_rng(seed).uniform(-1, 1, (steps, n_envs, width)).astype(np.float32)


def test_batched_rgb_frames_equal_the_single_envs():
    """The batch records every step as a single env does: same orbit/force trace, same frame."""
    steps = 3
    venv = make_batched("RotorDrop-Damping-v1", 2, seed=4, render_mode="rgb_array", **KW)
    venv.reset()
    acts = _acts(2, steps)
    for k in range(steps):
        venv.step(acts[k])
    env = gym.make("RotorDrop-Damping-v1", render_mode="rgb_array", episode_time=0.004)
    env.reset(seed=5)
    for k in range(steps):
        env.step(acts[k, 1])
    mine, ref = venv.envs[1]._renderer, env.unwrapped._renderer
    assert mine.n == steps + 1
    assert np.array_equal(mine.recorded, ref.recorded, equal_nan=True)
    assert np.array_equal(venv.get_images()[1], env.render())


@pytest.mark.filterwarnings("ignore:.*non-interactive 'agg' backend")
def test_batched_human_mode_redraws_every_step():
    venv = make_batched("RotorDrop-Passive-v1", 2, seed=0, render_mode="human", **KW)
    venv.reset()
    with mock.patch.object(RotorDropEnv, "render", autospec=True) as render:
        venv.step(np.zeros((2, 1), np.float32))
        venv.step(np.zeros((2, 1), np.float32))
    assert render.call_count == 4
    assert [e._renderer.n for e in venv.envs] == [3, 3]
    venv.close()


@pytest.mark.parametrize("copier", [copy.deepcopy, lambda v: pickle.loads(pickle.dumps(v))],
                         ids=["deepcopy", "pickle"])
def test_a_copied_batch_steps_identically_across_episode_ends(copier):
    venv = make_batched("RotorDrop-Damping-v1", 2, seed=0, **KW)
    venv.reset()
    acts = _acts(2, 9)
    venv.step(acts[0])
    twin = copier(venv)
    for e, env in enumerate(twin.envs):
        assert np.shares_memory(env._b.y, twin.stack.y[e]) and env._b.y.base is not None
        assert not np.shares_memory(env._b.y, venv.stack.y)
    for k in range(1, 9):                         # two episode ends (4 steps each)
        o1, r1, d1, i1 = venv.step(acts[k])
        o2, r2, d2, i2 = twin.step(acts[k])
        assert np.array_equal(o1, o2) and np.array_equal(r1, r2) and np.array_equal(d1, d2)
        assert d1.tolist() == [k % 4 == 3] * 2
        for a, b in zip(i1, i2):
            assert a.keys() == b.keys()
            assert all(np.array_equal(a[key], b[key], equal_nan=True) for key in a)
        assert twin.get_attr("time") == venv.get_attr("time")


@pytest.mark.parametrize("env_id,bad,match", [
    ("RotorDrop-Damping-v1", (1, 0, np.nan), "non-finite"),
    ("RotorDrop-Damping-v1", (2, 1, 1.5), "out-of-range"),
    ("RotorDrop-Relevitate-v1", (1, 0, 3), "must be 0 \\(stay off\\) or 1"),
])
def test_one_bad_action_advances_no_environment(env_id, bad, match):
    venv = make_batched(env_id, 3, seed=0, **KW)
    ref = make_batched(env_id, 3, seed=0, **KW)
    ref.reset()
    venv.reset()
    a = np.zeros((3, venv.stack.act.shape[1]), np.float32)
    e, j, value = bad
    a[e, j] = value
    if venv.envs[0]._discrete:
        a = a[:, 0]
    with pytest.raises(ValueError, match=match) as exc:
        venv.step(a)
    assert f"action {a[e]!r}" in str(exc.value)
    assert venv.get_attr("time") == [0.0, 0.0, 0.0]
    good = np.zeros_like(a)
    assert np.array_equal(venv.step(good)[0], ref.step(good)[0])   # continues as if untouched


def test_gym_make_time_limit_final_info_carries_the_kpis():
    """gym.make(max_episode_steps=N) truncates before the env's own end: the KPIs still come
    with that final step (every step's info carries the KPIs so far), so SB3's Monitor finds
    its info_keywords."""
    keys = ("kpi_backward_whirl", "kpi_peak_contact_force_N", "kpi_episode_time_s")
    made = gym.make("RotorDrop-Damping-v1", max_episode_steps=3, episode_time=0.01)
    env = Monitor(made, info_keywords=keys)
    for seed in (0, 1):                             # also after a reset
        env.reset(seed=seed)
        for k in range(3):
            _, _, term, trunc, info = env.step(np.zeros(2, np.float32))
            assert trunc == (k == 2) and not term
            assert info["kpi_episode_time_s"] == pytest.approx(1e-3 * (k + 1), abs=1e-12)
        assert info["episode"]["kpi_episode_time_s"] == pytest.approx(0.003, abs=1e-12)
        assert info["episode"]["kpi_peak_contact_force_N"] == env.unwrapped.kpis()["kpi_peak_contact_force_N"]
    assert gym.make(made.spec).spec == made.spec   # the spec still re-creates the env


def test_the_batch_refuses_max_episode_steps():
    with pytest.raises(ValueError, match="max_episode_steps.*episode_time"):
        make_batched("RotorDrop-Damping-v1", 2, max_episode_steps=3)
