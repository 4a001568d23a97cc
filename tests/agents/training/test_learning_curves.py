"""Learning curves over seeds: mean and std on the evaluation steps the runs share."""
import csv
import json

import numpy as np

from agents.training.learning_curves import aggregate, main


def fake_run(path, scores, whirl):
    path.mkdir()
    curve = [dict(timesteps=1000 * (i + 1), validation_score=s, mean_backward_whirl=w)
             for i, (s, w) in enumerate(zip(scores, whirl))]
    (path / "training.json").write_text(json.dumps(dict(learning_curve=curve)))
    return str(path)


def test_mean_and_std_over_seeds_on_shared_steps(tmp_path):
    a = fake_run(tmp_path / "a", [10, 20, 30], [1.0, 0.5, 0.0])
    b = fake_run(tmp_path / "b", [30, 40], [0.0, 0.5])                 # stopped earlier
    data = aggregate([a, b])
    np.testing.assert_array_equal(data["steps"], [1000, 2000])
    np.testing.assert_array_equal(data["validation_score"], [[10, 20], [30, 40]])
    assert main(["--group", f"ppo={a},{b}", "--group", f"sac={a}",
                 "--out", str(tmp_path / "lc.png")]) == 0
    rows = list(csv.DictReader((tmp_path / "lc.csv").open()))
    first = rows[0]
    assert first["label"] == "ppo" and first["runs"] == "2"
    assert float(first["validation_score_mean"]) == 20.0
    assert float(first["validation_score_std"]) == 10.0
    assert [r["label"] for r in rows].count("sac") == 3
    per_run = list(csv.DictReader((tmp_path / "lc-runs.csv").open()))
    assert [(r["run"], r["timesteps"], float(r["validation_score"])) for r in per_run
            if r["label"] == "ppo"] == [(a, "1000", 10.0), (a, "2000", 20.0), (b, "1000", 30.0),
                                        (b, "2000", 40.0)]
    assert (tmp_path / "lc.png").stat().st_size > 0


def test_other_quantities_of_the_curve(tmp_path):
    """--quantity picks learning-curve entries (a run without one gives NaN, not an error)."""
    a = fake_run(tmp_path / "a", [10, 20], [1.0, 0.5])
    assert main(["--group", f"tqc={a}", "--quantity", "mean_backward_whirl",
                 "--quantity", "mean_relevitated", "--out", str(tmp_path / "q.png")]) == 0
    rows = list(csv.DictReader((tmp_path / "q.csv").open()))
    assert list(rows[0]) == ["label", "timesteps", "runs", "mean_backward_whirl_mean",
                             "mean_backward_whirl_std", "mean_relevitated_mean", "mean_relevitated_std"]
    assert [float(r["mean_backward_whirl_mean"]) for r in rows] == [1.0, 0.5]
    assert rows[0]["mean_relevitated_mean"] == "nan"
