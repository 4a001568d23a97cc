"""``rotordrop research``: the oracle whirl bound end to end on a tiny search, and its usage errors."""
import json

import pytest

from agents.cli import main


def test_whirl_bound_never_reports_worse_than_its_baseline(tmp_path, capsys):
    """At mu = 0.48 with the power back at 50 ms whirl-brake does not stop the whirl (docs/agents.md:
    3.18 revolutions); the search starts from the baseline (zero correction), so its best is at
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
    (["whirl-bound", "--env", "RotorDrop-Damping-v0"], "--env must be one of RotorDrop-Relevitate-v0"),
    (["whirl-bound", "--baseline", "max-damping"], "must be a controller that commands the AMB currents"),
    (["tune-whirl-brake", "--env", "RotorDrop-Nope-v0"], "not the environment of a benchmark task"),
])
def test_research_usage_errors_are_one_line(tmp_path, capsys, args, message):
    assert main(["research", *args, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
