"""Hyperparameter files, a short SB3 training run (saved, loadable, resumable) and evaluate on it."""
import json

import numpy as np
import pytest

from agents.hyperparams import ConfigError, load_hyperparams, parse_literal, schedule, split

from helpers import phys

ENV_IDS = ("RotorDrop-Damping-v0", "RotorDrop-Relevitate-v0", "RotorDrop-Full-v0")


@pytest.mark.parametrize("algo", ["ppo", "sac", "td3"])
def test_shipped_configs_parse(algo):
    from gymnasium.spaces import Box
    from agents.plant import make_env
    for env_id in ENV_IDS:
        meta, kwargs = split(load_hyperparams(algo, env_id))
        assert meta["n_timesteps"] > 0 and meta["n_envs"] >= 1
        assert isinstance(kwargs["policy_kwargs"], dict)
        env = make_env(env_id, **meta["env_kwargs"])          # the env the config trains on
        if algo != "ppo":       # SAC/TD3 need continuous actions
            assert isinstance(env.action_space, Box), (algo, env_id)


def test_config_override_and_literals(tmp_path):
    cfg = tmp_path / "my.yaml"
    cfg.write_text("RotorDrop-Damping-v0:\n  n_steps: 64\n  env_kwargs:\n    control_dt: 0.002\n")
    shipped = load_hyperparams("ppo", "RotorDrop-Damping-v0")
    hp = load_hyperparams("ppo", "RotorDrop-Damping-v0", cfg)
    assert hp["n_steps"] == 64
    assert hp["env_kwargs"] == {**shipped["env_kwargs"], "control_dt": 0.002}   # merged, not replaced
    assert parse_literal("dict(net_arch=[32, 32], log_std_init=-1.0)", "k") == \
        {"net_arch": [32, 32], "log_std_init": -1.0}
    lr = schedule("lin_1e-3", "learning_rate")
    assert lr(1.0) == pytest.approx(1e-3) and lr(0.0) == 0.0
    with pytest.raises(ConfigError, match="policy_kwargs"):
        parse_literal("__import__('os').system('true')", "policy_kwargs")
    with pytest.raises(ConfigError, match="no block for RotorDrop-Damping-v0"):
        (tmp_path / "other.yaml").write_text("RotorDrop-Full-v0:\n  n_steps: 64\n")
        load_hyperparams("ppo", "RotorDrop-Damping-v0", tmp_path / "other.yaml")
    with pytest.raises(ConfigError, match="algo"):
        load_hyperparams("a2c", "RotorDrop-Damping-v0")


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    """A 2048-step PPO run on the damping task with checkpoints every 1024 steps."""
    from agents.train import train
    out = tmp_path_factory.mktemp("ppo")
    cfg = out / "tiny.yaml"
    cfg.write_text("RotorDrop-Damping-v0:\n  n_steps: 256\n  batch_size: 128\n  n_epochs: 2\n"
                   "  eval_freq: 1024\n  n_eval_episodes: 2\n  checkpoint_freq: 1024\n"
                   "  env_kwargs:\n    episode_time: 0.05\n")
    res = train("RotorDrop-Damping-v0", "ppo", out / "run", timesteps=2048, n_envs=4, config=cfg,
                seed=3, progress=False)
    return res, cfg


def test_training_saves_a_loadable_model(trained):
    from agents.plant import Plant, make_env
    from agents.policies import LearnedPolicy
    res, _ = trained
    run = res.out
    for f in ("model.zip", "vecnormalize.pkl", "config.yaml", "training.json",
              "best/best_model.zip", "best/vecnormalize.pkl", "learning_curve.png"):
        assert (run / f).is_file(), f
    info = json.loads((run / "training.json").read_text())
    assert info["timesteps"] >= 2048 and info["seed"] == 3
    assert info["hyperparams"]["n_steps"] == 256          # the exact config used is recorded
    assert len(info["learning_curve"]) == 2               # evaluations at 1024 and 2048 steps
    assert all(0.0 <= h["mean_failure"] <= 1.0 for h in info["learning_curve"])

    pol = LearnedPolicy.load(run)
    assert pol.env_id == "RotorDrop-Damping-v0" and pol.name == "ppo-damping"
    env = make_env(pol.env_id, episode_time=0.02)
    pol.bound(Plant.from_env(env))          # the shipped config trains a residual on max-damping
    assert pol.residual == "max-damping"
    obs, _ = env.reset(seed=0)
    a, _ = pol.predict(obs)
    assert env.action_space.contains(np.asarray(a, np.float32))
    batch, _ = pol.predict(np.stack([obs] * 3))
    assert batch.shape == (3, 2) and np.all(np.abs(batch) <= 1.0)
    assert Plant.from_env(env).channels == ("damping",)


def test_training_resumes_from_a_checkpoint(trained, tmp_path):
    from agents.train import find_checkpoint, train
    res, cfg = trained
    ckpt, vn, _ = find_checkpoint(res.out)
    assert ckpt.name == "rl_model_2048_steps.zip" and vn is not None
    first, _, _ = find_checkpoint(res.out / "checkpoints" / "rl_model_1024_steps.zip")
    resumed = train("RotorDrop-Damping-v0", "ppo", tmp_path / "resumed", timesteps=3072, n_envs=4,
                    config=cfg, seed=3, resume=first, progress=False)
    # continued from 1024 steps: one more rollout of 4 x 256 steps would end at 2048, so two more
    assert resumed.timesteps == 3072
    info = json.loads((tmp_path / "resumed" / "training.json").read_text())
    assert info["resumed_from"].endswith("rl_model_1024_steps.zip")


def test_evaluate_a_trained_policy_against_passive(trained, tmp_path):
    from physics.cli import main
    res, _ = trained
    out = tmp_path / "eval"
    assert main(["evaluate", "--policy", str(res.out), "--episodes", "2", "--set",
                 "contact.friction=0.1", "--out", str(out)]) == 0
    report = json.loads((out / "kpis.json").read_text())
    assert report["policy"] == "ppo-damping" and report["env_id"] == "RotorDrop-Damping-v0"
    eps = report["episodes"]
    assert [e["seed"] for e in eps] == [0, 1]
    # the summary is the episodes' statistics
    assert report["summary"]["peak_contact_force_N"] == pytest.approx(
        np.mean([e["peak_contact_force_N"] for e in eps]))
    assert report["summary"]["backward_whirl_rate"] == np.mean([e["backward_whirl"] for e in eps])
    assert len(report["passive_episodes"]) == 2
    for f in ("orbits.png", "contact_force.png", "actions.png"):
        assert (out / f).is_file()


#: non-default KPI-reward weights, so the tests also see them reach the wrapper
W = dict(w_whirl=2.0, w_force=0.25, w_disp=0.75, force_ref=5e3, disp_ref_um=600.0)


def _final_potential(info: dict) -> float:
    from agents.reward import PEAK_KEYS, kpi_potential
    return kpi_potential(*(info[k] for k in PEAK_KEYS), **W)


def test_kpi_reward_returns_minus_the_episode_cost():
    """The KPI reward telescopes: an episode's return is minus the potential of its final KPIs
    (peak backward revolutions capped at 3, peak force, max displacement; weights as given)."""
    from agents.plant import make_vec_env
    venv = make_vec_env("RotorDrop-Damping-v0", 2, 0, dict(
        episode_time=0.06, terminate_on_failure=False, overrides={"contact.friction": 0.6}),
        reward="kpi", reward_kwargs=W)
    venv.reset()
    rng = np.random.default_rng(1)
    ret, done_info = np.zeros(2), [None, None]
    while any(d is None for d in done_info):
        _, r, dones, infos = venv.step(rng.uniform(-1, 1, (2, 2)).astype(np.float32))
        for i in range(2):
            if done_info[i] is None:
                ret[i] += r[i]
                if dones[i]:
                    done_info[i] = infos[i]
    for i in range(2):
        k = done_info[i]
        assert k["kpi_peak_contact_force_N"] > 0.0          # the rotor has landed
        assert ret[i] == pytest.approx(-_final_potential(k), rel=1e-4, abs=1e-4)


def test_residual_zero_action_is_the_base_controller():
    """With residual: max-damping, an agent action of 0 commands C_max: the damper state follows
    its 10 ms first-order lag to C_max (spec §6); an action of -1 commands C_min."""
    from agents.plant import make_vec_env
    from physics.scene import load_scene
    s = load_scene("paper").support
    for a, target in ((0.0, s.damping_max), (-1.0, s.damping_min)):
        venv = make_vec_env("RotorDrop-Damping-v0", 2, 0, dict(episode_time=0.1), residual="max-damping")
        venv.reset()
        for _ in range(60):
            obs, *_ = venv.step(np.full((2, 2), a, dtype=np.float32))
        env = venv.unwrapped.envs[0]
        c = [phys(env, o, "damping1") for o in obs]
        np.testing.assert_allclose(c, target, rtol=0.01)


def test_kpi_reward_charges_the_time_before_relevitation():
    """Re-levitation tasks: the return is minus the final KPI potential, plus w_relevitate once,
    minus w_time * dt / T for every step before re-levitation (the score's T_R / T term)."""
    from agents.plant import make_vec_env
    kw = dict(episode_time=0.15, terminate_on_failure=False, command="discrete",
              power_return_time=0.02, overrides={"contact.friction": 0.1})
    venv = make_vec_env("RotorDrop-Relevitate-v0", 1, 0, kw, reward="kpi",
                        reward_kwargs=dict(W, w_relevitate=0.7, w_time=1.5))
    venv.reset()
    ret, pre, done = 0.0, 0, False
    while not done:
        _, r, dones, infos = venv.step(np.ones(1, dtype=np.int64))
        ret += float(r[0])
        done = bool(dones[0])
        pre += int(not infos[0]["relevitated"] and infos[0].get("reward_success", 0.0) == 0.0)
    k = infos[0]
    assert k["kpi_relevitated"]
    dt = venv.get_attr("dt")[0]
    assert pre * dt >= k["kpi_relevitation_time_s"]            # charged until it is confirmed
    expected = -_final_potential(k) + 0.7 - 1.5 * pre * dt / kw["episode_time"]
    assert ret == pytest.approx(expected, rel=1e-4, abs=1e-4)


def test_validation_keeps_the_best_model_by_validation_score(tmp_path):
    """validation: true scores each evaluation on the validation suite, records the score in the
    learning curve and keeps the best-scoring model in best/; residual_scale is saved and a
    residual policy at a ~zero action scores what its base scores."""
    from agents.benchmark import Validator
    from agents.controllers import WhirlBrake
    from agents.policies import LearnedPolicy
    from agents.train import train
    cfg = tmp_path / "val.yaml"
    cfg.write_text("RotorDrop-Full-v0:\n  n_steps: 128\n  batch_size: 128\n  n_epochs: 1\n"
                   "  eval_freq: 512\n  n_eval_episodes: 1\n  checkpoint_freq: 0\n"
                   "  policy_kwargs: \"dict(net_arch=[16], log_std_init=-3.0)\"\n"
                   "  residual: whirl-brake\n  residual_scale: 0.01\n  validation: true\n"
                   "  reward: kpi\n  env_kwargs: {command: continuous, terminate_on_failure: false}\n")
    res = train("RotorDrop-Full-v0", "ppo", tmp_path / "run", timesteps=1024, n_envs=4, config=cfg,
                progress=False)
    curve = json.loads((res.out / "training.json").read_text())["learning_curve"]
    scores = [e["validation_score"] for e in curve]
    assert len(scores) == 2 and (res.out / "best" / "best_model.zip").is_file()
    pol = LearnedPolicy.load(res.out / "best" / "best_model.zip")
    assert pol.residual == "whirl-brake" and pol.residual_scale == pytest.approx(0.01)
    v = Validator("RotorDrop-Full-v0")
    base, _ = v.score(WhirlBrake, {"command": "continuous"})
    assert max(scores) == pytest.approx(base, abs=1.0)       # a 1 % residual barely moves it
    kept, _ = v.score(pol.bound, {"command": "continuous"})
    assert kept == max(scores)                                # best/ is the best-scoring model
    with pytest.raises(ConfigError, match="residual_scale"):
        split({"residual_scale": 3.0})
