"""The controller-seat oracle (agents.research.seat_oracle): its pool, its seat, and that each
drop's best member is at least the reference law on that drop, end to end on a tiny case; and
``benchmark --only`` (the subset of rows it and the learning rows are scored with)."""
import json

import numpy as np
import pytest

from agents.benchmarking.benchmark import robust_entries
from agents.benchmarking.suites import SUITES
from agents.control.controllers import WhirlBrake
from agents.research.seat_oracle import REFERENCE, gain_sets, pool_entries
from agents.research.tune_whirl_brake import HIGH, LOW, NAMES

TUNED = dict(ff=1.09, kc=1.10, kd=4.79, kp=1.33, kr=0.31, kt=0.34)


def test_the_pool_holds_the_reference_first_and_draws_inside_the_tuning_ranges():
    pool = gain_sets(TUNED, draws=20, spread=0.3, seed=1)
    assert pool[0] == (REFERENCE, TUNED) and len(pool) == 23
    assert pool[1][1] == {n: WhirlBrake.GAINS[n] for n in NAMES}
    draws = np.array([[g[n] for n in NAMES] for _, g in pool[3:]])
    assert np.all(draws >= LOW) and np.all(draws <= HIGH)
    assert np.ptp(draws, axis=0).min() > 0                      # every gain varies
    assert gain_sets(TUNED, 20, 0.3, 1) == pool                  # seeded
    assert gain_sets(TUNED, 20, 0.3, 2) != pool
    with pytest.raises(ValueError, match="--spread"):
        gain_sets(TUNED, 2, 0.0, 0)
    with pytest.raises(ValueError, match="--draws"):
        gain_sets(TUNED, -1, 0.1, 0)


def test_the_pool_runs_in_whirl_brakes_seat():
    suite = SUITES.get("robust")
    entries = pool_entries(gain_sets(TUNED, 1, 0.1, 0), suite)
    assert [e.name for e in entries][:2] == ["passive", REFERENCE]
    for e in entries[1:]:
        assert e.seat == "controller" and e.env_kwargs["control_dt"] == pytest.approx(2e-4)
        assert e.env_kwargs["command"] == "continuous"


@pytest.mark.slow
def test_each_drops_best_member_is_at_least_the_reference(tmp_path):
    from agents.cli import main
    out = tmp_path / "so"
    assert main(["research", "seat-oracle", "--scenarios", "2", "--draws", "1", "--quiet",
                 "--out", str(out)]) == 0
    rec = json.loads((out / "seat_oracle.json").read_text())
    cols = {c["row"]: c for c in rec["headroom"]["columns"]}
    assert rec["headroom"]["reference"] == REFERENCE and rec["settings"]["seat"] == "controller"
    assert cols["per-drop best row"]["diff_vs_reference"] >= -1e-12
    assert cols["per-drop best row"]["score"] >= cols[REFERENCE]["score"] - 1e-12
    lines = (out / "seat_oracle.csv").read_text().splitlines()[1:]
    assert len(lines) == 2 and len(rec["best_member"]) == 2
    for line in lines:
        _, _, ref, best, member = line.split(",")
        assert float(best) <= float(ref) + 1e-12
        assert member in [p["name"] for p in rec["pool"]]
    assert (out / "seat_oracle.png").is_file()


def test_only_keeps_the_named_rows_the_extras_and_passive():
    entries, learned = robust_entries(None, suite=SUITES.get("robust"),
                                      only=["whirl-brake", "inner-loop", "ppo-robust-full-scratch"])
    assert sorted(e.name for e in entries) == ["inner-loop", "passive", "ppo-robust-full-scratch",
                                               "whirl-brake"]
    assert {e.name: e.seat for e in entries}["whirl-brake"] == "controller"
    assert list(learned) == ["ppo-robust-full-scratch"]
    with pytest.raises(ValueError, match="--only nope: not a row of the suite"):
        robust_entries(None, suite=SUITES.get("robust"), only=["nope"])


def test_only_is_refused_on_the_nominal_suite():
    from agents.benchmarking.suites import run_suite
    with pytest.raises(ValueError, match="--only applies to a drawn suite"):
        run_suite("nominal", "unused", only=["whirl-brake"])
