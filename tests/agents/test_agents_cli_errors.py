"""The agents CLIs: strict JSON reports, flag errors that name the flag and the allowed range,
learned policies that load their own statistics and refuse an environment of another shape,
and user controllers that fail before long work."""
import json
import shutil

import numpy as np
import pytest

from agents.cli import main


def _strict(text: str):
    """json.loads that rejects NaN / Infinity (what other JSON readers do)."""
    def no_constant(name):
        raise ValueError(f"non-standard JSON constant {name}")
    return json.loads(text, parse_constant=no_constant)


def _flag_error(argv, capsys) -> str:
    """The one-line argparse error of ``rotordrop argv`` (exit status 2)."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    return capsys.readouterr().err.strip().splitlines()[-1]


# ---------------------------------------------------------------------------- JSON reports --
def test_write_json_writes_null_for_non_finite_floats(tmp_path):
    from agents.benchmarking.score import write_json
    path = write_json(tmp_path / "r.json", {"a": float("nan"), "b": np.float32(np.inf),
                                            "c": [1.5, np.nan], "d": np.array([2.0, -np.inf]),
                                            "e": (np.int64(3), True)})
    assert _strict(path.read_text()) == {"a": None, "b": None, "c": [1.5, None],
                                         "d": [2.0, None], "e": [3, True]}


def test_evaluate_kpis_json_is_strict_json(tmp_path):
    """In the damping task nothing re-levitates: the per-episode re-levitation time is
    undefined, and JSON says so with null (it had a bare NaN)."""
    out = tmp_path / "ev"
    assert main(["evaluate", "--policy", "passive", "--env", "RotorDrop-Damping-v1", "--episodes",
                 "1", "--fixed", "--no-plots", "--no-passive", "--out", str(out)]) == 0
    r = _strict((out / "kpis.json").read_text())
    assert r["episodes"][0]["relevitated"] is False
    assert r["episodes"][0]["relevitation_time_s"] is None


# ------------------------------------------------------------------------ episode scenario --
def test_kpis_json_records_the_drawn_scenarios_end_to_end(tmp_path):
    """Every episode record, the policy's and passive's, holds the scenario reset drew."""
    out = tmp_path / "ev"
    assert main(["evaluate", "--policy", "max-damping", "--env", "RotorDrop-Damping-v1",
                 "--episodes", "2", "--no-plots", "--out", str(out)]) == 0
    r = _strict((out / "kpis.json").read_text())
    sc = [e["scenario"] for e in r["episodes"]]
    assert all(isinstance(s, dict) and "contact.friction" in s for s in sc)
    assert sc[0]["contact.friction"] != sc[1]["contact.friction"]     # seeds 0, 1 draw their own
    assert [e["scenario"] for e in r["passive_episodes"]] == sc       # the same scenarios


# ----------------------------------------------------------------------------- ride-through --
def test_ride_through_advice_is_valid_and_ranges_are_the_real_ones(tmp_path, capsys):
    assert main(["ride-through", "--policy", "ppo-damping", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "no re-levitation" in err and "pass --env RotorDrop-Damping-v1" not in err
    assert main(["ride-through", "--policy", "ppo-full", "--out", str(tmp_path)]) == 2
    assert "pass --env RotorDrop-Full-v1" in capsys.readouterr().err      # advice that works
    # the scene's friction range, checked before any episode runs
    assert main(["ride-through", "--friction", "2", "--quiet", "--out", str(tmp_path)]) == 2
    assert "--friction values [2.0] are outside [0, 1]" in capsys.readouterr().err
    # the power must come back inside the 300 ms episode
    assert main(["ride-through", "--delay-ms", "500", "--quiet", "--out", str(tmp_path)]) == 2
    assert "--delay-ms values [500.0] are outside [0, 300) ms" in capsys.readouterr().err


def test_power_return_after_the_episode_is_an_error(tmp_path, capsys):
    assert main(["evaluate", "--policy", "whirl-brake", "--env", "RotorDrop-Relevitate-v1",
                 "--power-return-ms", "1000", "--out", str(tmp_path)]) == 2
    assert "--power-return-ms = 1000 ms must be in [0, 300) ms" in capsys.readouterr().err
    assert main(["benchmark", "--power-return-ms", "300", "--quiet", "--out", str(tmp_path)]) == 2
    assert "--power-return-ms = 300 ms must be in [0, 300) ms" in capsys.readouterr().err


def test_a_ride_through_time_at_the_end_of_the_grid_is_a_lower_bound(tmp_path):
    """At mu = 0.3 (the passive drop rests) whirl-brake holds at every delay of the grid: the
    JSON says that 10 ms is a lower bound, as the table's "≥" does."""
    from agents.benchmarking.ride_through import summary_table
    out = tmp_path / "rt"
    assert main(["ride-through", "--policy", "whirl-brake", "--friction", "0.3", "--delay-ms", "0",
                 "--delay-ms", "10", "--phase", "0", "--quiet", "--no-plots", "--out", str(out)]) == 0
    r = _strict((out / "ride_through.json").read_text())
    m = r["controllers"]["whirl-brake"]
    assert m["ride_through_s"] == [0.01] and m["ride_through_lower_bound"] == [True]
    assert "≥ 10 ms" in summary_table(r)
    m["ride_through_lower_bound"] = [False]            # the table follows the JSON field
    assert "| 10 ms |" in summary_table(r)


# --------------------------------------------------------------------------------- --seed --
@pytest.mark.parametrize("argv", [
    ["evaluate", "--policy", "passive", "--env", "RotorDrop-Damping-v1"],
    ["train", "--env", "RotorDrop-Damping-v1", "--algo", "ppo", "--out", "x"],
    ["tune", "--policy", "whirl-brake", "--env", "RotorDrop-Relevitate-v1", "--gain", "kp=0:1"]])
def test_a_negative_seed_is_a_flag_error(argv, capsys, tmp_path):
    err = _flag_error([*argv, "--seed", "-1"], capsys)
    assert err == f"rotordrop {argv[0]}: error: argument --seed: must be an integer >= 0, got '-1'"


# ----------------------------------------------------------------------------------- tune --
SWITCH_CONTROLLER = '''
import numpy as np
from agents.control.controllers import Controller


class Switch(Controller):
    name = "switch-damping"
    needs = ("damping",)

    def __init__(self, plant, r_on=0.5, hold=0.01):
        super().__init__(plant)
        self.r_on, self.hold_s = r_on, hold

    def commands(self, obs):
        return {"damping": np.ones((len(obs), 2))}
'''


def test_tune_names_only_the_gains_the_class_does_not_take(tmp_path, capsys):
    path = tmp_path / "switch.py"
    path.write_text(SWITCH_CONTROLLER)
    assert main(["tune", "--policy", f"{path}:Switch", "--env", "RotorDrop-Damping-v1",
                 "--gain", "r_on=0:1", "--gain", "level=0:1", "--out", str(tmp_path / "t")]) == 2
    err = capsys.readouterr().err
    assert "does not take the gains ['level']; its gains: r_on, hold" in err
    # a class taking **gains: its GAINS are its gains
    assert main(["tune", "--policy", "whirl-brake", "--env", "RotorDrop-Relevitate-v1",
                 "--gain", "kp=0:1", "--gain", "gamma=0:1", "--out", str(tmp_path / "t")]) == 2
    assert "does not take the gains ['gamma']; its gains: kp, kd" in capsys.readouterr().err


# ------------------------------------------------------------- controller file's neighbours --
def test_a_controller_file_imports_the_modules_next_to_it(tmp_path, monkeypatch):
    from agents.control.controllers import load_controller
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "eval_fix_helper_gains.py").write_text("LEVEL = 0.25\n")
    (folder / "ctrl.py").write_text(
        "import numpy as np\nfrom agents.control.controllers import Controller\n"
        "from eval_fix_helper_gains import LEVEL\n\n\n"
        "class H(Controller):\n    name = 'h-damping'\n    needs = ('damping',)\n\n"
        "    def commands(self, obs):\n        return {'damping': np.full((len(obs), 2), LEVEL)}\n")
    monkeypatch.chdir(tmp_path)                                # not from the file's directory
    monkeypatch.setattr("sys.path", list(__import__("sys").path))
    assert load_controller("mine/ctrl.py:H").name == "h-damping"


# ---------------------------------------------------------------------- learned policies --
def _checkpoint_run(tmp_path, with_stats: bool = True):
    """A run directory holding the shipped ppo-damping as SB3's CheckpointCallback names it."""
    from agents.learning.hyperparams import dump_yaml
    from agents.learning.policies import shipped_dir
    run = tmp_path / "myrun"
    (run / "checkpoints").mkdir(parents=True)
    meta = json.loads((shipped_dir() / "ppo-damping.json").read_text())
    dump_yaml(dict(algo="ppo", env_id=meta["env_id"], hyperparams=meta["hyperparams"]),
              run / "config.yaml")
    zip_ = run / "checkpoints" / "rl_model_1024_steps.zip"
    from stable_baselines3 import PPO
    from agents.sb3_policy import save_plain
    save_plain(PPO.load(shipped_dir() / "ppo-damping.zip", device="cpu"), zip_)   # a raw checkpoint
    if with_stats:
        shutil.copyfile(shipped_dir() / "ppo-damping.pkl",
                        run / "checkpoints" / "rl_model_vecnormalize_1024_steps.pkl")
    return zip_


def test_a_checkpoint_loads_its_vecnormalize_statistics(tmp_path):
    from agents.learning.policies import LearnedPolicy, load_shipped
    pol = LearnedPolicy.load(_checkpoint_run(tmp_path))
    shipped = load_shipped("ppo-damping")
    assert pol.vecnormalize is not None
    assert not pol.self_contained and shipped.self_contained
    assert np.array_equal(pol.vecnormalize.obs_rms.mean, shipped.model.policy.obs_mean.numpy())


def test_a_normalised_policy_without_its_statistics_is_an_error(tmp_path, capsys):
    zip_ = _checkpoint_run(tmp_path, with_stats=False)
    assert main(["evaluate", "--policy", str(zip_), "--out", str(tmp_path / "ev")]) == 2
    err = capsys.readouterr().err
    assert "trained with observation normalisation" in err
    assert "rl_model_vecnormalize_1024_steps.pkl" in err


def test_a_policy_on_an_environment_of_another_shape_is_an_error(tmp_path, capsys):
    assert main(["evaluate", "--policy", "ppo-damping", "--env", "RotorDrop-Full-v1",
                 "--episodes", "1", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert ("policy ppo-damping was trained on RotorDrop-Damping-v1 with 14 observations; "
            "RotorDrop-Full-v1 has 20") in err


def test_evaluate_labels_a_run_and_compares_returns_at_its_control_step(tmp_path):
    """A user's run is shown as name@run (as the benchmark does); the passive reference runs at
    the policy's 5 ms control step, so both returns sum the same 60 steps; the checkpoint with
    its statistics acts like the shipped policy it copies."""
    zip_ = _checkpoint_run(tmp_path)
    reports = {}
    for spec in ("ppo-damping", str(zip_)):
        out = tmp_path / spec.replace("/", "_")
        assert main(["evaluate", "--policy", spec, "--episodes", "1", "--fixed", "--no-plots",
                     "--set", "contact.friction=0.45", "--out", str(out)]) == 0
        reports[spec] = _strict((out / "kpis.json").read_text())
    mine = reports[str(zip_)]
    assert mine["policy"] == "ppo-damping@rl_model_1024_steps"
    assert mine["episodes"][0]["length"] == mine["passive_episodes"][0]["length"] == 60
    assert mine["episodes"][0]["reward"] == reports["ppo-damping"]["episodes"][0]["reward"]


# --------------------------------------------------------- user controllers fail fast --
BROKEN_CONTROLLER = '''
from agents.control.controllers import Controller


class Broken(Controller):
    name = "broken"
    needs = ("damping",)

    def __init__(self, plant, k=1.0):
        super().__init__(plant)
        self.k = k

    def commands(self, obs):
        raise RuntimeError("broken on purpose")


class BrokenCurrents(Broken):
    name = "broken-currents"
    needs = ("currents",)
'''


def _long_work(*args, **kwargs):
    raise AssertionError("long work started before the controller was checked")


@pytest.mark.parametrize("cmd, cls, patch", [
    (["benchmark", "--quick", "--quiet"], "Broken", "agents.benchmarking.benchmark.passive_threshold"),
    (["ride-through", "--quiet", "--quick"], "BrokenCurrents", "agents.benchmarking.ride_through.run_episodes"),
    (["tune", "--env", "RotorDrop-Damping-v1", "--gain", "k=0:1", "--quiet"], "Broken",
     "agents.benchmarking.tune.Validator"),
    (["evaluate", "--env", "RotorDrop-Damping-v1"], "Broken", "agents.benchmarking.evaluate.run_episodes")])
def test_a_broken_user_controller_fails_before_long_work(cmd, cls, patch, tmp_path, capsys,
                                                         monkeypatch):
    path = tmp_path / "broken.py"
    path.write_text(BROKEN_CONTROLLER)
    monkeypatch.setattr(patch, _long_work)
    assert main([*cmd, "--policy", f"{path}:{cls}", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "broken on purpose" in err
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").iterdir())


# ------------------------------------------------- review 2: names, refusals, table digits --
def _named_run(tmp_path, run: str, name: str):
    """A run directory holding the shipped ppo-damping under the policy name ``name``."""
    from agents.learning.hyperparams import dump_yaml
    from agents.learning.policies import shipped_dir
    folder = tmp_path / run
    folder.mkdir()
    meta = json.loads((shipped_dir() / "ppo-damping.json").read_text())
    dump_yaml(dict(algo="ppo", env_id=meta["env_id"], name=name, hyperparams=meta["hyperparams"]),
              folder / "config.yaml")
    shutil.copyfile(shipped_dir() / "ppo-damping.zip", folder / "model.zip")
    shutil.copyfile(shipped_dir() / "ppo-damping.pkl", folder / "vecnormalize.pkl")
    return str(folder)


class _Stop(Exception):
    pass


def test_the_benchmark_names_every_run_name_at_run_as_evaluate_does(tmp_path, monkeypatch):
    """Two runs of a policy no shipped one is named like: both are name@run (the first was
    bare, the second got @run only because of the clash); evaluate's label is the same."""
    from agents.benchmarking.benchmark import benchmark
    from agents.learning.policies import policy_label
    from agents.learning.policies import LearnedPolicy
    run_a, run_b = _named_run(tmp_path, "runA", "ppo-mine"), _named_run(tmp_path, "runB", "ppo-mine")
    seen = []

    def entries_then_stop(entries):
        seen.extend(e.name for e in entries)
        raise _Stop                                 # before the long work
    monkeypatch.setattr("agents.benchmarking.benchmark.check_unique_names", entries_then_stop)
    with pytest.raises(_Stop):
        benchmark(tmp_path / "b", policies=[run_a, run_b, "ppo-damping"], progress=False)
    mine = [n for n in seen if n.startswith("ppo-mine")]
    assert mine == ["ppo-mine@runA", "ppo-mine@runB"]
    assert "ppo-damping" in seen                    # a shipped policy keeps its bare name
    assert policy_label(run_a, LearnedPolicy.load(run_a)) == "ppo-mine@runA"


@pytest.mark.parametrize("argv, name, commands", [
    (["--quick"], "max-damping", "damping only"),
    (["--env", "RotorDrop-Full-v1"], "max-damping", "damping only"),
    (["--env", "RotorDrop-Full-v1"], "whirl-switch", "damping only"),
    ([], "passive", "nothing")])
def test_ride_through_refuses_a_controller_that_cannot_relevitate_up_front(
        argv, name, commands, tmp_path, capsys, monkeypatch):
    """It failed after 6 of 24 episodes with a channels message (Relevitate) or printed a row
    of "none" (Full): the power return the map varies never reaches such a controller."""
    monkeypatch.setattr("agents.benchmarking.ride_through.run_episodes", _long_work)
    assert main(["ride-through", *argv, "--policy", "whirl-brake", "--policy", name, "--quiet",
                 "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (f"rotordrop ride-through: error: --policy '{name}': ride-through maps "
                   f"controllers that re-levitate (set the 'levitate' or 'currents' channel); "
                   f"{name} commands {commands}")
    assert not (tmp_path / "o").exists()


def test_ride_through_refuses_a_users_damping_class_alike(tmp_path, capsys, monkeypatch):
    path = tmp_path / "switch.py"
    path.write_text(SWITCH_CONTROLLER)
    monkeypatch.setattr("agents.benchmarking.ride_through.run_episodes", _long_work)
    assert main(["ride-through", "--env", "RotorDrop-Full-v1", "--policy", f"{path}:Switch",
                 "--quiet", "--out", str(tmp_path / "o")]) == 2
    assert "switch-damping commands damping only" in capsys.readouterr().err


def test_leaderboard_scores_show_the_digits_that_rank_them():
    """13.08 and 13.07 rank apart: the table must not show both as 13.1."""
    from agents.benchmarking.benchmark import leaderboard_markdown
    entry = dict(task="damping", whirl_rate=0.73, whirl_rate_where_passive_whirls=0.97,
                 force_ratio=0.75, max_force_ratio=1.09, displacement_ratio=0.84,
                 relevitation_rate=None, stator_contact_rate=0.85)
    board = [dict(entry, controller="max-damping", score=13.0809, in_distribution_score=11.444,
                  out_of_distribution_score=13.7),
             dict(entry, controller="ppo-damping", score=13.0749, in_distribution_score=11.436,
                  out_of_distribution_score=None)]
    md = leaderboard_markdown(dict(quick=False, passive_threshold=0.38, phases_deg=[0.0],
                                   episode_time_s=0.3, power_return_s=0.05, leaderboard=board,
                                   rows=[]))
    # no per-drop data: no bootstrap columns' values
    assert "| 1 | max-damping | - | 13.08 | - | - | 11.44 | 13.70 |" in md          # no seat recorded
    assert "| 2 | ppo-damping | - | 13.07 | - | - | 11.44 | - |" in md


def test_a_shipped_policy_trained_on_randomised_scenes_evaluates_fixed(tmp_path):
    """ppo-full carries its training ranges; --fixed must drop them (the env refuses ranges
    without randomize=True) and run the scene as given."""
    out = tmp_path / "ev"
    assert main(["evaluate", "--policy", "ppo-full", "--fixed", "--episodes", "1", "--no-plots",
                 "--no-passive", "--set", "contact.friction=0.3", "--out", str(out)]) == 0
    r = _strict((out / "kpis.json").read_text())
    assert "randomization" not in r["env_kwargs"] and not r["env_kwargs"]["randomize"]
    assert r["episodes"][0]["scenario"]["contact.friction"] == 0.3



def test_a_friction_range_that_is_not_two_numbers_is_a_flag_error(capsys, tmp_path):
    err = _flag_error(["oracle", "--friction", "0.3", "--out", str(tmp_path / "x")], capsys)
    assert err.endswith("argument --friction: expected LO:HI (numbers), got '0.3'")


@pytest.mark.parametrize("argv, message", [
    (["oracle", "--friction", "0.6:0.3", "--no-search"],
     "--friction must be LO:HI with 0 <= LO < HI <= 1, got 0.6:0.3"),
    (["oracle", "--suite", "nominal", "--no-search"],
     "--suite = 'nominal' must be one of robust, full"),
    (["oracle", "--suite", "robust", "--friction", "0.3:0.5", "--no-search"],
     "--friction does not apply to --suite robust (its scenarios are the robust suite's, "
     "friction 0.3-0.6)"),
    (["oracle", "--suite", "robust", "--constant", "0:1.5", "--no-search"],
     "--constant GAIN:OFFSET_R must have both in [-1, 1] (supervisor actions), got 0:1.5"),
    (["train", "--env", "RotorDrop-Relevitate-v1", "--algo", "tqc", "--time-limit", "0"],
     "--time-limit must be a number of seconds > 0, got 0.0")])
def test_a_bad_friction_range_or_time_limit_fails_before_anything_is_written(argv, message, capsys,
                                                                           tmp_path):
    assert main([*argv, "--out", str(tmp_path / "x")]) == 2
    assert capsys.readouterr().err.strip().splitlines()[-1].endswith(message)
    assert not (tmp_path / "x").exists()
