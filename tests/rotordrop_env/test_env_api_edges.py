"""API edges: reward weights set at run time (single env, gym.make wrapper, SB3 VecEnvs),
settings that cannot change, stepping after the end or after close, non-real actions."""
import warnings

import gymnasium as gym
import numpy as np
import pytest
from stable_baselines3.common.env_util import make_vec_env

from rotordrop_env import make_batched

WHIRL = dict(overrides={"contact.friction": 0.5}, episode_time=0.06, terminate_on_failure=False)


def _run(step, n):
    return [step() for _ in range(n)]


def _whirl_terms(set_weight, step, n_before=40, n_after=15):
    """reward_whirl of the steps before and after ``set_weight()`` (the paper scene at μ = 0.5
    whirls from about 20 ms after the fault)."""
    before = _run(step, n_before)
    set_weight()
    return before, _run(step, n_after)


def test_a_reward_weight_set_on_the_env_counts_from_the_next_step():
    """w_whirl 10 -> 25 on one of two identical envs: same physics, whirl term x 2.5 from the
    next step on, the other terms unchanged."""
    envs = [gym.make("RotorDrop-Damping-v1", **WHIRL) for _ in range(2)]
    for e in envs:
        e.reset(seed=0)
    a = np.zeros(2, np.float32)
    infos = [[e.step(a)[4] for _ in range(40)] for e in envs]
    envs[1].set_wrapper_attr("w_whirl", 25.0)    # through gym.make's wrappers
    assert envs[1].unwrapped.w_whirl == 25.0 == envs[1].get_wrapper_attr("w_whirl")
    after = [[e.step(a) for _ in range(15)] for e in envs]
    assert [i["reward_whirl"] for i in infos[0]] == [i["reward_whirl"] for i in infos[1]]
    w0 = np.array([s[4]["reward_whirl"] for s in after[0]])
    w1 = np.array([s[4]["reward_whirl"] for s in after[1]])
    assert (w0 < 0).sum() >= 5                     # the rotor whirls in these steps
    np.testing.assert_allclose(w1, 2.5 * w0, rtol=1e-12)
    for s0, s1 in zip(*after):
        assert np.array_equal(s0[0], s1[0]) and s0[4]["reward_contact"] == s1[4]["reward_contact"]
        assert s1[1] - s0[1] == pytest.approx(1.5 * s0[4]["reward_whirl"], rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("how", ["batched set_attr", "DummyVecEnv env_method"])
def test_a_reward_weight_set_through_a_vec_env_counts(how):
    if how == "batched set_attr":
        make = lambda: make_batched("RotorDrop-Damping-v1", 2, seed=0, n_threads=1, **WHIRL)
        set_w = lambda v: v.set_attr("w_whirl", 0.0, indices=[1])
    else:       # SB3's setattr would land on its Monitor wrapper: set_wrapper_attr reaches the env
        make = lambda: make_vec_env("RotorDrop-Damping-v1", 2, seed=0, env_kwargs=WHIRL)
        set_w = lambda v: v.env_method("set_wrapper_attr", "w_whirl", 0.0, indices=[1])
    venv = make()
    venv.reset()
    a = np.zeros((2, 2), np.float32)
    before, after = _whirl_terms(lambda: set_w(venv), lambda: venv.step(a)[3])
    assert venv.get_attr("w_whirl") == [10.0, 0.0]
    w = np.array([[i["reward_whirl"] for i in s] for s in after])
    assert (w[:, 0] < 0).sum() >= 5 and (w[:, 1] == 0).all()
    assert all(s[0]["reward_whirl"] == s[1]["reward_whirl"] for s in before)


@pytest.mark.parametrize("target", ["env", "wrapper", "batch"])
def test_settings_fixed_at_construction_and_misspelt_weights_raise(target):
    if target == "batch":
        venv = make_batched("RotorDrop-Damping-v1", 1, n_threads=1)
        setter = lambda name, value: venv.set_attr(name, value)
    else:
        env = gym.make("RotorDrop-Damping-v1")
        # through gym.make's wrappers: Gymnasium's set_wrapper_attr reaches the environment
        setter = (lambda name, value: setattr(env.unwrapped, name, value)) if target == "env" \
            else env.set_wrapper_attr
    for name in ("control_dt", "episode_time", "terminate_on_failure", "randomize"):
        with pytest.raises(AttributeError, match=f"{name} is fixed when the environment is made"):
            setter(name, 1)
    with pytest.raises(AttributeError, match="'w_whril' is not a reward weight; .*w_whirl"):
        setter("w_whril", 1.0)
    with pytest.raises(ValueError, match=r"w_contact = -1.0 must be in \[0, 1e\+09\]"):
        setter("w_contact", -1.0)
    with pytest.raises(ValueError, match="w_effort = 'a' must be a real number"):
        setter("w_effort", "a")
    setter("my_note", "fine")                    # any other attribute: plain Python


def test_a_step_after_the_end_warns_once_like_gymnasium():
    env = gym.make("RotorDrop-Passive-v1", episode_time=0.003)
    a = np.zeros(1, np.float32)
    for _ in range(2):                            # also in the second episode
        env.reset(seed=0)
        flags = [env.step(a)[3] for _ in range(3)]
        assert flags == [False, False, True]
        with pytest.warns(UserWarning, match="already returned terminated = True or truncated = True"):
            env.step(a)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            env.step(a)                           # once per episode


@pytest.mark.parametrize("target", ["env", "wrapper", "batch"])
def test_a_closed_env_refuses_to_step_or_reset(target):
    if target == "batch":
        env = make_batched("RotorDrop-Damping-v1", 2, n_threads=1, render_mode="rgb_array")
        step = lambda: env.step(np.zeros((2, 2), np.float32))
    else:
        env = gym.make("RotorDrop-Damping-v1", render_mode="rgb_array")
        env = env.unwrapped if target == "env" else env
        step = lambda: env.step(np.zeros(2, np.float32))
    env.reset()
    step()
    env.close()
    env.close()                                   # twice is fine
    with pytest.raises(gym.error.ClosedEnvironmentError, match=r"step\(\) on a closed environment"):
        step()
    with pytest.raises(gym.error.ClosedEnvironmentError, match=r"reset\(\) on a closed environment"):
        env.reset()


BAD = [True, np.bool_(False), np.array([True, False]), 1 + 0j, np.array([0.5 + 1j, 0.0]), "1",
       np.array(["0.1", "0.2"]), np.array([None, None])]


@pytest.mark.parametrize("action", BAD, ids=repr)
@pytest.mark.parametrize("env_id,kwargs,space", [
    ("RotorDrop-Damping-v1", {}, r"Box\(-1.0, 1.0, \(2,\), float32\)"),
    ("RotorDrop-Relevitate-v1", {}, r"Discrete\(2\)")])
def test_non_real_actions_raise_naming_the_action_space(env_id, kwargs, space, action):
    env = gym.make(env_id, **kwargs)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=f"is not in {space}: give real numbers"):
        env.step(action)
    assert env.unwrapped.time == 0.0              # nothing advanced
    venv = make_batched(env_id, 2, seed=0, n_threads=1, **kwargs)
    venv.reset()
    batch = np.array([action, action], dtype=np.asarray(action).dtype)
    with pytest.raises(ValueError, match=f"is not in {space}: give real numbers"):
        venv.step(batch)
    assert venv.get_attr("time") == [0.0, 0.0]
