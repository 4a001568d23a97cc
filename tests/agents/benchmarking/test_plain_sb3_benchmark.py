"""A model trained with plain Stable-Baselines3 outside rotordrop (``model.save``: no config.yaml,
no statistics, no env id in the zip) goes on the leaderboard with ``--env`` and ``--name``."""
import json

import gymnasium as gym
import pytest
from stable_baselines3 import PPO

import rotordrop_env  # noqa: F401
from agents.cli import main

ENV = "RotorDrop-Damping-v1"


@pytest.fixture(scope="module")
def plain_zip(tmp_path_factory):
    path = tmp_path_factory.mktemp("plain") / "my.zip"
    model = PPO("MlpPolicy", gym.make(ENV), n_steps=128, batch_size=64, n_epochs=1, seed=0,
                device="cpu")
    model.learn(256)
    model.save(path)
    return path


def test_benchmark_puts_a_plain_sb3_zip_on_the_leaderboard_under_its_name(plain_zip, tmp_path, capsys):
    out = tmp_path / "bench"
    assert main(["benchmark", "--quick", "--policy", str(plain_zip), "--env", ENV,
                 "--name", "my-model", "--out", str(out), "--no-plots", "--quiet"]) == 0
    report = json.loads((out / "benchmark.json").read_text())
    mine = [e for e in report["leaderboard"] if e["controller"] == "my-model"]
    assert len(mine) == 1 and mine[0]["task"] == "damping"
    assert not any("@" in e["controller"] for e in report["leaderboard"])
    assert "| my-model |" in (out / "leaderboard.md").read_text()


def test_a_plain_zip_without_env_or_with_a_wrong_one_is_a_one_line_error(plain_zip, tmp_path, capsys):
    for extra, says in (([], "pass --env ID"),
                        (["--env", "RotorDrop-Full-v1"], "pass the --env the model was trained on"),
                        (["--env", "RotorDrop-Nope-v1"], "not a registered environment"),
                        (["--env", ENV, "--name", "a", "--name", "b"], "2 name(s) for 1")):
        assert main(["benchmark", "--quick", "--policy", str(plain_zip), *extra,
                     "--out", str(tmp_path / "b"), "--no-plots", "--quiet"]) != 0
        err = capsys.readouterr().err.strip()
        assert says in err and "\n" not in err, err


def test_export_policy_makes_a_plain_zip_self_contained_with_env(plain_zip, tmp_path):
    from agents.learning.policies import LearnedPolicy
    out = tmp_path / "mine.zip"
    assert main(["export-policy", str(plain_zip), "--env", ENV, "--out", str(out)]) == 0
    pol = LearnedPolicy.load(out)
    assert pol.self_contained and pol.env_id == ENV
