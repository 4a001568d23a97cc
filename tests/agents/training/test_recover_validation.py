"""Model selection on the Recover task: the validation callback scores a Recover run on the
recover suite's validation events (recovered %, ties broken by the mean peak contact force),
scores the initial policy at step 0, and rejects bad settings with a clear error."""
import json

import pytest

from agents.benchmarking.recover import (ENV_ID, RecoverValidator, event_record, learned_kwargs,
                                         selection_score)
from agents.training.validation import validator_for
from agents.benchmarking.suites import SUITES
from agents.learning.hyperparams import ConfigError, split


def _rec(recovered: bool, force: float) -> dict:
    return {"recovered": recovered, "peak_contact_force_N": force}


def test_selection_score_counts_recoveries_first_then_breaks_ties_by_force():
    a = [_rec(True, 5e3), _rec(False, 2e4)]                     # 1 of 2, mean force 12.5 kN
    assert selection_score(a) == pytest.approx(50.0 - 12.5e3 / 22.5e3)
    heavier = [_rec(True, 9e4), _rec(False, 9e4)]               # as many recoveries, more force
    assert selection_score(heavier) < selection_score(a)
    # one more recovery outranks any force: 60 events, one recovery is 1.67 points
    more = [_rec(i < 31, 1e6) for i in range(60)]
    fewer = [_rec(i < 30, 0.0) for i in range(60)]
    assert selection_score(more) > selection_score(fewer)
    assert selection_score([_rec(False, 0.0)] * 3) == 0.0


def test_a_recover_run_validates_on_the_recover_suites_events():
    v = validator_for(ENV_ID, {"randomize": True, "episode_time": 0.5}, 12)
    assert isinstance(v, RecoverValidator) and v.suite.name == "recover"
    assert list(v.seeds) == list(range(61_000, 61_012))          # validation, not test, seeds
    assert not set(v.seeds) & set(SUITES.get("recover").test_seeds())
    noisy = validator_for(ENV_ID, {"sensor_noise": 2e-6})        # imperfect sensing: the robust suite
    assert noisy.suite.name == "recover-robust" and len(noisy.seeds) == 30
    # the policy's interface (command) is kept, its training distribution gives way to the suite's
    kw = learned_kwargs({"command": "supervisor", "episode_time": 0.1, "randomize": False},
                        v.suite.env_kwargs)
    assert kw["command"] == "supervisor" and kw["episode_time"] == 0.5 and kw["randomize"]


@pytest.mark.parametrize("events", [0, 61, 2.5, True, "10"])
def test_bad_validation_event_counts_are_clear_errors(events):
    with pytest.raises(ValueError, match="validation_events"):
        validator_for(ENV_ID, {}, events)


def test_validation_events_on_a_drop_task_is_an_error():
    with pytest.raises(ValueError, match="validation_events.*RotorDrop-Full-v1"):
        validator_for("RotorDrop-Full-v1", {}, 10)


@pytest.mark.parametrize("meta, match", [
    ({"validation_events": 10}, "needs validation: true"),
    ({"validation": True, "validation_events": 0}, r"integer in \[1, 60\]"),
    ({"validation": True, "validation_events": 61}, r"integer in \[1, 60\]"),
    ({"validation": True, "validation_events": "20"}, r"integer in \[1, 60\]"),
])
def test_bad_validation_events_config_names_the_key(meta, match):
    with pytest.raises(ConfigError, match=match):
        split(meta)


def test_a_recover_run_keeps_its_best_model_from_step_zero_on_recover_events(tmp_path):
    """A zero-start residual on the PID is the PID at step 0: its validation score there is the
    PID's selection score on the same events, recorded in best/validation.json with the events
    recovered, and best/ holds a model (the initial one at least)."""
    from agents.benchmarking.rollout import run_episodes
    from agents.control.controllers import controller_class, controller_env_kwargs, make_controller
    from agents.training.train import train
    cfg = tmp_path / "val.yaml"
    cfg.write_text("RotorDrop-Recover-v1:\n  n_steps: 64\n  batch_size: 64\n  n_epochs: 1\n"
                   "  eval_freq: 128\n  n_eval_episodes: 1\n  checkpoint_freq: 0\n"
                   "  policy_kwargs: \"dict(net_arch=[8], log_std_init=-3.0)\"\n"
                   "  residual: inner-loop\n  residual_scale: 1.0\n  zero_start: true\n"
                   "  validation: true\n  validation_events: 2\n"
                   "  env_kwargs: {command: supervisor, episode_time: 0.05}\n")
    res = train(ENV_ID, "ppo", tmp_path / "run", timesteps=128, n_envs=2, config=cfg,
                progress=False)
    kept = json.loads((res.out / "best" / "validation.json").read_text())
    first = kept["history"][0]
    assert first["timesteps"] == 0 and first["events"] == 2
    assert (res.out / "best" / "best_model.zip").is_file()
    assert kept["best"] == max(h["score"] for h in kept["history"]) >= first["score"]
    v = validator_for(ENV_ID, {"command": "supervisor"}, 2)
    cls = controller_class("inner-loop")
    eps = run_episodes(ENV_ID, lambda plant: make_controller(cls, plant), v.seeds,
                       {**v.suite.env_kwargs, **controller_env_kwargs(cls, ENV_ID)})
    pid = [event_record(e) for e in eps]
    assert pid[0]["peak_contact_force_N"] > 0                     # the events make contact
    assert first["score"] == pytest.approx(selection_score(pid))
    assert first["recovered"] == sum(r["recovered"] for r in pid)
    from agents.training.validation import selection_rows
    row, = selection_rows([res.out])
    assert row["initial_recovered"] == f"{first['recovered']}/2" and row["checks"] == len(kept["history"])
    assert row["kept_score"] == pytest.approx(kept["best"], abs=0.01) and row["steps"] == res.timesteps
    from agents.training.validation import plot_selection
    assert plot_selection([res.out], tmp_path / "sel.png").stat().st_size > 0
