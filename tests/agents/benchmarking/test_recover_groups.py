"""Seed groups of learned rows in a recovery report: mean ± std of the seeds' rates and the
seed-mean's paired difference against the PID and the best designed row."""
import numpy as np
import pytest

from agents.benchmarking.recover import REFERENCE, groups_markdown, seed_groups


def _rows(*flags):
    return [{"recovered": bool(f)} for f in flags]


def test_seed_groups_average_the_seeds_and_pair_them_with_the_best_designed_row():
    rows = {REFERENCE: _rows(1, 0, 0, 0), "sync-phase-search": _rows(1, 1, 0, 0),
            "ppo-s0": _rows(1, 1, 1, 0), "ppo-s1": _rows(1, 1, 0, 0), "ppo-s2": _rows(1, 0, 0, 0),
            "lonely-s0": _rows(0, 0, 0, 0), "other": _rows(1, 1, 1, 1)}
    g = seed_groups(rows, ["ppo-s0", "ppo-s1", "ppo-s2", "lonely-s0", "other"])
    assert list(g) == ["ppo"]                      # one seed or no seed suffix: not a group
    ppo = g["ppo"]
    assert ppo["rates"] == [0.75, 0.5, 0.25] and ppo["mean"] == pytest.approx(0.5)
    assert ppo["std"] == pytest.approx(0.25) and ppo["mean_minus_std"] == pytest.approx(0.25)
    # the seed mean per event is (1, 2/3, 1/3, 0): against the PID (1, 0, 0, 0) +1/4 on average
    assert ppo["vs"][REFERENCE]["delta"] == pytest.approx(0.25)
    assert ppo["vs"]["sync-phase-search"]["delta"] == pytest.approx(0.0)
    lo, hi = ppo["vs"][REFERENCE]["ci95"]
    assert lo <= 0.25 <= hi and ppo["vs"][REFERENCE]["se"] > 0
    text = groups_markdown(g)
    assert "| `ppo` | 75.0, 50.0, 25.0 | 50.0 ± 25.0 | 25.0 |" in text
    assert "`sync-phase-search`" in text and np.isfinite(ppo["std"])
