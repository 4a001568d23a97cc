"""The robust suite (``rotordrop benchmark --suite robust``, agents/benchmarking/robust.py): its scenarios,
the latency in each row's control steps, seed groups and the target, the leaderboard on a
small fixture, and one-line errors for a bad --suite."""
from types import SimpleNamespace

import numpy as np
import pytest

from agents.benchmarking.benchmark import Entry, Scenario, episode_kwargs, latency_steps
from agents.benchmarking.score import seed_groups, target
from agents.benchmarking.robust import (LATENCY_MS, ROBUST_RANGES, SENSOR_DELAY_S, SENSOR_NOISE, SUITE_SEED,
                           VALIDATION_SEED,
                           draw_scenario, robust_benchmark, robust_scenarios,
                           training_env_kwargs)
from agents.benchmarking.suites import SUITES, run_suite


def test_scenarios_are_reproducible_inside_the_ranges_and_disjoint_from_validation():
    a, b = robust_scenarios(30), robust_scenarios(30)
    assert a == b
    lat = set()
    for s in a:
        values = {"contact.friction": s.friction, **s.overrides, **s.env_kwargs}
        for key, (lo, hi) in ROBUST_RANGES.items():
            hi = hi + (0.005 if key == "power_return_time" else 0.0)     # rounded up to the grid
            assert lo <= values[key] <= hi, key
        steps = s.env_kwargs["power_return_time"] / 0.005
        assert abs(steps - round(steps)) < 1e-9
        assert s.sensor_noise == SENSOR_NOISE and s.tasks == ("full",)
        assert SENSOR_DELAY_S[0] <= s.overrides["sensor.delay"] <= SENSOR_DELAY_S[1]
        lat.add(round(1e3 * s.latency_s))
    assert lat == set(range(LATENCY_MS[0], LATENCY_MS[1] + 1))
    assert {s.seed for s in a}.isdisjoint(range(VALIDATION_SEED, VALIDATION_SEED + 1000))
    assert draw_scenario(SUITE_SEED + 7).friction == a[7].friction


@pytest.mark.parametrize("latency_ms, dt, steps", [(1, 1e-3, 1), (3, 1e-3, 3), (1, 5e-3, 1),
                                                   (3, 5e-3, 1), (6, 5e-3, 2), (2, 2e-3, 1)])
def test_latency_in_whole_control_steps_rounded_up(latency_ms, dt, steps):
    assert latency_steps(1e-3 * latency_ms, dt) == steps


def test_episode_kwargs_take_the_scenarios_sensing_not_the_training_one():
    trained = dict(command="supervisor", control_dt=0.005, **{
        k: v for k, v in training_env_kwargs().items() if k != "control_dt"})
    entry = Entry("sac", "full", None, trained)
    robust = Scenario("r", 0.4, {"amb.current_limit": 2.5}, sensor_noise=2e-6, latency_s=3e-3)
    kw = episode_kwargs(entry, robust, 0.0)
    assert kw["sensor_noise"] == 2e-6 and kw["obs_latency_steps"] == 1
    assert kw["overrides"]["amb.current_limit"] == 2.5 and "randomization" not in kw
    nominal = episode_kwargs(entry, Scenario("n", 0.4), 0.0)          # the nominal suite
    assert "sensor_noise" not in nominal and "obs_latency_steps" not in nominal
    designed = episode_kwargs(Entry("pid", "full", None, {"command": "continuous"}), robust, 0.0)
    assert designed["obs_latency_steps"] == 3                          # 1 ms step: supervisor seat
    inside = Entry("pid", "full", None, {"command": "continuous", "control_dt": 2e-4})
    assert inside.seat == "controller"                                 # inside the AMB controller:
    kw = episode_kwargs(inside, robust, 0.0)                           # the sensor's noise and
    assert "obs_latency_steps" not in kw and kw["sensor_noise"] == 2e-6  # delay, no transport


def test_training_kwargs_match_the_suite():
    kw = training_env_kwargs(0.005)
    assert kw["obs_latency_steps"] == [0, 1] and kw["sensor_noise"] == SENSOR_NOISE
    assert training_env_kwargs(1e-3)["obs_latency_steps"] == [0, 1]
    assert kw["randomization"] == {**{k: list(v) for k, v in ROBUST_RANGES.items()},
                                   "sensor.delay": list(SENSOR_DELAY_S)}


def test_seed_groups_and_the_target():
    hp = {"gamma": 0.98}
    pols = {f"sac@s{i}": SimpleNamespace(algo="sac", env_id="F", meta={"hyperparams": hp}, env_kwargs={})
            for i in range(3)}
    pols["ppo-x"] = SimpleNamespace(algo="ppo", env_id="F", meta={"hyperparams": hp}, env_kwargs={})
    board = [dict(controller="inner-loop", score=60.0, kind="designed"),
             dict(controller="passive", score=0.0, kind="designed"),
             dict(controller="sac@s0", score=66.0, kind="learned"),
             dict(controller="sac@s1", score=64.0, kind="learned"),
             dict(controller="sac@s2", score=65.0, kind="learned"),
             dict(controller="ppo-x", score=63.5, kind="learned")]
    groups = seed_groups(board, pols)
    assert len(groups) == 1 and groups[0]["mean"] == pytest.approx(65.0)
    assert groups[0]["std"] == pytest.approx(1.0) and groups[0]["mean_minus_std"] == pytest.approx(64.0)
    t = target(board, groups)
    assert t["best_designed"] == "inner-loop" and t["best_learned_score"] == pytest.approx(64.0)
    assert t["met"] and t["margin"] == 2.0              # 64.0 >= 60 + 2
    board[0]["score"] = 62.5
    assert not target(board, groups)["met"]             # 64.0 < 64.5: mean - std counts, not the best seed
    # a shipped policy benchmarked beside the run it came from (same seed) counts once, and
    # does not stand alone as a best learned row either
    for name, seed in (("sac@s0", 0), ("sac@s1", 1), ("sac@s2", 2)):
        pols[name].meta = {"hyperparams": hp, "seed": seed}
    pols["sac-shipped"] = SimpleNamespace(algo="sac", env_id="F", env_kwargs={},
                                          meta={"hyperparams": hp, "seed": 0})
    board.append(dict(controller="sac-shipped", score=66.0, kind="learned"))
    groups = seed_groups(board, pols)
    assert groups[0]["members"] == ["sac@s0", "sac@s1", "sac@s2"]
    assert groups[0]["repeats"] == ["sac-shipped"] and groups[0]["mean"] == pytest.approx(65.0)
    assert target(board, groups)["best_learned_score"] == pytest.approx(64.0)


def test_bad_suite_and_nominal_only_options_raise():
    with pytest.raises(ValueError, match="--suite = 'robst' must be one of nominal, robust"):
        run_suite("robst", "unused")
    with pytest.raises(ValueError, match="--episodes does not apply to --suite robust"):
        run_suite("robust", "unused", episodes=2)


def test_cli_refuses_a_bad_suite_in_one_line(capsys):
    from agents.cli import main
    assert main(["benchmark", "--suite", "hard", "--out", "unused"]) == 2
    err = capsys.readouterr().err.strip()
    assert "--suite = 'hard' must be one of nominal, robust" in err and "\n" not in err


def test_a_small_robust_suite_scores_every_full_row(tmp_path):
    report = robust_benchmark(tmp_path, max_scenarios=2, progress=False, plots=False,
                              suite=SUITES.get("robust"))
    board = {e["controller"]: e for e in report["leaderboard"]}
    assert board["passive"]["score"] == pytest.approx(0.0) and board["passive"]["kind"] == "designed"
    assert {"inner-loop", "whirl-brake", "pid-relevitate", "whirl-brake-sup"} <= set(board)
    assert all(e["task"] == "full" for e in board.values())
    assert any(e["kind"] == "learned" for e in board.values())
    assert len(report["rows"]) == 2 * len(board) and len(report["scenarios"]) == 2
    # the built-in PID re-levitates through the sensors' delay and noise
    assert board["builtin-relevitate"]["relevitation_rate"] == 1.0
    assert SENSOR_DELAY_S[0] <= report["scenarios"][0]["overrides"]["sensor.delay"] <= SENSOR_DELAY_S[1]
    assert (tmp_path / "benchmark.json").is_file() and "Target" in (tmp_path / "leaderboard.md").read_text()
    assert report["scenarios"][0]["seed"] == SUITE_SEED


@pytest.mark.slow
def test_robust_quick_end_to_end(tmp_path):
    import json
    from agents.cli import main
    assert main(["benchmark", "--suite", "robust", "--quick", "--quiet", "--out", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "benchmark.json").read_text())
    assert len(report["scenarios"]) == 40 and (tmp_path / "robust.png").is_file()
    rows = {e["controller"]: e for e in report["leaderboard"]}
    assert rows["passive"]["whirl_rate_where_passive_whirls"] == 1.0
    assert np.isfinite(rows["inner-loop"]["score"])


def test_the_test_drops_are_fresh_and_the_legacy_ones_stay_reproducible():
    """The test set shares no seed with the validation drops or the earlier test set, which
    --suite robust-legacy still draws."""
    from agents.benchmarking.robust import LEGACY_SUITE_SEED, SUITE_SCENARIOS, VALIDATION_SCENARIOS
    test = set(range(SUITE_SEED, SUITE_SEED + SUITE_SCENARIOS))
    assert test.isdisjoint(range(VALIDATION_SEED, VALIDATION_SEED + VALIDATION_SCENARIOS))
    assert test.isdisjoint(range(LEGACY_SUITE_SEED, LEGACY_SUITE_SEED + SUITE_SCENARIOS))
    assert robust_scenarios(1, LEGACY_SUITE_SEED)[0] == draw_scenario(30_000, "#0")
    assert robust_scenarios(1)[0].seed == SUITE_SEED != LEGACY_SUITE_SEED


def test_robust_legacy_runs_the_earlier_test_drops(tmp_path):
    report = run_suite("robust-legacy", tmp_path, max_scenarios=1, progress=False, plots=False,
                       score="legacy")
    assert report["suite"] == "robust-legacy" and report["score"] == "legacy"
    assert report["scenarios"][0]["seed"] == 30_000
    assert report["distribution"]["scenario_seeds"] == [30_000, 30_000]
    assert "--suite robust-legacy" in (tmp_path / "leaderboard.md").read_text()
