"""The ceiling analysis of a benchmark report (agents.benchmarking.headroom): its terms add up to
the benchmark's own score, the per-drop envelope is at least every row it picks from, and the
term-wise estimate at least the envelope."""
import numpy as np
import pytest

from agents.benchmarking.headroom import TERMS, headroom, table
from agents.benchmarking.score import overall_score, row_cost


def _row(name, sc, whirl, revs, force, disp, t_relev):
    return dict(controller=name, task="full", scenario=sc, backward_whirl=whirl,
                peak_whirl_revolutions=revs, peak_contact_force_N=force, max_displacement_um=disp,
                relevitated=0.0 if t_relev is None else 1.0, relevitation_time_s=t_relev)


REPORT = dict(score="severity", episode_time_s=0.3,
              scenarios=[dict(name="a", env_kwargs=dict(power_return_time=0.05)),
                         dict(name="b", env_kwargs=dict(power_return_time=0.03))],
              rows=[_row("passive", "a", 1.0, 20.0, 1000.0, 700.0, None),
                    _row("passive", "b", 1.0, 10.0, 800.0, 650.0, None),
                    _row("inner-loop", "a", 1.0, 5.0, 900.0, 690.0, 0.12),      # designed
                    _row("inner-loop", "b", 0.0, 1.0, 700.0, 600.0, 0.10),
                    _row("whirl-brake", "a", 0.0, 2.0, 950.0, 695.0, 0.09),     # designed
                    _row("whirl-brake", "b", 1.0, 4.0, 760.0, 640.0, 0.07),
                    _row("my-policy", "a", 0.0, 1.0, 980.0, 699.0, 0.08),       # learned
                    _row("my-policy", "b", 0.0, 2.0, 790.0, 645.0, 0.06)])


def test_terms_add_up_to_the_benchmark_score_and_the_estimates_are_ordered():
    r = headroom(REPORT)
    cols = {c["row"]: c for c in r["columns"]}
    passive = {row["scenario"]: row for row in REPORT["rows"] if row["controller"] == "passive"}
    for name in ("inner-loop", "whirl-brake", "my-policy"):
        col = headroom(REPORT, reference=name)["columns"][0]
        mine = [row_cost(row, passive[row["scenario"]], 0.3, True) for row in REPORT["rows"]
                if row["controller"] == name]
        p = [row_cost(row, row, 0.3, True) for row in passive.values()]
        assert col["row"] == name
        assert col["score"] == pytest.approx(overall_score(mine, p), abs=1e-12)
        assert 100.0 - sum(col["points"].values()) == pytest.approx(col["score"])
    # the reference is the best designed row; the envelopes pick per drop
    assert r["reference"] == max(("inner-loop", "whirl-brake"),
                                 key=lambda n: headroom(REPORT, reference=n)["columns"][0]["score"])
    env_d, env_all = cols["per-drop best designed row"], cols["per-drop best row"]
    termwise = cols["term-wise best (optimistic)"]
    assert env_d["score"] >= cols[r["reference"]]["score"]
    assert env_all["score"] >= max(env_d["score"], cols["my-policy"]["score"])
    assert termwise["score"] >= env_all["score"]
    # the re-levitation time's floor is the power return: 0.05/0.3 and 0.03/0.3 over the drops
    total = sum(row_cost(row, row, 0.3, True) for row in passive.values())
    assert termwise["points"]["relevitation_time"] == pytest.approx(100 * (0.05 + 0.03) / 0.3 / total)
    assert set(termwise["points"]) == set(TERMS)
    assert "| **score** |" in table(r)


def test_an_unknown_reference_or_task_is_named():
    with pytest.raises(ValueError, match="--reference 'nope' is not a row"):
        headroom(REPORT, reference="nope")
    with pytest.raises(ValueError, match="no rows of task 'damping'"):
        headroom(REPORT, task="damping")
