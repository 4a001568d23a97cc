"""``rotordrop evaluate`` and ``rotordrop benchmark`` end to end on tiny settings."""
import json

import pytest

from agents.control.controllers import BASELINES

from agents.cli import main


def test_evaluate_a_baseline_against_passive(tmp_path):
    """At mu = 0.1 the rotor rests at the bottom and never orbits backwards, so the whirl
    switch never leaves the passive damping: its episode is the passive drop, KPI for KPI."""
    out = tmp_path / "ev"
    assert main(["evaluate", "--policy", "whirl-switch", "--env", "RotorDrop-Damping-v1",
                 "--episodes", "1", "--fixed", "--set", "contact.friction=0.1",
                 "--out", str(out)]) == 0
    r = json.loads((out / "kpis.json").read_text())
    mine, passive = r["episodes"][0], r["passive_episodes"][0]
    assert not mine["backward_whirl"] and not passive["backward_whirl"]
    assert mine["peak_contact_force_N"] == pytest.approx(passive["peak_contact_force_N"], rel=1e-9)
    assert mine["max_displacement_um"] == pytest.approx(passive["max_displacement_um"], rel=1e-9)
    assert r["env_kwargs"]["overrides"] == {"contact.friction": 0.1}
    for f in ("orbits.png", "contact_force.png"):
        assert (out / f).is_file()


def test_evaluate_errors_name_the_problem(tmp_path, capsys):
    assert main(["evaluate", "--policy", "no-such-policy", "--env", "RotorDrop-Damping-v1",
                 "--out", str(tmp_path)]) == 2
    assert "max-damping" in capsys.readouterr().err          # the known names are listed
    assert main(["evaluate", "--policy", "passive", "--out", str(tmp_path)]) == 2
    assert "--env is required" in capsys.readouterr().err
    assert main(["evaluate", "--policy", "max-damping", "--env", "RotorDrop-Relevitate-v1",
                 "--out", str(tmp_path)]) == 2
    assert "needs action channels" in capsys.readouterr().err


def test_benchmark_quick_end_to_end(tmp_path):
    out = tmp_path / "bench"
    assert main(["benchmark", "--quick", "--scenarios", "2", "--episodes", "1", "--quiet",
                 "--out", str(out)]) == 0
    rep = json.loads((out / "benchmark.json").read_text())
    sweep = rep["threshold_sweep"]
    mu_star, fr = rep["passive_threshold"], sweep["whirl_fraction"]
    # the paper's whirl threshold lies between mu 0.25 and 0.5 (spec §7)
    assert mu_star is not None and 0.25 < mu_star < 0.5
    i = sweep["grid"].index(mu_star)      # the documented rule: whirls from mu* on, not below it
    assert all(f >= 0.5 for f in fr[i:]) and (i == 0 or fr[i - 1] < 0.5)
    assert rep["scenarios"][0]["friction"] == pytest.approx(mu_star + 0.05)
    keys = {"controller", "scenario", "friction", "backward_whirl", "peak_contact_force_N",
            "max_displacement_um", "max_contact_pressure_MPa"}
    for row in rep["rows"]:
        assert keys <= set(row)
        assert row["episodes"] == 1
        assert 100.0 < row["max_contact_pressure_MPa"] < 4200.0     # below the ISO 76 C_0 level
    board = {(e["task"], e["controller"]): e for e in rep["leaderboard"]}
    for task in ("damping", "relevitate"):
        assert board[(task, "passive")]["score"] == pytest.approx(0.0)
        # the passive whirl (orbit ~800 um) passes the 600 um AMB gap; the flag latches to the end
        passive = [r for r in rep["rows"] if r["task"] == task and r["controller"] == "passive"]
        assert all(r["backward_whirl"] == 1.0 and r["stator_contact"] == 1.0 for r in passive)
        assert board[(task, "passive")]["stator_contact_rate"] == 1.0
    assert {("damping", "max-damping"), ("damping", "whirl-switch"), ("relevitate", "pid-relevitate"),
            ("relevitate", "builtin-relevitate")} <= set(board)
    # learned controllers are named after their algorithm
    for task, name in board:
        if name not in BASELINES:
            assert name.split("-")[0] in ("ppo", "sac", "td3")
    md = (out / "leaderboard.md").read_text()
    assert "| max-damping |" in md and "mu*" in md
    for f in ("score.png", "whirl_map.png", "peak_force.png"):
        assert (out / f).is_file()


def test_evaluate_a_current_commanding_baseline_in_the_relevitation_env(tmp_path):
    """whirl-brake commands currents: evaluate gives the env the command it needs."""
    out = tmp_path / "ev"
    assert main(["evaluate", "--policy", "whirl-brake", "--env", "RotorDrop-Relevitate-v1",
                 "--episodes", "1", "--fixed", "--no-plots", "--no-passive",
                 "--set", "contact.friction=0.25", "--out", str(out)]) == 0
    r = json.loads((out / "kpis.json").read_text())
    assert r["env_kwargs"]["command"] == "continuous"
    assert r["episodes"][0]["relevitated"]


def test_ride_through_times_take_the_unbroken_run_of_safe_delays():
    import numpy as np
    from agents.benchmarking.ride_through import ride_through_times
    delays = (0.0, 0.02, 0.04, 0.06)
    revs = np.array([[0.1, 0.2, 0.3, 0.4],        # safe throughout
                     [0.1, 3.2, 0.3, 0.4],        # a whirl at 20 ms: later luck does not count
                     [3.1, 0.1, 0.1, 0.1],        # whirls even at once
                     [0.1, 0.2, 0.3, 0.4]])
    relev = np.ones_like(revs)
    relev[3, 2] = 0.5                             # one phase not re-levitated at 40 ms
    assert ride_through_times(revs, relev, delays, 3.0) == [0.06, 0.0, None, 0.02]


def test_ride_through_early_power_stops_the_whirl_late_power_does_not(tmp_path):
    """At mu = 0.5 the passive drop whirls; whirl-brake prevents it when the power is back
    at once and cannot when it comes back after 100 ms (about 5 revolutions by then)."""
    out = tmp_path / "rt"
    assert main(["ride-through", "--policy", "whirl-brake", "--friction", "0.5",
                 "--delay-ms", "0", "--delay-ms", "100", "--phase", "0", "--quiet",
                 "--out", str(out)]) == 0
    r = json.loads((out / "ride_through.json").read_text())
    m = r["controllers"]["whirl-brake"]
    (early, late), = m["peak_whirl_revolutions"]
    assert early < 1.0 and late >= r["whirl_revolutions"]
    assert m["relevitated"] == [[1.0, 1.0]]
    assert m["ride_through_s"] == [0.0]
    assert r["passive"]["backward_whirl"] == [1.0]
    rows = (out / "ride_through.csv").read_text().splitlines()
    assert len(rows) == 1 + 2 + 1                 # header, 2 cells, the passive reference
    assert (out / "ride_through.png").is_file()


def test_ride_through_errors_name_the_option(tmp_path, capsys):
    assert main(["ride-through", "--friction", "-0.1", "--out", str(tmp_path)]) == 2
    assert "--friction" in capsys.readouterr().err
    assert main(["ride-through", "--delay-ms", "-5", "--out", str(tmp_path)]) == 2
    assert "--delay-ms values [-5.0]" in capsys.readouterr().err        # in the unit typed
    assert main(["ride-through", "--env", "RotorDrop-Damping-v1", "--out", str(tmp_path)]) == 2
    assert "re-levitation environment" in capsys.readouterr().err
    assert main(["ride-through", "--policy", "ppo-damping", "--out", str(tmp_path)]) == 2
    assert "trained on RotorDrop-Damping-v1" in capsys.readouterr().err
    assert main(["ride-through", "--policy", "agents.benchmarking.plots:_plt", "--out", str(tmp_path)]) == 2
    assert "not a subclass" in capsys.readouterr().err


def test_ride_through_cells_of_single_value_grids_have_a_width():
    from agents.benchmarking.plots import _cell_edges
    assert _cell_edges([0.5], 0.05) == pytest.approx([0.475, 0.525])
    assert _cell_edges([0.0, 40.0, 100.0], 10.0) == pytest.approx([-20.0, 20.0, 70.0, 130.0])


USER_CONTROLLER = '''
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from agents.control.controllers import Controller


@dataclass
class Level:                    # a dataclass needs its module in sys.modules while it is made
    value: float = 0.0


class MidDamping(Controller):
    """Constant damping halfway between C_min and C_max."""
    name = "mid-damping"
    needs = ("damping",)

    def commands(self, obs):
        return {"damping": np.full((len(obs), 2), Level().value)}


class SameName(MidDamping):
    """Another class that keeps the name mid-damping."""


class NotAController:
    pass
'''


def test_a_users_controller_class_is_evaluated_and_benchmarked_like_a_baseline(tmp_path, capsys,
                                                                               monkeypatch):
    from agents.benchmarking.benchmark import _entries
    from agents.control.controllers import load_controller
    path = tmp_path / "my_controllers.py"
    path.write_text(USER_CONTROLLER)
    spec = f"{path}:MidDamping"
    out = tmp_path / "ev"
    assert main(["evaluate", "--policy", spec, "--env", "RotorDrop-Damping-v1", "--episodes", "1",
                 "--fixed", "--no-plots", "--set", "contact.friction=0.1", "--out", str(out)]) == 0
    r = json.loads((out / "kpis.json").read_text())
    assert r["policy"] == "mid-damping"
    # a damper between C_s = 5000 and C_max = 27 900 N s/m: first impact softer than passive
    assert r["episodes"][0]["peak_contact_force_N"] < r["passive_episodes"][0]["peak_contact_force_N"]
    tasks = {e.task for e in _entries([], [load_controller(spec)]) if e.name == "mid-damping"}
    assert tasks == {"damping", "full"}                  # not in relevitate: it has no damper
    monkeypatch.chdir(tmp_path)                          # module:Class finds modules next to you
    assert load_controller("my_controllers:MidDamping").name == "mid-damping"
    monkeypatch.setattr("agents.benchmarking.benchmark.passive_threshold", None)      # fails before it
    assert main(["benchmark", "--quick", "--quiet", "--policy", spec, "--policy",
                 f"{path}:SameName", "--out", str(tmp_path / "b")]) == 2
    assert "two controllers are named mid-damping" in capsys.readouterr().err
    for bad, words in ((f"{path}:NotAController", "not a subclass"),
                       (f"{path}:Missing", "has no 'Missing'"),
                       ("no_such_module_xyz:Ctrl", "cannot import"),
                       (f"{tmp_path}/absent.py:Ctrl", "no file")):
        assert main(["evaluate", "--policy", bad, "--env", "RotorDrop-Damping-v1",
                     "--out", str(tmp_path / "x")]) == 2
        assert words in capsys.readouterr().err


def test_benchmark_power_return_applies_to_every_scenario_without_its_own():
    from agents.benchmarking.benchmark import _group, scenario_suite
    suite = scenario_suite(0.38, power_return=0.04)
    late = [s for s in suite if s.name == "power back at 0.15 s"]
    assert late and late[0].env_kwargs == {"power_return_time": 0.15}
    assert all(s.env_kwargs == {"power_return_time": 0.04} for s in suite if s not in late)
    assert all(s.env_kwargs == {} for s in scenario_suite(0.38) if s.name != late[0].name)
    # a power return outside the training range makes a scenario out-of-distribution only in
    # the tasks that have a power return
    first = scenario_suite(0.38, power_return=0.0)[0]
    assert _group(first) == "out-of-distribution" and _group(first, "damping") == "in-distribution"


def test_runs_of_one_policy_get_labels_that_tell_them_apart(tmp_path, monkeypatch):
    from agents.learning.policies import run_label
    assert run_label("runs/s1/best/best_model.zip") == "s1/best"
    assert run_label("runs/s2/best/best_model.zip") == "s2/best"
    assert run_label("runs/s1/model.zip") == run_label("runs/s1") == run_label("runs/s1/") == "s1"
    assert run_label("x/ppo-7.zip") == "ppo-7"
    monkeypatch.chdir(tmp_path)                      # inside the run directory: never empty
    assert run_label("model.zip") == run_label(".") == tmp_path.name
    assert run_label("best/best_model.zip") == f"{tmp_path.name}/best"


def test_evaluate_at_a_given_power_return(tmp_path, capsys):
    """--power-return-ms fixes the delay (also out of the randomisation); power back at once
    re-levitates sooner than the default 50 ms."""
    times = {}
    for ms in ("0", "50"):
        out = tmp_path / ms
        assert main(["evaluate", "--policy", "whirl-brake", "--env", "RotorDrop-Relevitate-v1",
                     "--episodes", "1", "--no-plots", "--no-passive", "--power-return-ms", ms,
                     "--set", "contact.friction=0.25", "--out", str(out)]) == 0
        r = json.loads((out / "kpis.json").read_text())
        assert r["env_kwargs"]["power_return_time"] == float(ms) * 1e-3
        assert r["env_kwargs"]["randomization"]["power_return_time"] is None
        times[ms] = r["episodes"][0]["relevitation_time_s"]
    assert times["0"] < times["50"] - 0.03
    assert main(["evaluate", "--policy", "max-damping", "--env", "RotorDrop-Damping-v1",
                 "--power-return-ms", "30", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "--power-return-ms" in err and "re-levitation environments" in err


LEVEL_CONTROLLER = '''
import numpy as np
from agents.control.controllers import Controller


class Level(Controller):
    """Constant damper command ``level`` in [-1, 1] (-1 = C_min, +1 = C_max)."""
    name = "level-damping"
    needs = ("damping",)
    GAINS = {"level": 0.0}

    def __init__(self, plant, level=0.0):
        super().__init__(plant)
        self.level = level

    def commands(self, obs):
        return {"damping": np.full((len(obs), 2), self.level)}


class Required(Level):
    """The same with a gain that has no default."""
    GAINS = {}

    def __init__(self, plant, level):
        super().__init__(plant, level)
'''


def test_tune_moves_a_damper_level_towards_more_damping(tmp_path, capsys):
    """Between C_min and C_max more damping scores better (it holds the whirl off longer), so
    the search must raise the level from its start at mid-range; the reported validation score
    is what the validator gives for the reported gains."""
    from agents.benchmarking.benchmark import Validator
    from agents.control.controllers import load_controller
    path = tmp_path / "level.py"
    path.write_text(LEVEL_CONTROLLER)
    spec = f"{path}:Level"
    out = tmp_path / "tune"
    assert main(["tune", "--policy", spec, "--env", "RotorDrop-Damping-v1", "--gain", "level=-1:1",
                 "--iterations", "3", "--population", "6", "--elite", "2", "--quiet",
                 "--out", str(out)]) == 0
    r = json.loads((out / "tune.json").read_text())
    assert r["start"] == {"level": 0.0}
    assert r["gains"]["level"] > 0.1
    assert r["validation_score"] > r["start_validation_score"]
    from agents.control.controllers import controller_env_kwargs
    cls = load_controller(spec)                                     # in its seat (0.2 ms)
    again, _ = Validator("RotorDrop-Damping-v1").score(
        lambda plant: cls(plant, level=r["gains"]["level"]),
        controller_env_kwargs(cls, "RotorDrop-Damping-v1"))
    assert again == pytest.approx(r["validation_score"], rel=1e-12)
    assert (out / "tune.png").is_file()
    # a gain without a default starts mid-range (and the checks build it with that value)
    assert main(["tune", "--policy", f"{path}:Required", "--env", "RotorDrop-Damping-v1",
                 "--gain", "level=0:1", "--iterations", "0", "--quiet", "--no-plots",
                 "--out", str(tmp_path / "req")]) == 0
    assert json.loads((tmp_path / "req" / "tune.json").read_text())["start"] == {"level": 0.5}
    for bad, words in ((["--gain", "level=1:-1"], "LO < HI"),
                       (["--gain", "gamma=0:1"], "does not take the gains"),
                       (["--gain", "level=0:1", "--population", "2", "--elite", "3"],
                        "--elite = 3 must be <= --population = 2"),
                       ([], "--gain is required")):
        assert main(["tune", "--policy", spec, "--env", "RotorDrop-Damping-v1", *bad,
                     "--out", str(tmp_path / "x")]) == 2
        assert words in capsys.readouterr().err
    assert main(["tune", "--policy", "ppo-damping", "--env", "RotorDrop-Damping-v1",
                 "--gain", "a=0:1", "--out", str(tmp_path / "x")]) == 2
    assert "not a learned policy" in capsys.readouterr().err


def test_tune_json_holds_what_recomputes_its_validation_score(tmp_path):
    """The passive rows are in tune.json: J and the score follow from the file alone."""
    from agents.benchmarking.benchmark import EPISODE_TIME
    from agents.benchmarking.score import overall_score, row_cost
    out = tmp_path / "tune"
    assert main(["tune", "--policy", "whirl-brake", "--env", "RotorDrop-Relevitate-v1",
                 "--gain", "kp=0.8:0.9", "--iterations", "0", "--quiet", "--no-plots",
                 "--out", str(out)]) == 0
    r = json.loads((out / "tune.json").read_text())
    passive = {p["scenario"]: p for p in r["passive_rows"]}
    assert set(passive) == {x["scenario"] for x in r["rows"]} and len(passive) == 5
    costs = [row_cost(x, passive[x["scenario"]], EPISODE_TIME, True) for x in r["rows"]]
    p_costs = [row_cost(p, p, EPISODE_TIME, True) for p in passive.values()]
    assert [x["cost"] for x in r["rows"]] == pytest.approx(costs, rel=1e-12)
    assert [p["cost"] for p in passive.values()] == pytest.approx(p_costs, rel=1e-12)
    assert overall_score(costs, p_costs) == pytest.approx(r["validation_score"], rel=1e-12)


def test_evaluate_actions_are_named_and_the_planes_tell_apart(tmp_path, monkeypatch):
    """actions.png: the legend names the actions (it said action[0..5]), and the plane-1 and
    plane-2 lines of a channel share a colour but not a line style (whirl-brake commands
    equal currents and dampers in both planes: one line hid the other)."""
    import agents.benchmarking.plots as plots
    seen = {}
    finish = plots._finish_time_plot

    def spy(plt, fig, ax, ylabel, title, path):
        seen[path.name] = {line.get_label(): (line.get_color(), line.get_linestyle())
                           for line in ax.get_lines()}
        return finish(plt, fig, ax, ylabel, title, path)
    monkeypatch.setattr(plots, "_finish_time_plot", spy)
    assert main(["evaluate", "--policy", "whirl-brake", "--env", "RotorDrop-Full-v1", "--episodes",
                 "1", "--fixed", "--no-passive", "--set", "contact.friction=0.45",
                 "--out", str(tmp_path / "ev")]) == 0
    lines = seen["actions.png"]
    assert list(lines) == ["damping1", "damping2", "current_amb1_x", "current_amb1_y",
                           "current_amb2_x", "current_amb2_y"]
    for one, two in (("damping1", "damping2"), ("current_amb1_x", "current_amb2_x"),
                     ("current_amb1_y", "current_amb2_y")):
        assert lines[one][0] == lines[two][0] and lines[one][1] != lines[two][1]
    assert len({color for color, _ in lines.values()}) == 3
