"""Policy zips under plain Stable-Baselines3: every shipped zip acts under ``PPO.load`` as under
the project's loader, and as its separate pieces (VecNormalize statistics, network, residual
baseline) did; exported SAC / TD3 zips too; a residual on a baseline with per-episode state
refuses plain SB3 with an error that says how to load it."""
import json
import pickle
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import torch

from agents.control.controllers import BASELINES, make_baseline
from agents.learning.hyperparams import algo_class
from agents.control.plant import Plant
from agents.learning.policies import LearnedPolicy, export_policy, load_shipped, shipped_dir, shipped_names
from agents.control.residual import residual_action
from agents.sb3_policy import export_self_contained, is_self_contained

ROOT = Path(__file__).resolve().parents[3]

torch.set_num_threads(1)


def _episode_obs(env, actor, seeds=(0, 1), steps=40):
    """Observations of real episodes driven by ``actor`` (randomised scenarios)."""
    obs = []
    for seed in seeds:
        o, _ = env.reset(seed=seed)
        for _ in range(steps):
            obs.append(o)
            o, *_ = env.step(actor.predict(o, deterministic=True)[0])
    return np.array(obs)


@pytest.mark.parametrize("name", shipped_names())
def test_a_shipped_zip_acts_under_plain_sb3_as_under_the_project_loader(name):
    meta = json.loads((shipped_dir() / f"{name}.json").read_text())
    zip_path = shipped_dir() / f"{name}.zip"
    plain = algo_class(meta["algo"]).load(zip_path, device="cpu")
    assert is_self_contained(plain)
    env = gym.make(meta["env_id"], **meta["env_kwargs"])
    project = load_shipped(name).bound(Plant.from_env(env))
    obs = _episode_obs(env, project)
    mine = plain.predict(obs, deterministic=True)[0]
    assert np.array_equal(mine, project.predict(obs, deterministic=True)[0])
    assert np.array_equal(plain.predict(obs[7], deterministic=True)[0],        # one observation
                          project.predict(obs[7], deterministic=True)[0])
    # ... and as the pieces the zip replaces: the statistics file, the bare network, the residual
    with open(shipped_dir() / f"{name}.pkl", "rb") as fh:
        vn = pickle.load(fh)
    net, _ = plain.policy.network_predict(vn.normalize_obs(obs), deterministic=True)
    hp = meta["hyperparams"]
    expected = (residual_action(make_baseline(hp["residual"], Plant.from_env(env)), obs, net,
                                hp["residual_scale"]) if hp.get("residual") else net)
    assert np.array_equal(mine, expected)
    assert not np.array_equal(net, plain.policy.network_predict(obs, deterministic=True)[0])



def test_a_shipped_policy_pickles_as_its_file_and_acts_the_same():
    """A Ray task of ``rotordrop benchmark --backend ray`` receives the policy pickled as the
    path it was loaded from (self-contained zips included) and loads it again."""
    pol = load_shipped("ppo-full")
    env = gym.make(pol.env_id, **pol.env_kwargs)
    plant = Plant.from_env(env)
    again = pickle.loads(pickle.dumps(pol))
    assert again.source == pol.source and again.residual == pol.residual
    obs = _episode_obs(env, pol.bound(plant), seeds=(3,), steps=20)
    assert np.array_equal(again.bound(plant).predict(obs)[0], pol.predict(obs)[0])

def _trained_run(tmp_path, algo, residual=None, sde=False):
    """A tiny model of ``algo`` with VecNormalize statistics from a few hundred steps
    (``sde``: with gSDE exploration)."""
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import VecNormalize
    env_id = "RotorDrop-Full-v1"
    env_kwargs = dict(command="continuous", episode_time=0.02, randomize=True)
    venv = VecNormalize(make_vec_env(env_id, 2, seed=0, env_kwargs=env_kwargs))
    kw = dict(n_steps=64, batch_size=64) if algo == "ppo" else dict(learning_starts=50, buffer_size=500)
    if sde:
        kw["use_sde"] = True
    model = algo_class(algo)("MlpPolicy", venv, seed=0, device="cpu",
                             policy_kwargs=dict(net_arch=[16, 16]), **kw)
    model.learn(160)
    venv.training = False
    return model, venv, env_id, env_kwargs


@pytest.mark.parametrize("algo, sde", [("ppo", False), ("sac", False), ("td3", False),
                                       ("tqc", False), ("ppo", True), ("sac", True)])
def test_an_exported_model_acts_as_model_plus_vecnormalize_plus_residual(tmp_path, algo, sde):
    """Also with gSDE, which PPO passes to its policy outside policy_kwargs (the export once
    rebuilt it without, and a gSDE run failed when saving its final model)."""
    model, vn, env_id, env_kwargs = _trained_run(tmp_path, algo, sde=sde)
    out = export_self_contained(model, vn, tmp_path / "policy.zip", env_id=env_id,
                                env_kwargs=env_kwargs, residual="whirl-brake", residual_scale=0.5)
    plain = algo_class(algo).load(out, device="cpu")
    env = gym.make(env_id, **env_kwargs)
    base = make_baseline("whirl-brake", Plant.from_env(env))
    obs = _episode_obs(env, plain, seeds=(3,), steps=20)
    net, _ = model.predict(vn.normalize_obs(obs), deterministic=True)
    assert np.array_equal(plain.predict(obs, deterministic=True)[0],
                          residual_action(base, obs, net, 0.5))
    assert "rotordrop" not in model.policy_kwargs and not is_self_contained(model)   # untouched


def test_a_residual_on_a_stateful_baseline_refuses_plain_sb3(tmp_path):
    assert not BASELINES["whirl-switch"].memoryless
    model, vn, env_id, env_kwargs = _trained_run(tmp_path, "ppo")
    out = export_self_contained(model, vn, tmp_path / "switch.zip", env_id=env_id,
                                env_kwargs=env_kwargs, residual="whirl-switch")
    plain = algo_class("ppo").load(out, device="cpu")
    obs = gym.make(env_id, **env_kwargs).reset(seed=0)[0]
    with pytest.raises(RuntimeError, match=r"whirl-switch.*LearnedPolicy.load\(path\)"):
        plain.predict(obs)
    meta = dict(algo="ppo", env_id=env_id, env_kwargs=env_kwargs)
    (tmp_path / "switch.json").write_text(json.dumps(meta))
    env = gym.make(env_id, **env_kwargs)
    pol = LearnedPolicy.load(out).bound(Plant.from_env(env))           # the way the error names
    assert pol.residual == "whirl-switch" and pol.predict(obs)[0].shape == (6,)


@pytest.mark.parametrize("name", ["max-damping", "whirl-brake"])
def test_memoryless_baselines_act_on_the_observation_alone(name):
    """What a zip relies on: the baseline's action on a shuffled batch of observations is
    its action in the episode, step by step."""
    env_id = "RotorDrop-Full-v1"
    env = gym.make(env_id, command="continuous", randomize=True, terminate_on_failure=False)
    ctrl = make_baseline(name, Plant.from_env(env))
    obs, acts = [], []
    o, _ = env.reset(seed=2)
    for _ in range(80):
        a, _ = ctrl.predict(o)
        obs.append(o)
        acts.append(a)
        o, *_ = env.step(a)
    order = np.random.default_rng(0).permutation(len(obs))
    fresh = make_baseline(name, Plant.from_env(env))
    assert np.array_equal(fresh.predict(np.array(obs)[order])[0], np.array(acts)[order])


def test_export_policy_of_a_run_writes_a_zip_plain_sb3_runs(tmp_path):
    """``rotordrop export-policy``'s function on a shipped name re-writes the same policy."""
    out = export_policy("ppo-damping", tmp_path / "again.zip")
    a = algo_class("ppo").load(out, device="cpu")
    b = algo_class("ppo").load(shipped_dir() / "ppo-damping.zip", device="cpu")
    obs = np.random.default_rng(1).normal(size=(16, a.observation_space.shape[0])).astype(np.float32)
    assert np.array_equal(a.predict(obs, deterministic=True)[0], b.predict(obs, deterministic=True)[0])


def test_export_reads_env_and_residual_from_the_models_training_env(tmp_path):
    """export_self_contained(model, vecnormalize, path): what the run's env says is inside."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize
    from agents.control.residual import ResidualAction
    from rotordrop_env import make_batched
    kw = dict(command="continuous", episode_time=0.02)
    venv = VecNormalize(ResidualAction(make_batched("RotorDrop-Relevitate-v1", 2, seed=0,
                                                    n_threads=1, **kw), base="whirl-brake", scale=0.5))
    model = PPO("MlpPolicy", venv, n_steps=32, batch_size=32, seed=0, device="cpu")
    model.learn(64)
    out = export_self_contained(model, venv, tmp_path / "p.zip")
    inside = PPO.load(out, device="cpu").policy.rotordrop
    assert (inside["env_id"], inside["residual"], inside["residual_scale"]) == \
        ("RotorDrop-Relevitate-v1", "whirl-brake", 0.5)
    assert inside["env_kwargs"] == kw and inside["normalize"]["clip_obs"] == 10.0


def test_a_residual_on_tuned_constants_carries_them_and_acts_as_that_law(tmp_path):
    """``residual: {law: whirl-brake, tuned_on: robust}`` is written into the run as the law with
    the robust suite's tuned constants; the exported policy corrects that law (not the class
    gains) under plain SB3 and the project loader alike."""
    from agents.benchmarking.suites import SUITES
    from agents.benchmarking.tuned import load_records
    from agents.learning.hyperparams import split
    from agents.learning.policies import LearnedPolicy
    from agents.training.train import resolve_config
    hp = resolve_config("RotorDrop-Full-v1", "ppo",
                        str(ROOT / "docs/experiments/configs/ppo-ctrl-tuned-residual.yaml"))
    spec = split(hp)[0]["residual"]
    gains = load_records(SUITES.get("robust", "tune"))["whirl-brake"]["gains"]
    assert spec == {"law": "whirl-brake", "gains": gains}
    model, vn, env_id, env_kwargs = _trained_run(tmp_path, "ppo")
    out = export_self_contained(model, vn, tmp_path / "tuned.zip", env_id=env_id,
                                env_kwargs=env_kwargs, residual=spec, residual_scale=0.5)
    env = gym.make(env_id, **env_kwargs)
    plant = Plant.from_env(env)
    tuned, plain_law = make_baseline(spec, plant), make_baseline("whirl-brake", plant)
    obs = _episode_obs(env, algo_class("ppo").load(out, device="cpu"), seeds=(3,), steps=20)
    net, _ = model.predict(vn.normalize_obs(obs), deterministic=True)
    expected = residual_action(tuned, obs, net, 0.5)
    assert tuned.g == {**plain_law.g, **gains} and tuned.g != plain_law.g
    assert np.array_equal(algo_class("ppo").load(out, device="cpu").predict(obs, deterministic=True)[0],
                          expected)
    pol = LearnedPolicy.load(str(out)).bound(plant)
    assert pol.residual == spec and pol.base.g == tuned.g
    assert np.array_equal(pol.predict(obs)[0], expected)


@pytest.mark.parametrize("value, match", [
    ({"law": "whirl-brake", "tuned_on": "nowhere"}, "tuned_on = 'nowhere'"),
    ({"law": "max-damping", "tuned_on": "robust"}, "no tuned record of 'max-damping'"),
    ({"law": "no-such-law", "tuned_on": "robust"}, "no tuned record of 'no-such-law'"),
    ({"law": "whirl-brake", "gains": {"kq": 1.0}}, "unknown whirl-brake constants"),
    ({"law": "whirl-brake", "gains": {"kp": float("nan")}}, "finite"),
    ({"law": "whirl-brake"}, "law: NAME"),
    ("no-such-law", "unknown baseline controller"),
])
def test_bad_residual_specs_are_clear_config_errors(value, match, tmp_path):
    """Through ``rotordrop train``'s config resolution (which writes tuned constants in) and the
    baseline they make: one clear error naming what is wrong."""
    from agents.learning.config_checks import ConfigError
    from agents.learning.hyperparams import split
    from agents.training.train import resolve_config
    cfg = tmp_path / "c.yaml"
    cfg.write_text("base: ppo.yaml\nresidual: " + json.dumps(value) + "\n")
    env = gym.make("RotorDrop-Full-v1", command="continuous", episode_time=0.01)
    with pytest.raises((ConfigError, ValueError), match=match):
        make_baseline(split(resolve_config("RotorDrop-Full-v1", "ppo", str(cfg)))[0]["residual"],
                      Plant.from_env(env))
