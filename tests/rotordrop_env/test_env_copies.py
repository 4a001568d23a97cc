"""Copies of environments: deepcopy / pickle (single env and batch, with and without rendering),
a JSON env spec made again, and a Scene through JSON: each continues with the same trajectory."""
import copy
import dataclasses
import json
import pickle

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.envs.registration import EnvSpec

from physics.scene import Scene, SceneError, load_scene
from rotordrop_env import make_batched

IDS = ["RotorDrop-Passive-v1", "RotorDrop-Damping-v1", "RotorDrop-Relevitate-v1", "RotorDrop-Full-v1"]
COPIERS = {"deepcopy": copy.deepcopy, "pickle": lambda x: pickle.loads(pickle.dumps(x))}


def _actions(space, n, seed=0):
    space = copy.deepcopy(space)
    space.seed(seed)
    return [space.sample() for _ in range(n)]


def _same_step(a, b):
    (o1, r1, te1, tr1, i1), (o2, r2, te2, tr2, i2) = a, b
    assert np.array_equal(o1, o2) and r1 == r2 and (te1, tr1) == (te2, tr2)
    assert i1.keys() == i2.keys()
    assert all(np.array_equal(i1[k], i2[k], equal_nan=True) for k in i1)


@pytest.mark.parametrize("copier", COPIERS.values(), ids=COPIERS.keys())
@pytest.mark.parametrize("render_mode", [None, "rgb_array"])
@pytest.mark.parametrize("env_id", IDS)
def test_a_copied_env_steps_and_renders_like_the_original(env_id, render_mode, copier):
    """Copied mid-episode, the copy and the original continue identically, through the episode
    end and the next (seeded) reset, and draw the same frames; the original is untouched."""
    env = gym.make(env_id, episode_time=0.005, randomize=True, render_mode=render_mode)
    env.reset(seed=3)
    acts = _actions(env.action_space, 10)
    for a in acts[:2]:
        env.step(a)
    if render_mode:
        env.render()                        # the copy must not depend on drawing resources
    twin = copier(env)
    assert twin.unwrapped._b.y is not env.unwrapped._b.y
    for k, a in enumerate(acts[2:]):
        if k == 3:                          # after the episode end (5 steps)
            o1, i1 = env.reset(seed=11)
            o2, i2 = twin.reset(seed=11)
            assert np.array_equal(o1, o2) and env.unwrapped.scenario == twin.unwrapped.scenario
        _same_step(env.step(a), twin.step(a))
        if render_mode:
            f1, f2 = env.render(), twin.render()
            assert f1.shape == (432, 768, 3) and np.array_equal(f1, f2)
        else:
            assert twin.unwrapped._renderer is None
    twin.close()
    env.reset()
    env.step(acts[0])                       # closing the copy leaves the original open


@pytest.mark.parametrize("copier", COPIERS.values(), ids=COPIERS.keys())
def test_a_copied_rendering_batch_draws_the_same_frames(copier):
    venv = make_batched("RotorDrop-Full-v1", 2, seed=0, render_mode="rgb_array",
                        episode_time=0.003, n_threads=1)
    venv.reset()
    acts = np.stack(_actions(venv.action_space, 12)).reshape(6, 2, -1)
    venv.step(acts[0])
    venv.render()
    twin = copier(venv)
    for a in acts[1:]:                      # past an episode end and its auto-reset
        o1, r1, d1, _ = venv.step(a)
        o2, r2, d2, _ = twin.step(a)
        assert np.array_equal(o1, o2) and np.array_equal(r1, r2) and np.array_equal(d1, d2)
        for f1, f2 in zip(venv.get_images(), twin.get_images()):
            assert np.array_equal(f1, f2)


def _trajectory(env, seed, n=6):
    obs, info = env.reset(seed=seed)
    out = [obs]
    for a in _actions(env.action_space, n, seed=seed):
        obs, r, *_ = env.step(a)
        out += [obs, np.array([r])]
    return np.concatenate(out), env.unwrapped.scenario


def test_a_json_env_spec_makes_the_same_environment():
    """gym.make(EnvSpec.from_json(env.spec.to_json())): same kwargs, same trajectory, also
    with a Scene object, randomisation ranges (tuples become JSON lists) and overrides."""
    scene = load_scene("paper", {"support.stiffness": 2e7, "rotor.speed_rpm": 9000.0})
    env = gym.make("RotorDrop-Full-v1", scene=scene, overrides={"contact.friction": 0.45},
                   randomize=True, randomization={"power_return_time": (0.03, 0.04)},
                   command="continuous", episode_time=0.006, w_whirl=3.0)
    again = gym.make(EnvSpec.from_json(env.spec.to_json()))
    assert again.unwrapped.base_scene == env.unwrapped.base_scene
    assert again.unwrapped.ranges == env.unwrapped.ranges and again.unwrapped.w_whirl == 3.0
    for seed in (0, 1):
        (t1, s1), (t2, s2) = _trajectory(env, seed), _trajectory(again, seed)
        assert np.array_equal(t1, t2) and s1 == s2
    assert s1["contact.friction"] == 0.45 and 0.03 <= s1["power_return_time"] <= 0.04


@pytest.mark.parametrize("preset,overrides", [("paper", {}),
                                              ("spec", {"contact.friction": 0.1 + 0.2,
                                                        "solver.rtol": 3e-6,
                                                        "effects.retainer_bearing": "linear"})])
def test_a_scene_survives_json(preset, overrides):
    scene = dataclasses.replace(load_scene(preset, overrides), name="my machine")
    back = Scene.from_json(scene.to_json())
    assert back == scene and back.name == "my machine"
    assert back.contact.friction == scene.contact.friction          # bit for bit (0.30000000000000004)
    assert Scene.from_dict(json.loads(json.dumps(dataclasses.asdict(scene)))) == scene
    env_a = gym.make("RotorDrop-Damping-v1", scene=scene, episode_time=0.004)
    env_b = gym.make("RotorDrop-Damping-v1", scene=json.loads(scene.to_json()), episode_time=0.004)
    (t1, _), (t2, _) = _trajectory(env_a, 0, 4), _trajectory(env_b, 0, 4)
    assert np.array_equal(t1, t2)


def test_bad_scene_json_names_the_problem():
    with pytest.raises(SceneError, match="contact.frction"):
        Scene.from_dict({"contact": {"frction": 0.3}})
    with pytest.raises(SceneError, match=r"contact.friction = 7.0 is out of range"):
        Scene.from_json('{"contact": {"friction": 7.0}}')
    with pytest.raises(SceneError, match="malformed scene JSON"):
        Scene.from_json("{contact")
    with pytest.raises(ValueError, match="scene = 3 must be a preset name"):
        gym.make("RotorDrop-Passive-v1", scene=3)
