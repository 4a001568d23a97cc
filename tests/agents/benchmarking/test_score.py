"""The benchmark's scores (agents/benchmarking/score.py): the severity score ranks a shorter whirl better,
the legacy score is the verdict-only J to the bit, the paired bootstrap of the leaderboards,
the KPI reward's unsaturated severity term, and one-line errors for a bad --score."""
import numpy as np
import pytest

from agents.benchmarking.benchmark import EPISODE_TIME, Scenario, leaderboard
from agents.benchmarking.score import (SCORES, bootstrap_scores, check_score, drop_costs, overall_score,
                          row_cost)

PASSIVE = dict(backward_whirl=1.0, peak_whirl_revolutions=20.0, peak_contact_force_N=12000.0,
               max_displacement_um=800.0, relevitated=0.0, relevitation_time_s=None)


def _row(revs, whirl=1.0, force=9000.0, disp=650.0, relev=1.0, t=0.08):
    return dict(backward_whirl=whirl, peak_whirl_revolutions=revs, peak_contact_force_N=force,
                max_displacement_um=disp, relevitated=relev, relevitation_time_s=t)


def _old_row_cost(row, passive, episode_time, relevitation):
    """J as the benchmark computed it before the severity score (verbatim)."""
    cost = float(row["backward_whirl"])
    cost += 0.5 * row["peak_contact_force_N"] / max(passive["peak_contact_force_N"], 1e-9)
    cost += 0.5 * row["max_displacement_um"] / max(passive["max_displacement_um"], 1e-9)
    if relevitation:
        rate = row.get("relevitated") or 0.0
        t = row.get("relevitation_time_s")
        cost += (1.0 - rate) + (rate * (t if t is not None else episode_time)
                                + (1.0 - rate) * episode_time) / episode_time
    return cost


@pytest.mark.parametrize("relev", [False, True])
def test_a_whirl_stopped_sooner_scores_better_under_the_severity_score_only(relev):
    short, long = _row(4.0), _row(18.0)              # both whirl (>= 3 revolutions)
    p = row_cost(PASSIVE, PASSIVE, EPISODE_TIME, relev)
    s_short = overall_score([row_cost(short, PASSIVE, EPISODE_TIME, relev)], [p])
    s_long = overall_score([row_cost(long, PASSIVE, EPISODE_TIME, relev)], [p])
    # ½ (18 − 4)/20 of the passive drop's whirl revolutions apart
    assert s_short - s_long == pytest.approx(100.0 * 0.5 * (18.0 - 4.0) / 20.0 / p)
    legacy = [row_cost(r, PASSIVE, EPISODE_TIME, relev, "legacy") for r in (short, long)]
    assert legacy[0] == legacy[1]
    # the passive drop of a whirling scenario costs the same under both scores
    assert row_cost(PASSIVE, PASSIVE, EPISODE_TIME, relev) == pytest.approx(
        row_cost(PASSIVE, PASSIVE, EPISODE_TIME, relev, "legacy"))


def test_the_severity_is_normalised_by_the_passive_drop_at_least_three_revolutions():
    calm = dict(PASSIVE, backward_whirl=0.0, peak_whirl_revolutions=0.1)   # passive rests
    r = _row(1.5, whirl=0.0)
    base = row_cost(r, calm, EPISODE_TIME, False, "legacy")
    assert row_cost(r, calm, EPISODE_TIME, False) == pytest.approx(base + 0.5 * 1.5 / 3.0)


def test_the_legacy_score_is_the_old_cost_bit_for_bit():
    rng = np.random.default_rng(3)
    for _ in range(200):
        relev = bool(rng.integers(2))
        row = _row(rng.uniform(0, 30), whirl=rng.choice([0.0, 0.25, 1.0]),
                   force=rng.uniform(1e3, 2e4), disp=rng.uniform(100, 900),
                   relev=rng.choice([0.0, 0.5, 1.0]), t=rng.choice([None, rng.uniform(0.01, 0.3)]))
        p = _row(rng.uniform(0, 30), force=rng.uniform(1e3, 2e4), disp=rng.uniform(100, 900))
        assert row_cost(row, p, EPISODE_TIME, relev, "legacy") == _old_row_cost(row, p, EPISODE_TIME, relev)


def _drops(revs, whirl, force, disp):
    return dict(backward_whirl=whirl, peak_whirl_revolutions=revs, peak_contact_force_N=force,
                max_displacement_um=disp, relevitated=[True] * len(revs),
                relevitation_time_s=[0.07] * len(revs))


def _means(drops):
    out = {k: float(np.mean(v)) for k, v in drops.items() if k != "relevitation_time_s"}
    out["relevitation_time_s"] = 0.07
    return out


def _rows():
    """Two scenarios x two phases of a re-levitation task: passive and two controllers."""
    spec = {"passive": ([20.0, 22.0, 0.1, 0.2], [1, 1, 0, 0], [12e3, 13e3, 3e3, 3e3], [800, 810, 430, 440]),
            "whirl-brake": ([4.0, 5.0, 0.1, 0.1], [1, 1, 0, 0], [8e3, 9e3, 2e3, 3e3], [600, 650, 400, 420]),
            "ppo-full": ([3.5, 12.0, 0.1, 2.0], [1, 1, 0, 0], [8e3, 8e3, 2e3, 2e3], [600, 640, 400, 400])}
    rows = []
    for name, (revs, whirl, force, disp) in spec.items():
        for j, sc in enumerate(("a", "b")):
            cut = slice(2 * j, 2 * j + 2)
            drops = _drops(revs[cut], whirl[cut], force[cut], disp[cut])
            if name == "passive":
                drops["relevitated"] = [False, False]
                drops["relevitation_time_s"] = [None, None]
            m = _means(drops)
            if name == "passive":
                m["relevitated"], m["relevitation_time_s"] = 0.0, None
            rows.append(dict(m, controller=name, task="full", scenario=sc, group="in-distribution",
                             friction=0.5, stator_contact=0.0, drops=drops))
    return rows


@pytest.mark.parametrize("score", SCORES)
def test_drop_costs_average_to_the_row_cost_and_the_leaderboard_carries_the_bootstrap(score):
    rows = _rows()
    by = {(r["controller"], r["scenario"]): r for r in rows}
    for (name, sc), r in by.items():
        p = by[("passive", sc)]
        assert np.mean(drop_costs(r["drops"], p, EPISODE_TIME, True, score)) == pytest.approx(
            row_cost(r, p, EPISODE_TIME, True, score), rel=1e-12)
    board = {e["controller"]: e for e in leaderboard(rows, [Scenario("a", 0.5), Scenario("b", 0.5)],
                                                      None, score=score)}
    ref = board["whirl-brake"]                   # the only designed row besides passive
    assert all(e["reference"] == "whirl-brake" for e in board.values())
    assert ref["diff_vs_reference"] == 0.0 and ref["diff_se"] == 0.0 and ref["diff_ci95"] == [0.0, 0.0]
    assert board["passive"]["score_se"] == pytest.approx(0.0, abs=1e-9)
    ppo = board["ppo-full"]
    assert ppo["diff_vs_reference"] == pytest.approx(ppo["score"] - ref["score"], abs=1e-9)
    assert ppo["diff_se"] > 0.0 and ppo["diff_ci95"][0] <= ppo["diff_vs_reference"] <= ppo["diff_ci95"][1]


def test_bootstrap_of_a_row_against_itself_and_of_equal_differences_has_no_spread():
    rng = np.random.default_rng(0)
    c = rng.uniform(0.5, 2.0, 50)
    b = bootstrap_scores(np.stack([c, c, c + 0.1]), np.ones(50), reference=0)
    assert b["diff_se"][1] == 0.0 and b["diff"][1] == 0.0
    # with unit passive costs the score difference is −100 × the mean per-drop difference
    assert b["diff_se"][2] == pytest.approx(0.0, abs=1e-9)
    assert b["diff"][2] == pytest.approx(-10.0)
    assert b["score_se"][0] > 0.0


def test_bootstrap_se_of_iid_differences_is_sigma_over_root_n():
    rng = np.random.default_rng(1)
    n, sigma = 400, 0.2
    a = rng.uniform(0.5, 1.5, n)
    b = bootstrap_scores(np.stack([a, a + rng.normal(0.0, sigma, n)]), np.ones(n), reference=0)
    assert b["diff_se"][1] == pytest.approx(100.0 * sigma / np.sqrt(n), rel=0.1)


def test_bootstrap_is_deterministic_and_paired():
    rng = np.random.default_rng(2)
    common = rng.uniform(0.2, 2.0, 60)                 # drop difficulty both rows share
    costs = np.stack([common, common * 0.9 + rng.normal(0, 0.01, 60)])
    p = rng.uniform(1.0, 3.0, 60)                      # passive costs of their own
    one, two = bootstrap_scores(costs, p, 0), bootstrap_scores(costs, p, 0)
    assert all(np.array_equal(one[k], two[k]) for k in one)
    # paired: the difference is far tighter than the scores themselves
    assert one["diff_se"][1] < 0.2 * one["score_se"][1]
    with pytest.raises(ValueError, match="passive"):
        bootstrap_scores(costs, p[:10], 0)


def test_check_score_and_the_cli_name_the_allowed_scores(capsys):
    assert check_score("legacy") == "legacy"
    with pytest.raises(ValueError, match=r"--score = 'sev' must be one of severity, legacy"):
        check_score("sev")
    from agents.cli import main
    assert main(["benchmark", "--score", "sev", "--out", "unused"]) == 2
    err = capsys.readouterr().err.strip()
    assert "--score = 'sev' must be one of severity, legacy" in err and "\n" not in err


def test_the_kpi_reward_charges_whirl_severity_without_saturating():
    from rotordrop_env.reward import KPI_WEIGHTS, kpi_potential
    phi = kpi_potential(np.array([0.0, 3.0, 4.0, 20.0]), 0.0, 0.0, **KPI_WEIGHTS)
    assert phi[0] == 0.0 and np.all(np.diff(phi) > 0.0)
    assert phi[3] - phi[2] == pytest.approx(KPI_WEIGHTS["w_severity"] * 16.0 / KPI_WEIGHTS["whirl_ref_revs"])
    old = dict(KPI_WEIGHTS, w_whirl=1.0, w_severity=0.0)      # the former default: saturates
    assert kpi_potential(4.0, 0.0, 0.0, **old) == kpi_potential(20.0, 0.0, 0.0, **old)


def test_the_legacy_score_reproduces_a_benchmark_run_before_the_severity_score():
    """The rows and scores of a `benchmark --quick` run made before the severity score: the
    legacy leaderboard gives the very same floats (JSON keeps them exactly)."""
    import json
    from pathlib import Path
    d = json.loads((Path(__file__).resolve().parents[2] / "data" / "benchmark-quick-legacy.json").read_text())
    board = leaderboard(d["rows"], [], d["passive_threshold"], score="legacy")
    new = {(e["task"], e["controller"]): e["score"] for e in board}
    assert {(e["task"], e["controller"]): e["score"] for e in d["scores"]} == new
    severity = leaderboard(d["rows"], [], d["passive_threshold"])
    assert {(e["task"], e["controller"]): e["score"] for e in severity} != new


def test_the_severity_reference_must_be_positive():
    from rotordrop_env.reward import check_kpi_weights
    with pytest.raises(ValueError, match=r"reward_kwargs.whirl_ref_revs must be a finite number > 0"):
        check_kpi_weights({"whirl_ref_revs": 0.0})
    assert check_kpi_weights({"w_severity": 0.0})["w_severity"] == 0.0
