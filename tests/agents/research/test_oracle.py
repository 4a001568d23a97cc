"""``rotordrop oracle``: command sequences of the supervisor interface, their batched rollouts,
and a search that can only improve on the inner-loop row it starts from."""
import json

import numpy as np
import pytest

from agents.benchmarking.benchmark import Entry, episode_kwargs
from agents.control.controllers import InnerLoop
from agents.research.oracle import (CONTROL_DT, ENV_ID, MAX_DELAY, as_benchmark, draw_scenarios,
                           inner_loop_theta, kpi_row, n_params, oracle, rollout,
                           sequence_actions)
from agents.benchmarking.rollout import run_episodes

NAMES = ["damping1", "damping2", "levitate", "gain", "offset_r1", "offset_t1", "offset_r2",
         "offset_t2"]


def test_sequence_actions_switch_on_after_power_and_delay():
    theta = np.stack([inner_loop_theta(), inner_loop_theta()])
    theta[1, -1] = 1.0                                   # the longest switch-on delay
    before = sequence_actions(theta, 0.029, 0.03, NAMES)
    after = sequence_actions(theta, 0.03, 0.03, NAMES)
    late = sequence_actions(theta, 0.03 + MAX_DELAY, 0.03, NAMES)
    lev = NAMES.index("levitate")
    assert list(before[:, lev]) == [-1.0, -1.0]
    assert list(after[:, lev]) == [1.0, -1.0] and list(late[:, lev]) == [1.0, 1.0]
    np.testing.assert_array_equal(after[:, :2], 1.0)     # C_max
    np.testing.assert_array_equal(after[:, 3:], 0.0)     # nominal gain, no offsets
    assert theta.shape[1] == n_params()


def test_segments_follow_the_edges():
    theta = np.zeros((1, n_params()))
    theta[0, :-1] = np.repeat(np.arange(n_params() - 1) // 7, 1) / 10.0   # segment index / 10
    for t, seg in ((0.0, 0), (0.0099, 0), (0.01, 1), (0.05, 4), (0.2, 6)):
        a = sequence_actions(theta, t, 0.05, NAMES)
        assert a[0, NAMES.index("gain")] == pytest.approx(seg / 10.0), t


def test_batched_rollout_of_the_inner_loop_sequence_is_the_inner_loop_row():
    from rotordrop_env import BatchedRotorDropVecEnv
    values = draw_scenarios(1)[0]
    sc, phase = as_benchmark(values, "#0")
    entry = Entry("inner-loop", "full", InnerLoop,
                  {"command": "supervisor", "control_dt": CONTROL_DT})
    kw = episode_kwargs(entry, sc, phase)
    venv = BatchedRotorDropVecEnv(ENV_ID, 2, seed=0, **kw)
    rows = [kpi_row(k) for k in rollout(venv, np.stack([inner_loop_theta()] * 2), sc.env_kwargs[
        "power_return_time"], sc.seed)]
    ref = kpi_row(run_episodes(ENV_ID, InnerLoop, [sc.seed], kw)[0].kpis)
    assert rows[0] == rows[1] == ref


def test_oracle_never_worse_than_its_start_and_resumes(tmp_path):
    rep = oracle(tmp_path, scenarios=1, population=4, iterations=1, progress=False, plots=False)
    s = rep["per_scenario"][0]
    assert s["search"]["start"] == inner_loop_theta().tolist()      # by default from inner-loop
    assert s["rows"]["oracle"]["J"] <= s["search"]["start_J"]
    # the same commands at a 1 ms control step: the same drop up to the integrator's segments
    assert s["search"]["start_J"] == pytest.approx(s["rows"]["inner-loop"]["J"], rel=1e-3)
    assert s["scenario"]["power_return_time"] * 200 == pytest.approx(
        round(s["scenario"]["power_return_time"] * 200))                # on the 5 ms grid
    names = [e["controller"] for e in rep["summary"]]
    assert {"oracle", "passive", "inner-loop", "whirl-brake-sup", "whirl-brake"} <= set(names)
    assert next(e for e in rep["summary"] if e["controller"] == "passive")["score"] == 0.0
    saved = json.loads((tmp_path / "oracle.json").read_text())
    again = oracle(tmp_path, scenarios=1, population=4, iterations=1, progress=False, plots=False)
    assert again["per_scenario"][0]["search"] == saved["per_scenario"][0]["search"]     # reused


def test_every_oracle_row_has_its_bootstrap_se_against_the_best_designed_row(tmp_path):
    """Paired bootstrap over the drops (the leaderboards' resamples and seed); the budget sweep's
    row of the results page reads the same fields."""
    from agents.benchmarking.results import budget_run, oracle_budget_section
    from agents.benchmarking.score import bootstrap_scores
    rep = oracle(tmp_path, scenarios=3, population=4, iterations=1, progress=False, plots=False)
    ref = rep["best_designed"]
    rows = {e["controller"]: e for e in rep["summary"]}
    assert all(e["reference"] == ref for e in rep["summary"])
    assert rows[ref]["diff_vs_reference"] == 0.0 and rows[ref]["diff_se"] == 0.0
    names = list(rows)
    costs = [[d["rows"][n]["J"] for d in rep["per_scenario"]] for n in names]
    passive = [d["rows"]["passive"]["J"] for d in rep["per_scenario"]]
    b = bootstrap_scores(costs, passive, names.index(ref))
    i = names.index("oracle")
    assert rows["oracle"]["score_se"] == pytest.approx(b["score_se"][i]) and b["score_se"][i] > 0
    assert rows["oracle"]["diff_vs_reference"] == pytest.approx(rows["oracle"]["score"]
                                                                - rows[ref]["score"])
    lo, hi = rows["oracle"]["diff_ci95"]
    assert lo <= rows["oracle"]["diff_vs_reference"] <= hi
    run = budget_run(rep)
    assert run["rollouts_per_drop"] == 5 and run["scenarios"] == 3
    assert run["unchanged"] == sum(d["search"]["J"] >= d["search"]["start_J"]
                                   for d in rep["per_scenario"])
    assert "| 4 × 1 | 5 |" in "\n".join(oracle_budget_section({"runs": [run]}, "x"))


def test_rows_only_on_other_scenarios(tmp_path):
    rep = oracle(tmp_path, scenarios=2, search=False, scenario_seed=20_000, progress=False,
                 plots=True)
    names = [e["controller"] for e in rep["summary"]]
    assert "oracle" not in names and "inner-loop" in names
    assert rep["oracle_gain_over_best_designed"] is None
    assert rep["per_scenario"][0]["scenario"] == draw_scenarios(1, 20_000)[0]
    assert (tmp_path / "oracle.png").is_file()


def test_whirl_by_friction_bins_the_scenarios():
    from agents.research.oracle import whirl_by_friction
    per = [dict(scenario={"contact.friction": mu}, rows={"a": {"backward_whirl": w}})
           for mu, w in ((0.39, 1.0), (0.40, 0.0), (0.52, 1.0), (0.60, 1.0))]
    t = whirl_by_friction(dict(per_scenario=per, summary=[{"controller": "a"}]))
    assert t["counts"] == [2, 0, 1, 1]                  # 0.60 falls in the last bin
    assert t["rates"]["a"] == [0.5, None, 1.0, 1.0]


def test_a_friction_range_draws_there_and_bins_its_whirl_table(tmp_path, capsys):
    """--friction 0.3:0.36: every scenario's mu in the range (the other draws as before), the
    per-friction table on the given edges, printed; a bad range or bad edges fail at once."""
    from agents.research.oracle import friction_edges
    wide, low = draw_scenarios(8, 20_000), draw_scenarios(8, 20_000, (0.3, 0.36))
    assert all(0.3 <= s["contact.friction"] <= 0.36 for s in low)
    assert [s["power_return_time"] for s in low] == [s["power_return_time"] for s in wide]
    rep = oracle(tmp_path, scenarios=3, search=False, scenario_seed=20_000, progress=False,
                 plots=False, friction=(0.3, 0.36), friction_bins=(0.3, 0.33, 0.36))
    assert rep["settings"]["ranges"]["contact.friction"] == [0.3, 0.36]
    table = rep["whirl_by_friction"]
    assert table["edges"] == [0.3, 0.33, 0.36] and sum(table["counts"]) == 3
    assert "| drops |" in capsys.readouterr().out
    lines = (tmp_path / "whirl_by_friction.csv").read_text().splitlines()
    assert lines[0] == "controller,mu_lo,mu_hi,drops,whirls,whirl_rate"
    assert len(lines) == 1 + 2 * len(table["rates"])               # a line per row and bin
    assert friction_edges((0.3, 0.6)) == (0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6)
    assert friction_edges((0.38, 0.6)) == (0.38, 0.44, 0.5, 0.55, 0.6)       # the default's bins
    with pytest.raises(ValueError, match=r"--friction must be LO:HI with 0 <= LO < HI <= 1, got 0.5:0.3"):
        oracle(tmp_path / "bad", scenarios=1, search=False, friction=(0.5, 0.3))
    with pytest.raises(ValueError, match="--friction-bins must be increasing edges from 0.3 to 0.6"):
        oracle(tmp_path / "bad", scenarios=1, search=False, friction=(0.3, 0.6),
               friction_bins=(0.3, 0.5, 0.4, 0.6))
    assert not (tmp_path / "bad").exists()                    # nothing written


def test_robust_suite_searches_the_robust_scenario_with_its_sensing(tmp_path):
    """--suite robust: the robust suite's first scenario (seed SUITE_SEED), its plant spread,
    noise and latency in the oracle's rollouts and the rows, the rows' J as the robust
    benchmark scores them; the oracle never scores worse than inner-loop there."""
    from agents.benchmarking.benchmark import leaderboard, suite_rows
    from agents.control.controllers import Passive
    from agents.research.oracle import search_kwargs, suite_scenarios
    from agents.benchmarking.robust import SENSOR_DELAY_S, SENSOR_NOISE, SUITE_SEED, draw_scenario
    from rotordrop_env import BatchedRotorDropVecEnv
    sc, phase, record = suite_scenarios("robust", 1, SUITE_SEED)[0]
    assert sc == draw_scenario(SUITE_SEED, "#0")
    kw = search_kwargs(sc, phase)
    venv = BatchedRotorDropVecEnv(ENV_ID, 1, seed=0, **kw)
    venv.reset()
    env = venv.envs[0]
    assert env.sensor_noise == SENSOR_NOISE == record["sensor_noise"]
    assert env._sensing.k == int(np.ceil(sc.latency_s / CONTROL_DT - 1e-9))          # 0-1 ms
    lo, hi = SENSOR_DELAY_S                     # the sensor delay every controller sees
    assert lo <= env.scene.sensor.delay == sc.overrides["sensor.delay"] <= hi
    assert env.scene.amb.current_limit == pytest.approx(sc.overrides["amb.current_limit"])
    assert env.scene.amb.coil_time_constant == pytest.approx(
        sc.overrides["amb.coil_time_constant"])
    venv.close()

    rep = oracle(tmp_path, scenarios=1, population=4, iterations=1, progress=False, plots=False,
                 suite="robust", constants=[(0.0, 0.0), (0.0, -0.75)], start_from_constants=True)
    assert rep["settings"]["suite"] == "robust" and rep["settings"]["scenario_seed"] == SUITE_SEED
    s = rep["per_scenario"][0]
    assert s["scenario"] == record
    rows = s["rows"]
    assert rows["oracle"]["J"] <= rows["inner-loop"]["J"] * (1 + 1e-3)
    score = {e["controller"]: e["score"] for e in rep["summary"]}
    assert score["oracle"] >= score["inner-loop"] - 0.1
    assert {"whirl-brake-robust", "sac-robust-full-scratch"} <= set(score)
    # the constant law g = 0, r = 0 is the inner-loop sequence (here at a 5 ms control step);
    # started from the best constant law, the oracle is never worse than any of them
    assert rows["constant g=0 r=0"]["J"] == pytest.approx(rows["inner-loop"]["J"], rel=1e-3)
    assert rows["oracle"]["J"] <= min(rows["constant g=0 r=0"]["J"],
                                      rows["constant g=0 r=-0.75"]["J"])
    assert rep["settings"]["search_start"] == ["inner-loop", [0.0, 0.0], [0.0, -0.75]]
    assert rep["constant_rows"] == ["constant g=0 r=0", "constant g=0 r=-0.75"]
    assert "constant g=0 r=-0.75" not in rep["learned"]
    # the rows are the robust benchmark's own episodes of the scenario
    bench = suite_rows(Entry("passive", "full", Passive, {}), [sc], (0.0,)) + suite_rows(
        Entry("inner-loop", "full", InnerLoop, {"command": "supervisor"}), [sc], (0.0,))
    leaderboard(bench, [sc], None, any_friction=True)
    assert bench[1]["cost"] == pytest.approx(rows["inner-loop"]["J"], rel=1e-9)
    with pytest.raises(ValueError, match="--suite = 'nominal' must be one of robust, full"):
        oracle(tmp_path / "bad", scenarios=1, suite="nominal")
    with pytest.raises(ValueError, match=r"--constant GAIN:OFFSET_R must have both in \[-1, 1\]"):
        oracle(tmp_path / "bad", scenarios=1, suite="robust", constants=[(0.0, -1.5)])
    with pytest.raises(ValueError, match="--start-from-constants needs at least one --constant"):
        oracle(tmp_path / "bad", scenarios=1, suite="robust", start_from_constants=True)
    assert not (tmp_path / "bad").exists()


def test_inner_loop_lift_is_the_oracles_constant_row(tmp_path):
    """On a robust drop: the oracle's --constant row with inner-loop-lift's constants tuned on
    the robust validation drops is inner-loop-lift there (same J), and the same law as the
    search's command sequence (constant_theta, batched rollout at 5 ms) runs the same drop to
    the last digit."""
    from agents.benchmarking.benchmark import controller_entry
    from agents.benchmarking.suites import SUITES
    from agents.benchmarking.tuned import tuned_gains
    from agents.control.controllers import InnerLoopLift
    from agents.research.oracle import constant_name, constant_theta, search_kwargs, suite_scenarios
    from rotordrop_env import BatchedRotorDropVecEnv
    g = tuned_gains(SUITES.get("robust"), "inner-loop-lift", ENV_ID)
    rep = oracle(tmp_path, scenarios=1, search=False, suite="robust",
                 constants=[(g["gain"], g["offset_r"])], progress=False, plots=False)
    rows = rep["per_scenario"][0]["rows"]
    assert rows[constant_name(g["gain"], g["offset_r"])] == rows["inner-loop-lift"]
    assert rows["inner-loop-lift"]["J"] < rows["inner-loop"]["J"]      # re-levitates sooner
    sc, phase, _ = suite_scenarios("robust", 1, 30_000)[0]
    venv = BatchedRotorDropVecEnv(ENV_ID, 1, seed=0, **search_kwargs(sc, phase))
    seq = kpi_row(rollout(venv, constant_theta(0.5, -0.5)[None], sc.env_kwargs[
        "power_return_time"], sc.seed)[0])
    venv.close()
    entry = controller_entry(InnerLoopLift, ENV_ID)
    ctrl = kpi_row(run_episodes(ENV_ID, entry.make, [sc.seed], episode_kwargs(entry, sc, phase))[0].kpis)
    assert seq == ctrl


def test_the_raw_current_oracle_searches_whirl_brake_corrections_and_never_loses_to_it(tmp_path):
    """--interface currents: open-loop corrections of whirl-brake's coil currents, started from
    no correction, so the searched plan's J is at most whirl-brake's on every drop."""
    from agents.research.oracle import oracle
    rep = oracle(tmp_path, scenarios=1, population=3, iterations=1, progress=False, plots=False,
                 interface="currents")
    assert rep["settings"]["interface"] == "currents"
    s = rep["per_scenario"][0]
    assert s["rows"]["oracle"]["J"] <= s["rows"]["whirl-brake"]["J"] + 1e-12
    assert s["search"]["rollouts"] >= 4 and np.shape(s["search"]["theta"]) == (16, 4)
    with pytest.raises(ValueError, match=r"--interface = 'x' must be one of supervisor, currents"):
        oracle(tmp_path, interface="x")
