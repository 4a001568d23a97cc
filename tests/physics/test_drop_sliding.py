"""A drop that ends before the sleeves roll with the rotor says so (metrics sleeves_still_sliding
and a warning); a settled drop, and a run without a drop, do not."""
import pytest

from physics.metrics import SLIDING_SLIP, compute_metrics
from physics.scene import load_scene
from physics.simulate import simulate


def _metrics(t_end):
    return compute_metrics(simulate(load_scene("paper"), t_end=t_end))


def test_a_short_drop_ends_sliding_and_warns():
    m = _metrics(0.15)
    assert set(m["sleeves_still_sliding"]) == {"RB1", "RB2"}
    assert all(v > 0.5 for v in m["sleeves_still_sliding"].values())     # the sleeves lag far behind
    assert m["final_slip_ratio"] == m["sleeves_still_sliding"]
    assert any("still sliding" in w and "t_end = 0.15 s" in w for w in m["warnings"])


def test_a_settled_drop_rolls_and_does_not_warn():
    m = _metrics(1.0)
    assert m["sleeves_still_sliding"] == {}
    assert all(abs(v) < SLIDING_SLIP for v in m["final_slip_ratio"].values())
    assert not any("still sliding" in w for w in m["warnings"])


def test_no_drop_no_slip():
    m = _metrics(0.05)                                    # the AMBs switch off at 0.1 s
    assert m["final_slip_ratio"] == {"RB1": None, "RB2": None} and m["sleeves_still_sliding"] == {}
    assert not any("still sliding" in w for w in m["warnings"])
