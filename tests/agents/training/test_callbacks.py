"""The training callbacks (agents/training/callbacks.py) one at a time, without a training run."""

import pytest

pytest.importorskip("stable_baselines3")

from agents.training.callbacks import RecordCallback, SaveBest, WallClockLimit, _run_now  # noqa: E402


class _Model:
    num_timesteps = 1234


def test_wall_clock_limit_stops_the_run_once_its_budget_has_passed_and_marks_the_record():
    record = {}
    cb = WallClockLimit(3600.0, record)
    cb._on_training_start()
    assert record == {"stopped_by_time_limit": False} and cb._on_step()
    cb.limit = 0.0
    assert not cb._on_step() and record["stopped_by_time_limit"] is True


def test_save_best_hands_the_model_and_the_best_zip_path_to_its_saver(tmp_path):
    saved = []
    cb = SaveBest(tmp_path / "best", lambda model, path: saved.append((model, path)))
    cb.model = model = _Model()
    assert cb._on_step()
    assert saved == [(model, tmp_path / "best" / "best_model.zip")]


def test_record_writes_training_json_when_an_evaluation_was_added(tmp_path):
    class Eval:
        kpi_history = []

    path = tmp_path / "training.json"
    cb = RecordCallback(path, {"algo": "ppo"}, Eval)
    cb.model = _Model()
    cb._on_training_start()
    assert cb._on_step() and not path.exists()          # nothing new: nothing written
    Eval.kpi_history = [{"timesteps": 1234, "mean_reward": -1.5}]
    cb._on_step()
    import json
    data = json.loads(path.read_text())
    assert data["algo"] == "ppo" and data["finished"] is False
    assert data["learning_curve"] == Eval.kpi_history and data["timesteps"] == 1234


def test_run_now_runs_a_periodic_callback_once_off_its_period_and_restores_the_period():
    class Periodic:
        save_freq, n_calls, calls = 10, 7, 0
        model = _Model()

        def _on_step(self):
            assert self.n_calls % self.save_freq == 0      # the callback believes it is due
            self.calls += 1

    cb = Periodic()
    _run_now(cb, "save_freq")
    assert cb.calls == 1 and cb.save_freq == 10 and cb.num_timesteps == 1234
    cb.n_calls = 20                                       # just ran on its own period: not again
    _run_now(cb, "save_freq")
    assert cb.calls == 1
    cb.save_freq = 0                                      # disabled: never
    _run_now(cb, "save_freq")
    assert cb.calls == 1
