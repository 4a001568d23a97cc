"""rl-zoo3 unchanged: the shipped YAMLs train with ``python -m rl_zoo3.train`` as they are, a
shipped policy plays with ``python -m rl_zoo3.enjoy``, and ``rotordrop train`` reads the same
rl-zoo3 entries as its own keys."""
import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from stable_baselines3 import PPO
from stable_baselines3.common.env_util import make_vec_env

from agents.learning.hyperparams import (ConfigError, default_config_path, load_hyperparams,
                                project_keys, split)
from agents.learning.policies import ACTING_ONLY, export_zoo
from agents.control.residual import ResidualAction
from agents.learning.reward import KpiReward
from rotordrop_env import make_batched

ROOT = Path(__file__).resolve().parents[3]
#: what the shipped PPO blocks meant before they were written as rl-zoo3 entries
SHIPPED = {"RotorDrop-Damping-v1": ("max-damping", 0.5), "RotorDrop-Relevitate-v1": ("whirl-brake", 0.5),
           "RotorDrop-Full-v1": ("whirl-brake", 1.0)}


def _zoo(module, *args, timeout=300):
    # looked up, not imported: importing rl_zoo3 patches gymnasium's TimeLimit in this process
    # (its gym_patches), and the environment tests that run later would see its info key
    if importlib.util.find_spec("rl_zoo3") is None:
        pytest.skip("rl_zoo3 is not installed")
    env = dict(os.environ, PYTHONPATH=str(ROOT), OMP_NUM_THREADS="1", MPLBACKEND="Agg")
    res = subprocess.run([sys.executable, "-m", f"rl_zoo3.{module}", *args], cwd=ROOT, env=env,
                         capture_output=True, text=True, timeout=timeout)
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-3000:]
    return res.stdout


def test_rl_zoo3_trains_from_the_shipped_yaml_with_the_projects_wrappers_and_callback(tmp_path):
    """A few hundred steps from agents/configs/ppo.yaml as it is; the validation callback's
    interval shortened (rl-zoo3's -params) so that it runs and keeps a self-contained best."""
    best = tmp_path / "validation"
    callback = f"[{{'agents.training.validation.ValidationCallback': {{'eval_freq': 512, 'save_path': '{best}'}}}}]"
    out = _zoo("train", "--algo", "ppo", "--env", "RotorDrop-Damping-v1", "--gym-packages",
               "rotordrop_env", "-conf", "agents/configs/ppo.yaml", "-n", "300", "-f", str(tmp_path),
               "--eval-freq", "-1", "--num-threads", "1", "--seed", "0", "-params",
               f"callback:{callback}")
    assert "validation score" in out
    run = tmp_path / "ppo" / "RotorDrop-Damping-v1_1"
    saved = yaml.load((run / "RotorDrop-Damping-v1" / "config.yml").read_text(), Loader=yaml.UnsafeLoader)
    assert dict(saved)["vec_env_wrapper"][0] == {"agents.control.residual.ResidualAction":
                                                 {"base": "max-damping", "scale": 0.5}}
    # the schedules rl-zoo3 pickled would import rl_zoo3 (and its gymnasium patch) here
    model = PPO.load(run / "RotorDrop-Damping-v1.zip", device="cpu", custom_objects=ACTING_ONLY)
    assert model.num_timesteps == 1024                          # one rollout of 8 x 128 steps
    assert (best / "best_model.zip").is_file()
    chosen = PPO.load(best / "best_model.zip", device="cpu",     # plain SB3, residual inside
                      custom_objects=ACTING_ONLY)
    assert chosen.policy.rotordrop["residual"] == "max-damping"


def test_rl_zoo3_enjoy_plays_a_shipped_policy(tmp_path):
    export_zoo("ppo-damping", tmp_path)
    out = _zoo("enjoy", "--algo", "ppo", "--env", "RotorDrop-Damping-v1", "--gym-packages",
               "rotordrop_env", "-f", str(tmp_path), "--exp-id", "-1", "--no-render",
               "--deterministic", "-n", "61", "--num-threads", "1")
    assert "Episode Length 60" in out                          # 0.3 s at its 5 ms control step


@pytest.mark.parametrize("env_id", list(SHIPPED))
def test_the_shipped_entries_are_the_projects_options(env_id):
    meta, _ = split(load_hyperparams("ppo", env_id))
    base, scale = SHIPPED[env_id]
    assert (meta["residual"], meta["residual_scale"], meta["reward"], meta["validation"]) == \
        (base, scale, "kpi", True)
    assert (meta["eval_freq"], meta["n_eval_episodes"], meta["checkpoint_freq"]) == (25_000, 8, 100_000)


def test_a_user_config_overrides_the_entries_in_either_form(tmp_path):
    cfg = tmp_path / "c.yaml"
    cfg.write_text("residual: whirl-switch\nresidual_scale: 1.0\n")            # the old keys
    meta, _ = split(load_hyperparams("ppo", "RotorDrop-Damping-v1", cfg))
    assert (meta["residual"], meta["residual_scale"], meta["reward"]) == ("whirl-switch", 1.0, "kpi")
    cfg.write_text("vec_env_wrapper: []\ncallback: []\n")                        # drop them
    meta, _ = split(load_hyperparams("ppo", "RotorDrop-Damping-v1", cfg))
    assert meta.get("residual") is None and meta["reward"] == "env" and meta["validation"] is False


@pytest.mark.parametrize("block,match", [
    ({"residual": "passive", "vec_env_wrapper": [{"agents.control.residual.ResidualAction": {"base": "max-damping"}}]},
     "residual is given twice"),
    ({"vec_env_wrapper": "my.Wrapper"}, "vec_env_wrapper my.Wrapper: rotordrop train knows"),
    ({"vec_env_wrapper": [{"agents.control.residual.ResidualAction": {"bas": "x"}}]}, "unknown key 'bas'"),
    ({"callback": "sb3.Other"}, "callback sb3.Other: rotordrop train knows"),
    ({"env_wrapper": "x.Y"}, "env_wrapper .* is an rl-zoo3 option"),
    ({"vec_env_wrapper": [{"a": 1, "b": 2}]}, "each entry is a class path"),
    ({"callback": [{"agents.training.validation.ValidationCallback": {"save_path": "x"}}]},
     "save_path is where rl-zoo3 keeps"),
])
def test_entries_rotordrop_train_cannot_run_are_named(block, match):
    with pytest.raises(ConfigError, match=match):
        project_keys(block)


def test_the_wrappers_on_sb3s_dummy_vec_env_equal_the_batched_training_env():
    """What rl-zoo3 trains on (DummyVecEnv of gym.make envs) is what rotordrop train trains on
    (the batched VecEnv): same observations and KPI rewards under the same residual."""
    kw = dict(command="continuous", randomize=True, episode_time=0.02, terminate_on_failure=False)
    envs = [KpiReward(ResidualAction(v, base="whirl-brake", scale=0.5)) for v in
            (make_vec_env("RotorDrop-Full-v1", 2, seed=0, env_kwargs=kw),
             make_batched("RotorDrop-Full-v1", 2, seed=0, n_threads=1, **kw))]
    assert np.array_equal(envs[0].reset(), envs[1].reset())
    rng = np.random.default_rng(0)
    for _ in range(45):                                            # past two episode ends
        a = rng.uniform(-1, 1, (2, 6)).astype(np.float32)
        (o1, r1, d1, _), (o2, r2, d2, _) = envs[0].step(a), envs[1].step(a)
        assert np.array_equal(o1, o2) and np.array_equal(r1, r2) and np.array_equal(d1, d2)


def test_every_shipped_yaml_has_only_keys_rl_zoo3_passes_on_correctly():
    """rl-zoo3 hands every key it does not know to the algorithm's constructor. It reads the block
    of the env id it trains; the entries named after shipped policies are rotordrop train's
    (``--config FILE:ENTRY``) and may use its own keys."""
    import inspect
    from agents.learning.hyperparams import algo_class
    zoo = {"n_timesteps", "n_envs", "policy", "policy_kwargs", "normalize", "env_kwargs",
           "vec_env_wrapper", "callback", "noise_type", "noise_std", "env_wrapper", "frame_stack",
           "monitor_kwargs"}
    for algo in ("ppo", "sac", "td3"):
        args = set(inspect.signature(algo_class(algo).__init__).parameters)
        blocks = yaml.safe_load(default_config_path(algo).read_text())
        assert {"RotorDrop-Damping-v1", "RotorDrop-Relevitate-v1", "RotorDrop-Full-v1"} <= set(blocks)
        for env_id, block in blocks.items():
            if not env_id.startswith("RotorDrop-"):
                continue
            assert set(block) <= zoo | args, (algo, env_id, set(block) - zoo - args)


def test_the_run_flags_override_the_config(tmp_path):
    from agents.training.train import resolve_config
    hp = resolve_config("RotorDrop-Damping-v1", "ppo", eval_freq=1000, n_eval_episodes=2,
                        checkpoint_freq=0)
    meta, _ = split(hp)
    assert (meta["eval_freq"], meta["n_eval_episodes"], meta["checkpoint_freq"]) == (1000, 2, 0)


def test_export_policy_command(tmp_path, capsys):
    from agents.cli import main
    assert main(["export-policy", "ppo-relevitate", "--out", str(tmp_path / "p.zip")]) == 0
    assert PPO.load(tmp_path / "p.zip", device="cpu").policy.rotordrop["residual"] == "whirl-brake"
    assert main(["export-policy", "ppo-relevitate", "--zoo", str(tmp_path / "zoo")]) == 0
    assert "rl_zoo3.enjoy --algo ppo --env RotorDrop-Relevitate-v1" in capsys.readouterr().out
    assert (tmp_path / "zoo" / "ppo" / "RotorDrop-Relevitate-v1" / "config.yml").is_file()
    assert main(["export-policy", "no-such-policy", "--out", str(tmp_path / "x.zip")]) == 2
    assert "no-such-policy" in capsys.readouterr().err
