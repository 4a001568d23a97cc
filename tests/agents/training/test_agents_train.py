"""Hyperparameter files, a short SB3 training run (saved, loadable, resumable) and evaluate on it."""
import json
from pathlib import Path

import numpy as np
import pytest

from agents.learning.hyperparams import (ALGOS, ConfigError, load_hyperparams, parse_literal, read_yaml, schedule,
                                split)

from helpers import phys

ENV_IDS = ("RotorDrop-Damping-v1", "RotorDrop-Relevitate-v1", "RotorDrop-Full-v1")


@pytest.mark.parametrize("algo", ALGOS)
def test_shipped_configs_parse(algo):
    from gymnasium.spaces import Box
    from agents.control.plant import make_env
    for env_id in ENV_IDS:
        meta, kwargs = split(load_hyperparams(algo, env_id))
        assert meta["n_timesteps"] > 0 and meta["n_envs"] >= 1
        assert isinstance(kwargs["policy_kwargs"], dict)
        env = make_env(env_id, **meta["env_kwargs"])          # the env the config trains on
        if algo != "ppo":       # SAC/TD3/TQC/CrossQ need continuous actions
            assert isinstance(env.action_space, Box), (algo, env_id)


ROOT = Path(__file__).resolve().parents[3]
#: the experiment variants: deltas on a shipped entry or on each other (docs/experiments/configs)
DELTAS = sorted((ROOT / "docs/experiments/configs").glob("*.yaml"))
#: the named entries of the shipped files (one per shipped policy that shares an env id)
ENTRIES = [(algo, key) for algo in ALGOS
           for key in read_yaml(ROOT / f"agents/configs/{algo}.yaml") if not key.startswith("RotorDrop-")]


def _check(algo, env_id, config):
    from agents.learning.hyperparams import check_sb3
    from agents.training.train import check_env, resolve_config
    meta, kwargs = split(resolve_config(env_id, algo, config))
    check_sb3(algo, env_id, meta, kwargs)
    check_env(env_id, algo, meta)


def test_the_package_ships_one_file_per_algorithm():
    assert sorted(p.name for p in (ROOT / "agents/configs").iterdir()) == \
        sorted(f"{algo}.yaml" for algo in ALGOS)
    assert len(DELTAS) >= 20 and ENTRIES


@pytest.mark.parametrize("algo,entry", ENTRIES, ids=lambda x: x)
def test_every_shipped_entry_passes_the_checks_rotordrop_train_makes(algo, entry):
    """A named entry trains the env id of the shipped policy of its name."""
    env_id = json.loads((ROOT / f"agents/policies/{entry}.json").read_text())["env_id"]
    _check(algo, env_id, f"agents/configs/{algo}.yaml:{entry}")


@pytest.mark.parametrize("cfg", DELTAS, ids=lambda p: p.stem)
def test_every_experiment_delta_passes_the_checks_rotordrop_train_makes(cfg):
    """The experiment variants (docs/experiments/configs/<algo>-<name>.yaml: a base and the keys
    that differ) resolve and pass the checks a run makes before it writes anything."""
    data = read_yaml(cfg)
    assert "base" in data and len(data) <= 13, "a delta names its base and only what differs"
    algo = cfg.stem.split("-")[0]
    named, base = "", cfg
    while base.is_file() and not named.startswith("RotorDrop-"):    # a delta of a delta: its base's
        ref = str(read_yaml(base).get("base", ""))
        named, base = ref.rpartition(":")[2], base.parent / ref   # a base entry named after its env id
    env_id = (named if named.startswith("RotorDrop-") else
              "RotorDrop-Relevitate-v1" if "currents" in cfg.stem else "RotorDrop-Full-v1")
    _check(algo, env_id, cfg)


def test_a_delta_is_its_base_with_its_keys_on_top(tmp_path):
    base = load_hyperparams("ppo", "RotorDrop-Full-v1", "agents/configs/ppo.yaml:ppo-full-scratch")
    (tmp_path / "a.yaml").write_text("base: ppo.yaml:ppo-full-scratch\nn_steps: 64\n"
                                     "env_kwargs: {damping_action: linear}\n")
    (tmp_path / "b.yaml").write_text("base: a.yaml\nlearning_rate: 1e-4\n")    # a sibling delta
    hp = load_hyperparams("ppo", "RotorDrop-Full-v1", tmp_path / "b.yaml")
    assert hp["n_steps"] == 64 and hp["learning_rate"] == 1e-4
    assert hp["env_kwargs"] == {**base["env_kwargs"], "damping_action": "linear"}
    assert {k: v for k, v in hp.items() if k not in ("n_steps", "learning_rate", "env_kwargs")} == \
        {k: v for k, v in base.items() if k not in ("n_steps", "learning_rate", "env_kwargs")}
    assert hp["residual"] is None                   # the entry's, not the Full-v1 default's residual
    (tmp_path / "c.yaml").write_text("base: d.yaml\n")
    (tmp_path / "d.yaml").write_text("base: c.yaml\n")
    with pytest.raises(ConfigError, match="comes back to itself") as err:
        load_hyperparams("ppo", "RotorDrop-Full-v1", tmp_path / "c.yaml")
    assert "\n" not in str(err.value)
    with pytest.raises(ConfigError, match="pass --env RotorDrop-Full-v1"):
        load_hyperparams("ppo", "RotorDrop-Damping-v1", "agents/configs/ppo.yaml:ppo-full-scratch")
    with pytest.raises(ConfigError, match="--algo sac"):
        load_hyperparams("ppo", "RotorDrop-Full-v1", "agents/configs/sac.yaml:sac-full-scratch")
    with pytest.raises(ConfigError, match="no block for nope"):
        load_hyperparams("ppo", "RotorDrop-Full-v1", "ppo.yaml:nope")
    (tmp_path / "e.yaml").write_text("base: missing.yaml\n")
    with pytest.raises(ConfigError, match="missing.yaml does not exist"):
        load_hyperparams("ppo", "RotorDrop-Full-v1", tmp_path / "e.yaml")
    (tmp_path / "f.yaml").write_text("base: [ppo.yaml]\n")
    with pytest.raises(ConfigError, match="base must name a file"):
        load_hyperparams("ppo", "RotorDrop-Full-v1", tmp_path / "f.yaml")


def test_config_override_and_literals(tmp_path):
    cfg = tmp_path / "my.yaml"
    cfg.write_text("RotorDrop-Damping-v1:\n  n_steps: 64\n  env_kwargs:\n    control_dt: 0.002\n")
    shipped = load_hyperparams("ppo", "RotorDrop-Damping-v1")
    hp = load_hyperparams("ppo", "RotorDrop-Damping-v1", cfg)
    assert hp["n_steps"] == 64
    assert hp["env_kwargs"] == {**shipped["env_kwargs"], "control_dt": 0.002}   # merged, not replaced
    assert parse_literal("dict(net_arch=[32, 32], log_std_init=-1.0)", "k") == \
        {"net_arch": [32, 32], "log_std_init": -1.0}
    lr = schedule("lin_1e-3", "learning_rate")
    assert lr(1.0) == pytest.approx(1e-3) and lr(0.0) == 0.0
    with pytest.raises(ConfigError, match="policy_kwargs"):
        parse_literal("__import__('os').system('true')", "policy_kwargs")
    with pytest.raises(ConfigError, match="no block for RotorDrop-Damping-v1"):
        (tmp_path / "other.yaml").write_text("RotorDrop-Full-v1:\n  n_steps: 64\n")
        load_hyperparams("ppo", "RotorDrop-Damping-v1", tmp_path / "other.yaml")
    with pytest.raises(ConfigError, match="algo"):
        load_hyperparams("a2c", "RotorDrop-Damping-v1")


def test_scientific_notation_in_a_config_is_a_number(tmp_path):
    """YAML 1.1 (PyYAML's default) reads 1e-3 as a string; configs read it as a float."""
    cfg = tmp_path / "sci.yaml"
    cfg.write_text("RotorDrop-Damping-v1:\n  learning_rate: 3e-4\n  n_timesteps: 2E5\n"
                   "  ent_coef: -1.5e-2\n  policy: MlpPolicy\n  n_steps: 64\n"
                   "  env_kwargs:\n    control_dt: 2e-3\n")
    hp = load_hyperparams("ppo", "RotorDrop-Damping-v1", cfg)
    assert hp["learning_rate"] == 3e-4 and hp["n_timesteps"] == 2e5 and hp["ent_coef"] == -0.015
    assert hp["env_kwargs"]["control_dt"] == 2e-3 and hp["n_steps"] == 64
    assert hp["policy"] == "MlpPolicy"
    import yaml
    assert yaml.safe_load("a: 1e-3")["a"] == "1e-3"        # the global loader is left untouched


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    """A 2048-step PPO run on the damping task with checkpoints every 1024 steps."""
    from agents.training.train import train
    out = tmp_path_factory.mktemp("ppo")
    cfg = out / "tiny.yaml"
    cfg.write_text("RotorDrop-Damping-v1:\n  n_steps: 256\n  batch_size: 128\n  n_epochs: 2\n"
                   "  eval_freq: 1024\n  n_eval_episodes: 2\n  checkpoint_freq: 1024\n"
                   "  env_kwargs:\n    episode_time: 0.05\n")
    res = train("RotorDrop-Damping-v1", "ppo", out / "run", timesteps=2048, n_envs=4, config=cfg,
                seed=3, progress=False)
    return res, cfg


def test_training_saves_a_loadable_model(trained):
    from agents.control.plant import Plant, make_env
    from agents.learning.policies import LearnedPolicy
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
    assert pol.env_id == "RotorDrop-Damping-v1" and pol.name == "ppo-damping"
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
    from agents.training.train import find_checkpoint, train
    res, cfg = trained
    ckpt, vn, _ = find_checkpoint(res.out)
    assert ckpt.name == "rl_model_2048_steps.zip" and vn is not None
    first, _, _ = find_checkpoint(res.out / "checkpoints" / "rl_model_1024_steps.zip")
    resumed = train("RotorDrop-Damping-v1", "ppo", tmp_path / "resumed", timesteps=3072, n_envs=4,
                    config=cfg, seed=3, resume=first, progress=False)
    # continued from 1024 steps: one more rollout of 4 x 256 steps would end at 2048, so two more
    assert resumed.timesteps == 3072
    info = json.loads((tmp_path / "resumed" / "training.json").read_text())
    assert info["resumed_from"].endswith("rl_model_1024_steps.zip")


def test_evaluate_a_trained_policy_against_passive(trained, tmp_path):
    from agents.cli import main
    res, _ = trained
    out = tmp_path / "eval"
    assert main(["evaluate", "--policy", str(res.out), "--episodes", "2", "--set",
                 "contact.friction=0.1", "--out", str(out)]) == 0
    report = json.loads((out / "kpis.json").read_text())
    assert report["policy"] == "ppo-damping@run" and report["env_id"] == "RotorDrop-Damping-v1"
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
W = dict(w_whirl=2.0, w_verdict=0.5, w_severity=0.3, w_force=0.25, w_disp=0.75, force_ref=5e3,
         disp_ref_um=600.0, whirl_ref_revs=10.0)


def test_kpi_potential_charges_the_whirl_verdict_at_three_revolutions():
    """w_verdict is a step at the benchmark's whirl verdict (3 net backward revolutions), on top
    of the capped ramp; with w_whirl 0.25 and w_verdict 0.75 a whirl costs 1, as in J."""
    from agents.learning.reward import kpi_potential
    w = dict(w_whirl=0.25, w_verdict=0.75, w_force=0.0, w_disp=0.0, force_ref=1.0, disp_ref_um=1.0)
    phi = kpi_potential(np.array([0.0, 1.5, 2.999, 3.0, 7.0]), 0.0, 0.0, **w)
    np.testing.assert_allclose(phi, [0.0, 0.125, 0.25 * 2.999 / 3, 1.0, 1.0])
    base = {k: v for k, v in w.items() if k != "w_verdict"}
    assert kpi_potential(3.0, 0.0, 0.0, **base) == pytest.approx(0.25)     # default: no step


def _final_potential(info: dict) -> float:
    from agents.learning.reward import PEAK_KEYS, kpi_potential
    return kpi_potential(*(info[k] for k in PEAK_KEYS), **W)


def test_kpi_reward_returns_minus_the_episode_cost():
    """The KPI reward telescopes: an episode's return is minus the potential of its final KPIs
    (peak backward revolutions capped at 3, peak force, max displacement; weights as given)."""
    from agents.training.training_env import make_vec_env
    venv = make_vec_env("RotorDrop-Damping-v1", 2, 0, dict(
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
    from agents.training.training_env import make_vec_env
    from physics.scene import load_scene
    s = load_scene("paper").support
    for a, target in ((0.0, s.damping_max), (-1.0, s.damping_min)):
        venv = make_vec_env("RotorDrop-Damping-v1", 2, 0, dict(episode_time=0.1), residual="max-damping")
        venv.reset()
        for _ in range(60):
            obs, *_ = venv.step(np.full((2, 2), a, dtype=np.float32))
        env = venv.unwrapped.envs[0]
        c = [phys(env, o, "damping1") for o in obs]
        np.testing.assert_allclose(c, target, rtol=0.01)


def test_kpi_reward_charges_the_time_before_relevitation():
    """Re-levitation tasks: the return is minus the final KPI potential, plus w_relevitate once,
    minus w_time * dt / T for every step before re-levitation (the score's T_R / T term)."""
    from agents.training.training_env import make_vec_env
    kw = dict(episode_time=0.15, terminate_on_failure=False, command="discrete",
              power_return_time=0.02, overrides={"contact.friction": 0.1})
    venv = make_vec_env("RotorDrop-Relevitate-v1", 1, 0, kw, reward="kpi",
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
    from agents.benchmarking.benchmark import Validator
    from agents.control.controllers import WhirlBrake
    from agents.learning.policies import LearnedPolicy
    from agents.training.train import train
    cfg = tmp_path / "val.yaml"
    cfg.write_text("RotorDrop-Full-v1:\n  n_steps: 128\n  batch_size: 128\n  n_epochs: 1\n"
                   "  eval_freq: 512\n  n_eval_episodes: 1\n  checkpoint_freq: 0\n"
                   "  policy_kwargs: \"dict(net_arch=[16], log_std_init=-3.0)\"\n"
                   "  residual: whirl-brake\n  residual_scale: 0.01\n  validation: true\n"
                   "  reward: kpi\n  env_kwargs: {command: continuous, terminate_on_failure: false}\n")
    res = train("RotorDrop-Full-v1", "ppo", tmp_path / "run", timesteps=1024, n_envs=4, config=cfg,
                progress=False)
    curve = json.loads((res.out / "training.json").read_text())["learning_curve"]
    scores = [e["validation_score"] for e in curve]
    assert len(scores) == 2 and (res.out / "best" / "best_model.zip").is_file()
    pol = LearnedPolicy.load(res.out / "best" / "best_model.zip")
    assert pol.residual == "whirl-brake" and pol.residual_scale == pytest.approx(0.01)
    v = Validator("RotorDrop-Full-v1")
    base, _ = v.score(WhirlBrake, {"command": "continuous"})
    assert max(scores) == pytest.approx(base, abs=1.0)       # a 1 % residual barely moves it
    kept, _ = v.score(pol.bound, {"command": "continuous"})
    history = json.loads((res.out / "best" / "validation.json").read_text())["history"]
    assert history[0]["timesteps"] == 0                      # the initial policy is a candidate
    assert [h["score"] for h in history[1:]] == scores
    assert kept == max(h["score"] for h in history)           # best/ is the best-scoring model
    with pytest.raises(ConfigError, match="residual_scale"):
        split({"residual_scale": 3.0})


# --- run directories, resuming, config errors, short runs (UAT defects) ---------------------------

#: a tiny PPO damping config: 2 envs x 64 steps per rollout, one short evaluation episode
TINY = ("RotorDrop-Damping-v1:\n  n_steps: 64\n  batch_size: 64\n  n_epochs: 1\n  n_envs: 2\n"
        "  n_eval_episodes: 1\n  validation: false\n  policy_kwargs: \"dict(net_arch=[8])\"\n"
        "  env_kwargs:\n    episode_time: 0.02\n")


def _tiny(tmp_path, extra: str = "", name: str = "tiny.yaml"):
    cfg = tmp_path / name
    cfg.write_text(TINY + extra)
    return cfg


def _train(cfg, out, timesteps, **kw):
    from agents.training.train import train
    return train("RotorDrop-Damping-v1", kw.pop("algo", "ppo"), out, timesteps=timesteps,
                 config=cfg, progress=False, **kw)


@pytest.mark.parametrize("extra, match", [
    ("  learning_rat: 1.0e-3\n", r"ppo config: unknown key 'learning_rat' \(did you mean learning_rate\?\)"),
    ("  env_kwargs: {foo: 1}\n", r"env_kwargs \(RotorDrop-Damping-v1 arguments\): unknown key 'foo'; "
                                 r"allowed: scene, overrides"),
    ("  normalize: \"dict(foo=3)\"\n", r"normalize \(VecNormalize arguments\): unknown key 'foo'"),
    ("  batch_size: -4\n", r"batch_size must be >= 1, got -4"),
    ("  n_steps: 64.5\n", r"n_steps must be an integer, got 64.5"),
    ("  gamma: 1.5\n", r"gamma must be a number in \[0, 1\], got 1.5"),
    ("  seed: 3\n", r"seed is set by rotordrop train \(--seed\)"),
    ("  env_kwargs: {control_dt: -1.0}\n", r"env_kwargs: control_dt"),
    ("  reward: kpi\n  reward_kwargs: {w_wirl: 2.0}\n", r"reward_kwargs: unknown key 'w_wirl' \(did you mean w_whirl\?\)"),
    ("  reward: kpi\n  reward_kwargs: {force_ref: 0.0}\n", r"reward_kwargs.force_ref must be a finite number > 0"),
    ("  reward: env\n  reward_kwargs: {w_whirl: 2.0}\n", r"reward_kwargs are the weights of reward: kpi"),
])
def test_config_errors_name_the_key_before_anything_is_written(tmp_path, extra, match):
    with pytest.raises(ConfigError, match=match):
        _train(_tiny(tmp_path, extra), tmp_path / "run", 128)
    assert not (tmp_path / "run").exists()


def test_config_errors_of_the_action_space_and_the_algorithm(tmp_path):
    from agents.training.train import train
    cfg = tmp_path / "relev.yaml"
    cfg.write_text("RotorDrop-Relevitate-v1:\n  env_kwargs: {command: discrete}\n")
    # the shipped Relevitate config trains a residual on whirl-brake, which needs the currents
    with pytest.raises(ConfigError, match=r"residual: whirl-brake needs continuous actions: "
                                          r"RotorDrop-Relevitate-v1 has the action space Discrete\(2\)"
                                          r".*env_kwargs.command: continuous"):
        train("RotorDrop-Relevitate-v1", "ppo", tmp_path / "run", timesteps=128, config=cfg,
              progress=False)
    with pytest.raises(ConfigError, match=r"--algo sac needs continuous actions"):
        train("RotorDrop-Relevitate-v1", "sac", tmp_path / "run", timesteps=128, config=cfg,
              progress=False)
    with pytest.raises(ConfigError, match=r"ppo hyperparameters: .*batch_size"):   # SB3's own check
        _train(_tiny(tmp_path, "  batch_size: 1\n"), tmp_path / "run", 128)
    assert not (tmp_path / "run").exists()


def test_config_errors_reach_the_cli_as_one_line(tmp_path, capsys):
    from agents.cli import main
    cfg = _tiny(tmp_path, "  learning_rat: 1.0e-3\n")
    assert main(["train", "--env", "RotorDrop-Damping-v1", "--algo", "ppo", "--config", str(cfg),
                 "--out", str(tmp_path / "run"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("rotordrop train: error: ppo config: unknown key")


def test_resume_checks_the_algorithm_and_the_env_of_the_run(trained, tmp_path):
    import shutil
    from agents.training.train import train
    res, cfg = trained
    with pytest.raises(ConfigError, match=r"--algo sac does not match the run resumed from .*"
                                          r"rl_model_2048_steps.zip, trained with --algo ppo"):
        train("RotorDrop-Damping-v1", "sac", tmp_path / "a", resume=res.out, progress=False)
    with pytest.raises(ConfigError, match=r"--env RotorDrop-Full-v1 does not match .* trained with "
                                          r"--env RotorDrop-Damping-v1"):
        train("RotorDrop-Full-v1", "ppo", tmp_path / "b", resume=res.out, progress=False)
    # a bare checkpoint (no config.yaml): the algorithm from the zip, the env from its spaces
    bare = tmp_path / "bare"
    bare.mkdir()
    for f in ("rl_model_2048_steps.zip", "rl_model_vecnormalize_2048_steps.pkl"):
        shutil.copy(res.out / "checkpoints" / f, bare / f)
    with pytest.raises(ConfigError, match=r"--algo sac does not match .* trained with --algo ppo"):
        train("RotorDrop-Damping-v1", "sac", tmp_path / "c", resume=bare, progress=False)
    with pytest.raises(ConfigError, match=r"--resume .* does not fit --algo ppo --env RotorDrop-Full-v1"):
        train("RotorDrop-Full-v1", "ppo", tmp_path / "d", resume=bare, progress=False)
    assert not any((tmp_path / d).exists() for d in "abcd")


def test_an_out_holding_another_run_is_refused_or_overwritten(trained, tmp_path):
    res, cfg = trained
    before = sorted(p.relative_to(res.out) for p in res.out.rglob("*"))
    with pytest.raises(ConfigError, match=r"--out .* already holds a training run \(model.zip.*"
                                          r"best, checkpoints.*\): continue it with --resume"):
        _train(cfg, res.out, 512, n_envs=4)
    assert sorted(p.relative_to(res.out) for p in res.out.rglob("*")) == before   # untouched

    old = tmp_path / "old"                      # a copy of another run, plus a file of the user's
    import shutil
    shutil.copytree(res.out, old)
    (old / "notes.txt").write_text("mine")
    new = _train(_tiny(tmp_path), old, 128, overwrite=True, seed=5)
    assert not (old / "checkpoints" / "rl_model_1024_steps.zip").exists()     # the old run is gone
    assert (old / "notes.txt").read_text() == "mine"
    info = json.loads((old / "training.json").read_text())
    assert info["seed"] == 5 and [h["timesteps"] for h in info["learning_curve"]] == [new.timesteps]
    with pytest.raises(ConfigError, match="--overwrite would delete the run"):
        _train(_tiny(tmp_path), old, 256, overwrite=True, resume=old)


def test_a_short_run_evaluates_and_checkpoints_its_final_model(tmp_path):
    """eval_freq and checkpoint_freq far beyond the run: the final model is still evaluated,
    kept as best/, checkpointed and plotted, and the summary lists what was written."""
    out = tmp_path / "run"
    res = _train(_tiny(tmp_path, "  eval_freq: 25000\n  checkpoint_freq: 100000\n"), out, 200)
    curve = json.loads((out / "training.json").read_text())["learning_curve"]
    assert [h["timesteps"] for h in curve] == [256] and res.timesteps == 256
    for f in ("best/best_model.zip", "best/vecnormalize.pkl", "learning_curve.png",
              "checkpoints/rl_model_256_steps.zip", "checkpoints/rl_model_vecnormalize_256_steps.pkl"):
        assert (out / f).is_file(), f
        assert str(out / f) in res.summary() or f.startswith("checkpoints/")
    assert "checkpoints/ (1 checkpoints)" in res.summary() and res.evaluations == 1
    # eval_freq: 0 switches evaluation off, and the summary says so
    off = _train(_tiny(tmp_path, "  eval_freq: 0\n  checkpoint_freq: 0\n"), tmp_path / "off", 128)
    assert off.evaluations == 0 and not (tmp_path / "off" / "best").exists()
    assert "no evaluation ran" in off.summary()


def test_resume_into_the_same_directory_continues_the_record(tmp_path):
    """--resume R --out R: the learning curve, evaluations.npz and monitor.csv keep the first
    session's entries, and best/ is replaced only by a model better than the recorded best."""
    cfg = _tiny(tmp_path, "  eval_freq: 128\n  checkpoint_freq: 256\n")
    run = tmp_path / "run"
    _train(cfg, run, 256)
    first = json.loads((run / "training.json").read_text())["learning_curve"]
    assert [h["timesteps"] for h in first] == [128, 256]
    episodes = len((run / "monitor.csv").read_text().splitlines())
    # pretend the first session found an excellent model: nothing later may replace it
    record = json.loads((run / "training.json").read_text())
    record["learning_curve"][0]["mean_reward"] = 1e9
    (run / "training.json").write_text(json.dumps(record))
    best = (run / "best" / "best_model.zip").read_bytes()

    res = _train(cfg, run, 512, resume=run)
    assert res.timesteps == 512
    info = json.loads((run / "training.json").read_text())
    assert [h["timesteps"] for h in info["learning_curve"]] == [128, 256, 384, 512]
    assert info["learning_curve"][1] == first[1]                  # previous entries kept as they were
    assert info["resumed_from"].endswith("rl_model_256_steps.zip") and info["finished"]
    npz = np.load(run / "eval" / "evaluations.npz")
    assert npz["timesteps"].tolist() == [128, 256, 384, 512]
    assert (run / "best" / "best_model.zip").read_bytes() == best     # not replaced by a worse one
    lines = (run / "monitor.csv").read_text().splitlines()
    assert len(lines) > episodes and lines[1].startswith("r,l,t")   # appended under one header
    assert sum(line.startswith("r,l,t") for line in lines) == 1
    assert {p.name for p in (run / "checkpoints").glob("*_steps.zip")} == {
        "rl_model_256_steps.zip", "rl_model_512_steps.zip"}


def test_a_run_ships_as_a_policy_of_agents_policies(trained, tmp_path, capsys):
    """``python -m agents.training.ship RUN NAME``: how the shipped policies are made (a
    self-contained zip, the statistics, the JSON that reproduces the run)."""
    from stable_baselines3 import PPO

    from agents.sb3_policy import is_self_contained
    from agents.training.ship import main as ship
    res, _ = trained
    assert ship([str(res.out), "ppo-tiny", "--dest", str(tmp_path), "--notes", "a test"]) == 0
    assert "wrote" in capsys.readouterr().out
    assert {p.name for p in tmp_path.iterdir()} == {"ppo-tiny.zip", "ppo-tiny.pkl", "ppo-tiny.json"}
    meta = json.loads((tmp_path / "ppo-tiny.json").read_text())
    assert (meta["name"], meta["algo"], meta["env_id"], meta["seed"]) == \
        ("ppo-tiny", "ppo", "RotorDrop-Damping-v1", 3)
    assert meta["command"].startswith("rotordrop train --env RotorDrop-Damping-v1") and meta["notes"] == "a test"
    assert is_self_contained(PPO.load(tmp_path / "ppo-tiny.zip", device="cpu"))   # plain SB3 runs it
    assert ship([str(res.out), "tiny", "--dest", str(tmp_path)]) == 2      # no algorithm prefix
    assert "starts with its algorithm" in capsys.readouterr().err
