"""``rotordrop evaluate`` and ``rotordrop benchmark`` end to end on tiny settings."""
import json

import pytest

from agents.controllers import BASELINES

from physics.cli import main


def test_evaluate_a_baseline_against_passive(tmp_path):
    """At mu = 0.1 the rotor rests at the bottom and never orbits backwards, so the whirl
    switch never leaves the passive damping: its episode is the passive drop, KPI for KPI."""
    out = tmp_path / "ev"
    assert main(["evaluate", "--policy", "whirl-switch", "--env", "RotorDrop-Damping-v0",
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
    assert main(["evaluate", "--policy", "no-such-policy", "--env", "RotorDrop-Damping-v0",
                 "--out", str(tmp_path)]) == 2
    assert "max-damping" in capsys.readouterr().err          # the known names are listed
    assert main(["evaluate", "--policy", "passive", "--out", str(tmp_path)]) == 2
    assert "--env is required" in capsys.readouterr().err
    assert main(["evaluate", "--policy", "max-damping", "--env", "RotorDrop-Relevitate-v0",
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
            "max_displacement_um"}
    for row in rep["rows"]:
        assert keys <= set(row)
        assert row["episodes"] == 1
    board = {(e["task"], e["controller"]): e for e in rep["leaderboard"]}
    for task in ("damping", "relevitate"):
        assert board[(task, "passive")]["score"] == pytest.approx(0.0)
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
