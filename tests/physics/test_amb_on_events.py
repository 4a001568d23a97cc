"""The events with the AMBs on, from the command line: `drop` runs the shock, the sudden
unbalance change and the overload presets; the AMBs stay powered, the rotor touches its retainer
bearings after the event, and every metric is finite."""
import json
import math

import pytest

from agents.cli import main
from physics import load_scene

#: preset -> the time its event starts [s]
EVENTS = {"paper-shock": ("ground", "pulse_start"),
          "paper-unbalance-loss": ("unbalance_change", "time"),
          "paper-overload": ("external_load", "start")}

#: preset -> the effect that makes it an event scene
EFFECT = {"paper-shock": "base_excitation", "paper-unbalance-loss": "unbalance_change",
          "paper-overload": "external_load"}


def _numbers(tree):
    """Every number in a nested dict (None: a metric that does not apply)."""
    for value in tree.values():
        if isinstance(value, dict):
            yield from _numbers(value)
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            yield value


@pytest.mark.parametrize("preset", sorted(EVENTS))
def test_drop_runs_each_event_with_the_ambs_on_and_reports_finite_metrics_and_contact(
        preset, tmp_path):
    scene = load_scene(preset)
    group, key = EVENTS[preset]
    t_event = getattr(getattr(scene, group), key)
    assert scene.amb.off_time > scene.solver.t_end                  # the AMBs stay powered
    assert main(["drop", "--scene", preset, "--out", str(tmp_path), "--quiet"]) == 0
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert m["fault_simulated"] is False and m["contact_before_fault"] is True
    assert t_event < m["first_contact_time_s"] < t_event + 0.03       # touched after the event
    assert max(p["pre_fault_peak_contact_force_N"] for p in m["planes"].values()) > 100.0
    assert all(math.isfinite(v) for v in _numbers(m))
    # the run is about the event, not a drop that never happened: no advice to lengthen it
    assert m["amb_on_events"] == [EFFECT[preset]]
    assert not any("no fault" in w or "before the fault" in w for w in m["warnings"])


@pytest.mark.parametrize("preset", sorted(EVENTS))
def test_the_summary_names_the_event_and_its_contact(preset, tmp_path, capsys):
    assert main(["drop", "--scene", preset, "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert f"AMBs on throughout ({EFFECT[preset]}): first retainer contact at t = " \
           f"{m['first_contact_time_s'] * 1e3:.2f} ms" in out
    assert "warning: no fault" not in out
