"""TQC and CrossQ (sb3-contrib) through ``rotordrop train`` like SAC, their zips under plain
``TQC.load`` / ``CrossQ.load`` and the project's loader (algorithm and environment read from the
zip alone), and the wall-clock limit of a training run (``--time-limit``)."""
import json
import shutil

import gymnasium as gym
import numpy as np
import pytest
import torch

from agents.learning.hyperparams import ConfigError, algo_class, load_hyperparams, split
from agents.learning.policies import LearnedPolicy
from agents.sb3_policy import is_self_contained, zip_algo
from agents.training.train import train

torch.set_num_threads(1)
ENV = "RotorDrop-Relevitate-v1"
TINY = (f"{ENV}:\n  n_envs: 2\n  learning_starts: 64\n  buffer_size: 2000\n  batch_size: 32\n"
        "  policy_kwargs: \"dict(net_arch=[16, 16], n_critics=2, n_quantiles=5)\"\n"
        "  top_quantiles_to_drop_per_net: 1\n  eval_freq: 128\n  n_eval_episodes: 2\n"
        "  checkpoint_freq: 128\n  env_kwargs:\n    episode_time: 0.03\n    power_return_time: 0.01\n")


@pytest.fixture(scope="module")
def tqc_run(tmp_path_factory):
    """A 256-step TQC run on raw currents with evaluations and checkpoints every 128 steps."""
    out = tmp_path_factory.mktemp("tqc")
    (out / "tiny.yaml").write_text(TINY)
    res = train(ENV, "tqc", out / "run", timesteps=256, config=out / "tiny.yaml", seed=1,
                progress=False)
    return res, out / "tiny.yaml"


def test_tqc_trains_checkpoints_and_resumes_like_sac(tqc_run, tmp_path):
    res, cfg = tqc_run
    run = res.out
    for f in ("model.zip", "best/best_model.zip", "best/vecnormalize.pkl", "learning_curve.png",
              "checkpoints/rl_model_replay_buffer_256_steps.pkl"):    # off-policy: buffer kept
        assert (run / f).is_file(), f
    info = json.loads((run / "training.json").read_text())
    assert info["algo"] == "tqc" and info["hyperparams"]["top_quantiles_to_drop_per_net"] == 1
    assert [h["timesteps"] for h in info["learning_curve"]] == [128, 256]
    assert all("mean_relevitated" in h for h in info["learning_curve"])
    times = [h["wall_time_s"] for h in info["learning_curve"]]
    assert 0.0 < times[0] <= times[1] <= info["wall_time_s"]
    more = train(ENV, "tqc", tmp_path / "more", timesteps=320, config=cfg, seed=1, resume=run,
                 progress=False)
    assert more.timesteps == 320
    sac_cfg = tmp_path / "sac.yaml"                       # without TQC's own keys
    sac_cfg.write_text(TINY.replace(", n_critics=2, n_quantiles=5", "")
                       .replace("  top_quantiles_to_drop_per_net: 1\n", ""))
    with pytest.raises(ConfigError, match="--algo sac does not match .* --algo tqc"):
        train(ENV, "sac", tmp_path / "x", timesteps=320, config=sac_cfg, resume=run, progress=False)


def test_a_tqc_zip_alone_loads_under_plain_tqc_and_the_project_loader(tqc_run, tmp_path):
    """Copied away from its run (no config.yaml): the algorithm comes from the zip's policy
    class and the environment from inside it; plain TQC.load acts as LearnedPolicy does."""
    res, _ = tqc_run
    lone = tmp_path / "policy.zip"                       # no "tqc" in the name either
    shutil.copy(res.out / "best" / "best_model.zip", lone)
    assert zip_algo(lone) == "tqc" and zip_algo(res.out / "checkpoints" / "rl_model_256_steps.zip") == "tqc"
    pol = LearnedPolicy.load(lone)
    assert (pol.algo, pol.env_id, pol.name) == ("tqc", ENV, "tqc-relevitate")
    assert pol.env_kwargs["episode_time"] == 0.03 and pol.self_contained
    plain = algo_class("tqc").load(lone, device="cpu")
    assert is_self_contained(plain)
    env = gym.make(ENV, **pol.env_kwargs)
    obs = np.stack([env.reset(seed=s)[0] for s in range(4)])
    assert np.array_equal(plain.predict(obs, deterministic=True)[0], pol.predict(obs)[0])
    # the network sees normalised observations: raw ones give other actions
    assert not np.array_equal(plain.policy.network_predict(obs, deterministic=True)[0],
                              pol.predict(obs)[0])


def test_evaluate_and_export_run_a_tqc_zip(tqc_run, tmp_path, capsys):
    from agents.cli import main
    res, _ = tqc_run
    lone = tmp_path / "policy.zip"
    shutil.copy(res.out / "model.zip", lone)
    assert main(["export-policy", str(lone), "--out", str(tmp_path / "again.zip")]) == 0
    assert zip_algo(tmp_path / "again.zip") == "tqc"
    assert main(["evaluate", "--policy", str(tmp_path / "again.zip"), "--episodes", "2",
                 "--out", str(tmp_path / "ev"), "--no-plots"]) == 0
    report = json.loads((tmp_path / "ev" / "kpis.json").read_text())
    assert report["env_id"] == ENV and len(report["episodes"]) == 2
    assert "relev. rate" in capsys.readouterr().out


def test_the_time_limit_stops_training_and_keeps_the_final_evaluation(tmp_path):
    """A limit already passed at the first step: one step of the 2 envs, then the run ends as
    at its last step (evaluated, best/ and model written), marked in training.json."""
    (tmp_path / "tiny.yaml").write_text(TINY)
    res = train(ENV, "tqc", tmp_path / "run", timesteps=10**6, config=tmp_path / "tiny.yaml",
                progress=False, time_limit=1e-9)
    assert res.timesteps == 2 and res.evaluations == 1
    info = json.loads((tmp_path / "run" / "training.json").read_text())
    assert info["stopped_by_time_limit"] is True and info["time_limit_s"] == 1e-9
    assert info["finished"] and [h["timesteps"] for h in info["learning_curve"]] == [2]
    assert (tmp_path / "run" / "best" / "best_model.zip").is_file()
    for bad in (0.0, -5.0, float("nan")):
        with pytest.raises(ConfigError, match="--time-limit must be a number of seconds > 0"):
            train(ENV, "tqc", tmp_path / "bad", config=tmp_path / "tiny.yaml", time_limit=bad)


def test_tqc_hyperparameters_are_checked_like_sacs(tmp_path):
    cfg = tmp_path / "bad.yaml"
    cfg.write_text(TINY.replace("top_quantiles_to_drop_per_net", "top_quantile_to_drop"))
    with pytest.raises(ConfigError, match="tqc config: unknown key 'top_quantile_to_drop'"):
        train(ENV, "tqc", tmp_path / "run", config=cfg, progress=False)
    meta, kwargs = split(load_hyperparams("tqc", ENV, "docs/experiments/configs/tqc-currents.yaml"))
    assert meta["env_kwargs"]["command"] == "continuous" and kwargs["policy_kwargs"]["n_quantiles"] == 25
    with pytest.raises(ConfigError, match="--algo tqc needs continuous actions"):
        cfg.write_text(TINY + "    command: discrete\n")
        train(ENV, "tqc", tmp_path / "run2", config=cfg, progress=False)


def test_crossq_trains_and_its_zip_runs_under_plain_crossq_and_evaluate(tmp_path, capsys):
    """CrossQ (one line of the algorithm registry and agents/configs/crossq.yaml): a short run
    under the noisy sensing, its zip self-contained under plain CrossQ.load, and evaluate with
    the sensing given again by --env-kwarg."""
    from agents.cli import main
    cfg = tmp_path / "tiny.yaml"
    cfg.write_text(TINY.replace(", n_critics=2, n_quantiles=5", "")
                   .replace("net_arch=[16, 16]", "net_arch=dict(pi=[16, 16], qf=[32, 32])")
                   .replace("  top_quantiles_to_drop_per_net: 1\n", "  policy_delay: 2\n")
                   + "    sensor_noise: 1.0e-6\n    sensor_delay: 1.0e-4\n")
    res = train(ENV, "crossq", tmp_path / "run", timesteps=256, config=cfg, seed=1, progress=False)
    lone = tmp_path / "policy.zip"
    shutil.copy(res.out / "best" / "best_model.zip", lone)
    assert zip_algo(lone) == "crossq"
    pol = LearnedPolicy.load(lone)
    assert pol.algo == "crossq" and pol.env_kwargs["sensor_delay"] == 1e-4
    plain = algo_class("crossq").load(lone, device="cpu")
    assert is_self_contained(plain)
    env = gym.make(ENV, **pol.env_kwargs)
    obs = np.stack([env.reset(seed=s)[0] for s in range(4)])
    assert np.array_equal(plain.predict(obs, deterministic=True)[0], pol.predict(obs)[0])
    assert main(["evaluate", "--policy", "whirl-brake", "--env", ENV, "--episodes", "1",
                 "--env-kwarg", "command=continuous", "--env-kwarg", "sensor_noise=1e-6",
                 "--env-kwarg", "episode_time=0.03", "--env-kwarg", "power_return_time=0.01",
                 "--out", str(tmp_path / "ev"), "--no-plots", "--no-passive"]) == 0
    kw = json.loads((tmp_path / "ev" / "kpis.json").read_text())["env_kwargs"]
    assert kw["sensor_noise"] == 1e-6 and kw["command"] == "continuous"
    assert main(["evaluate", "--policy", "whirl-brake", "--env", ENV, "--episodes", "1",
                 "--env-kwarg", "power_return_time=0.02", "--power-return-ms", "20",
                 "--out", str(tmp_path / "ev2"), "--no-plots"]) == 2
    assert "power_return_time is given twice" in capsys.readouterr().err
