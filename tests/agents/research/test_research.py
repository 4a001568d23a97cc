"""``rotordrop research``: the oracle whirl bound end to end on a tiny search, and its usage errors."""
import json

import numpy as np
import pytest

from agents.cli import main


def test_whirl_bound_never_reports_worse_than_its_baseline(tmp_path, capsys):
    """At mu = 0.48 with the power back at 50 ms whirl-brake does not stop the whirl (docs/experiments/
    2026-11-21-baselines-and-residual-policies.md: 3.18 revolutions); the search starts from the baseline (zero correction), so its best is at
    most the baseline's, and the pushes at 12 angles are all recorded."""
    out = tmp_path / "wb"
    assert main(["research", "whirl-bound", "--friction", "0.48", "--phase", "0", "--segments", "1",
                 "--steps", "1", "--iterations", "1", "--population", "2", "--out", str(out)]) == 0
    rec = json.loads((out / "whirl_bound.json").read_text())
    (row,) = rec["rows"]
    assert row["baseline_peak_revolutions"] > rec["whirl_revolutions"]          # a whirl
    assert row["best_peak_revolutions"] <= row["baseline_peak_revolutions"]
    assert sorted(map(int, row["push_revolutions"])) == list(range(0, 360, 30))
    assert rec["settings"]["friction"] == [0.48] and "func" not in rec["settings"]
    assert "wrote " in capsys.readouterr().out


@pytest.mark.parametrize("args, message", [
    (["whirl-bound", "--env", "RotorDrop-Damping-v1"], "--env must be one of RotorDrop-Relevitate-v1"),
    (["whirl-bound", "--baseline", "max-damping"], "must be a controller that commands the AMB currents"),
    (["tune-whirl-brake", "--env", "RotorDrop-Nope-v1"], "not the environment of a benchmark task"),
])
def test_research_usage_errors_are_one_line(tmp_path, capsys, args, message):
    assert main(["research", *args, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_diagnosis_reads_damper_actions_through_the_runs_map():
    """The damper fraction (C - C_min) / (C_max - C_min) of a raw action: the linear map's zero
    action is mid-range; under ``from_max`` every action >= 0 is C_max and -1 is C_min."""
    from agents.research.diagnose_run import damper_fractions
    a = np.array([[-1.0, -0.5], [0.0, 0.6]])
    assert damper_fractions(a, "linear").tolist() == [[0.0, 0.25], [0.5, 0.8]]
    assert damper_fractions(a, "from_max").tolist() == [[0.0, 0.5], [1.0, 1.0]]


def test_collapse_diagnosis_tools_agree_with_the_validator_on_the_inner_loop():
    """agents.research.diagnose_run / probe_commands (docs/experiments/
    2026-11-26-robust-collapse.md): the inner loop through the diagnosis recorder and as the constant supervisor
    command (both dampers C_max, levitate on, zero gain and offsets) score what the robust
    validator gives the inner loop; it switches on at the first step that sees the power and
    re-levitates every drop."""
    from agents.control.controllers import InnerLoop
    from agents.control.plant import Plant
    from agents.research.diagnose_run import diagnose
    from agents.research.probe_commands import ConstantCommands, probe
    from agents.benchmarking.robust import ENV_ID, robust_validator, training_env_kwargs
    from agents.benchmarking.rollout import make_env
    validator = robust_validator()
    kw = dict(training_env_kwargs(), command="supervisor")
    ref, _ = validator.score(InnerLoop, kw)
    env = make_env(ENV_ID, command="supervisor", control_dt=kw["control_dt"])
    names = list(Plant.from_env(env).obs_names)
    env.close()
    d = diagnose("inner-loop", InnerLoop, kw, validator, names)
    assert d["score"] == ref and d["relevitated"] == 1.0
    assert d["never_switched_on"] == 0.0 and d["switch_on_after_power_ms_median"] == 0.0
    assert d["mean_damper_fraction_before_power"] == d["mean_damper_fraction_after_power"] == [1.0, 1.0]
    p = probe(validator, lambda plant: ConstantCommands([1, 1, 1, 0, 0, 0, 0, 0]))
    assert p["score"] == pytest.approx(ref, abs=0.5) and p["relevitated"] == 1.0
