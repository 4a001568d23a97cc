"""Initial exploration spread per action entry (agents/learning/exploration.py): the named entries of
PPO's log std start where the config says, the others at log_std_init; a resumed model keeps
what it learned; both config forms mean the same; bad values are named."""
import numpy as np
import pytest
from stable_baselines3 import PPO
from stable_baselines3.common.env_util import make_vec_env

import rotordrop_env  # noqa: F401  (registers the environments)
from agents.learning.exploration import ActionSpread
from agents.learning.hyperparams import ConfigError, load_hyperparams, project_keys, split
from agents.training.train import train

SPREAD = {"damping2": -0.5}
TINY = ("RotorDrop-Damping-v1:\n  n_steps: 64\n  batch_size: 64\n  n_epochs: 1\n  n_envs: 2\n"
        "  n_eval_episodes: 1\n  validation: false\n"
        "  policy_kwargs: \"dict(net_arch=[8], log_std_init=-2.0)\"\n"
        "  env_kwargs:\n    episode_time: 0.02\n")


def _model(log_std_init=-2.0):
    """A fresh PPO on SB3's DummyVecEnv of gym.make envs, as rl-zoo3 builds it."""
    venv = make_vec_env("RotorDrop-Damping-v1", 1, seed=0, env_kwargs=dict(episode_time=0.02))
    return PPO("MlpPolicy", venv, n_steps=64, batch_size=64, seed=0, device="cpu",
               policy_kwargs=dict(net_arch=[8], log_std_init=log_std_init))


def _log_std(model):
    return model.policy.log_std.detach().numpy().copy()


def test_the_named_entries_start_at_their_spread_and_the_others_at_log_std_init():
    model = _model()
    model.learn(64, callback=ActionSpread(SPREAD))           # damping1, damping2
    after_one_update = _log_std(model)
    # one PPO update moves each log std by at most a few learning rates from where it started
    assert np.allclose(after_one_update, [-2.0, -0.5], atol=0.01)
    assert abs(after_one_update[1] - after_one_update[0]) > 1.4


def test_a_resumed_model_keeps_the_spread_it_learned():
    model = _model()
    model.learn(64)
    model.policy.log_std.data[:] = 0.3                      # what "training" left
    model.learn(64, callback=ActionSpread(SPREAD), reset_num_timesteps=False)
    assert np.allclose(_log_std(model), 0.3, atol=0.01)


def test_the_rl_zoo3_entry_and_the_key_mean_the_same(tmp_path):
    cfg = tmp_path / "c.yaml"
    cfg.write_text("callback:\n  - agents.learning.exploration.ActionSpread: {log_std: {damping2: -0.5}}\n")
    meta, _ = split(load_hyperparams("ppo", "RotorDrop-Damping-v1", cfg))
    cfg.write_text("action_log_std: {damping2: -0.5}\n")
    meta2, _ = split(load_hyperparams("ppo", "RotorDrop-Damping-v1", cfg))
    assert meta["action_log_std"] == meta2["action_log_std"] == SPREAD
    # the shipped block's validation callback is replaced by the user's callback list, as for
    # every callback entry
    assert meta["validation"] is False and meta2["validation"] is True
    with pytest.raises(ConfigError, match="action_log_std is given twice"):
        project_keys({"action_log_std": {"damping2": -1.0},
                      "callback": [{"agents.learning.exploration.ActionSpread": {"log_std": SPREAD}}]})


def test_rotordrop_train_starts_from_the_configured_spread(tmp_path):
    cfg = tmp_path / "t.yaml"
    cfg.write_text(TINY + "  action_log_std: {damping1: 0.0}\n  learning_rate: 1.0e-12\n")
    res = train("RotorDrop-Damping-v1", "ppo", tmp_path / "run", timesteps=128, config=cfg,
                progress=False)
    assert np.allclose(_log_std(PPO.load(res.model_path)), [0.0, -2.0], atol=1e-6)


@pytest.mark.parametrize("extra, algo, match", [
    ("  action_log_std: {damping1: 3.0}\n", "ppo",
     r"action_log_std.damping1 = 3.0 must be a number in \[-5, 1\]"),
    ("  action_log_std: [0.5]\n", "ppo", r"action_log_std must be a non-empty mapping"),
    ("  action_log_std: {gain: -1.0}\n", "ppo",
     r"action_log_std: 'gain' is not an action entry of this environment; its entries: "
     r"damping1, damping2"),
    ("  action_log_std: {damping1: -1.0}\n", "sac",
     r"action_log_std sets the per-entry log std .* needs --algo ppo without use_sde \(got --algo sac\)"),
    ("  action_log_std: {damping1: -1.0}\n  use_sde: true\n", "ppo",
     r"needs --algo ppo without use_sde \(got --algo ppo, use_sde: true\)"),
])
def test_bad_spreads_are_named_before_anything_is_written(tmp_path, extra, algo, match):
    cfg = tmp_path / "t.yaml"
    ppo_only = "  n_steps: 64\n  batch_size: 64\n  n_epochs: 1\n"
    cfg.write_text((TINY.replace(ppo_only, "") if algo == "sac" else TINY) + extra)
    with pytest.raises(ConfigError, match=match):
        train("RotorDrop-Damping-v1", algo, tmp_path / "run", timesteps=128, config=cfg,
              progress=False)
    assert not (tmp_path / "run").exists()


def test_a_policy_without_a_per_entry_log_std_is_refused():
    """What rl-zoo3 would run: a gSDE PPO, whose log std is per latent feature and entry."""
    venv = make_vec_env("RotorDrop-Damping-v1", 1, seed=0, env_kwargs=dict(episode_time=0.02))
    model = PPO("MlpPolicy", venv, n_steps=64, batch_size=64, seed=0, device="cpu", use_sde=True,
                policy_kwargs=dict(net_arch=[8]))
    with pytest.raises(ConfigError, match="needs a policy with one state-independent log std"):
        model.learn(64, callback=ActionSpread(SPREAD))


@pytest.mark.parametrize("algo", ["sac", "ppo"])
def test_zero_start_makes_the_untrained_residual_policy_its_baseline(tmp_path, algo):
    """zero_start: the deterministic action of an untrained model is exactly 0 for any
    observation, so a residual policy on max-damping commands C_max (damper action 1) at every
    step; SAC's default initialisation does not (its mean head starts a few tenths away)."""
    from agents.learning.policies import LearnedPolicy
    from agents.control.plant import Plant, make_env
    ppo_only = "  n_steps: 64\n  batch_size: 64\n  n_epochs: 1\n"
    body = (TINY.replace(ppo_only, "  learning_starts: 1000\n") if algo == "sac" else TINY)
    env = make_env("RotorDrop-Damping-v1", episode_time=0.02)
    obs = np.stack([env.observation_space.sample() for _ in range(6)])
    acts = {}
    for zero in (True, False):
        cfg = tmp_path / f"{zero}.yaml"
        cfg.write_text(body + "  residual: max-damping\n  residual_scale: 1.0\n  learning_rate: 1.0e-12\n"
                       + f"  zero_start: {str(zero).lower()}\n")
        res = train("RotorDrop-Damping-v1", algo, tmp_path / f"run{zero}", timesteps=64,
                    config=cfg, progress=False, eval_freq=0)
        pol = LearnedPolicy.load(res.model_path)
        acts[zero] = pol.bound(Plant.from_env(env)).predict(obs)[0]
    np.testing.assert_array_equal(acts[True], 1.0)
    if algo == "sac":
        assert np.abs(acts[False] - 1.0).max() > 0.01


def test_zero_start_must_be_a_flag(tmp_path):
    cfg = tmp_path / "t.yaml"
    cfg.write_text(TINY + "  zero_start: yes please\n")
    with pytest.raises(ConfigError, match="zero_start must be true or false"):
        train("RotorDrop-Damping-v1", "ppo", tmp_path / "run", timesteps=64, config=cfg,
              progress=False)
