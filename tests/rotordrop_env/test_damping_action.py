"""``damping_action``: the map of the damper action to the commanded support damping."""
import gymnasium as gym
import numpy as np
import pytest

import rotordrop_env  # noqa: F401  (registers the ids)
from agents.control.plant import Plant

from helpers import run_env_checkers


def damper_states(damping, steps: int = 40, env_id="RotorDrop-Damping-v1", **kw):
    """The damper states (C_s of housing 1, 2) and the full state after each step."""
    env = gym.make(env_id, episode_time=0.05, terminate_on_failure=False, **kw)
    env.reset(seed=5)
    n = env.action_space.shape[0]
    out = []
    for _ in range(steps):
        a = np.zeros(n, dtype=np.float32)
        a[:2] = damping
        env.step(a)
        out.append(env.unwrapped.state.copy())
    return np.array(out)


@pytest.mark.parametrize("a, linear", [(-1.0, -1.0), (-0.25, 0.5), (0.0, 1.0), (0.7, 1.0)])
def test_from_max_is_the_linear_map_folded_at_c_max(a, linear):
    """from_max: a >= 0 commands C_max, a in [-1, 0] the linear map's 2a + 1: the same drop
    bit for bit."""
    assert np.array_equal(damper_states(a, damping_action="from_max"), damper_states(linear))


def test_linear_is_the_default_and_zero_is_mid_range():
    assert np.array_equal(damper_states(0.3, damping_action="linear"), damper_states(0.3))
    assert not np.array_equal(damper_states(0.0), damper_states(0.0, damping_action="from_max"))


def test_zero_action_holds_c_max_in_the_full_supervisor_env():
    env = gym.make("RotorDrop-Full-v1", command="supervisor", damping_action="from_max",
                   episode_time=0.1, terminate_on_failure=False)
    env.reset(seed=1)
    for _ in range(100):
        obs, *_ = env.step(np.zeros(8, dtype=np.float32))
    u = env.unwrapped
    c_max = u.base_scene.support.damping_max
    got = [obs[u.obs_names.index(n)] * u.obs_scale[u.obs_names.index(n)] for n in ("damping1", "damping2")]
    assert got == pytest.approx([c_max, c_max], rel=1e-3)      # after 10 damper time constants


@pytest.mark.parametrize("env_id, kw", [("RotorDrop-Damping-v1", {}),
                                        ("RotorDrop-Full-v1", {"command": "supervisor"})])
def test_env_checkers_pass_with_from_max(env_id, kw):
    run_env_checkers(lambda: gym.make(env_id, damping_action="from_max", episode_time=0.01, **kw))


def test_unknown_map_names_the_maps():
    with pytest.raises(ValueError, match="damping_action = 'max' is not a damper map; the maps "
                                         "are 'linear', 'from_max'"):
        gym.make("RotorDrop-Damping-v1", damping_action="max")


def test_from_max_needs_damper_commands():
    with pytest.raises(ValueError, match="applies to the environments with damper commands"):
        gym.make("RotorDrop-Relevitate-v1", damping_action="from_max")


def test_setting_is_fixed_after_construction():
    env = gym.make("RotorDrop-Damping-v1", damping_action="from_max")
    with pytest.raises(AttributeError):
        env.unwrapped.damping_action = "linear"


@pytest.mark.parametrize("command", [-1.0, 0.0, 0.5, 1.0])
def test_controllers_command_the_same_damping_under_either_map(command):
    """Plant.compose turns a controller's damper command (-1 C_min, +1 C_max, linear) into
    the action of the env's map: the same damping under both maps."""
    acts = {}
    for m in ("linear", "from_max"):
        env = gym.make("RotorDrop-Damping-v1", damping_action=m)
        plant = Plant.from_env(env)
        assert plant.damping_action == m
        acts[m] = plant.compose(1, {"damping": np.full((1, 2), command)})[0]
    assert np.array_equal(damper_states(acts["linear"]),
                          damper_states(acts["from_max"], damping_action="from_max"))
