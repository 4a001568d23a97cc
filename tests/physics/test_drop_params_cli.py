"""The rotordrop command line: drop outputs, params listing, clear errors."""
import json
import subprocess
import sys

import numpy as np
import pytest

from agents.cli import main
from physics.metrics import worst_plane


def test_drop_writes_metrics_timeseries_and_plots(tmp_path, capsys):
    out = tmp_path / "drop"
    assert main(["drop", "--t-end", "0.2", "--set", "contact.friction=0.1", "--out", str(out),
                 "--quiet"]) == 0
    m = json.loads((out / "metrics.json").read_text())
    for key in ("t_end", "first_contact_time_s", "final_rotor_speed_rpm", "wall_time_s",
                "compile_time_s", "rhs_evaluations", "planes"):
        assert key in m
    assert m["t_end"] == 0.2 and m["rhs_evaluations"] > 1000
    for p in ("RB1", "RB2"):
        for key in ("max_displacement_um", "peak_contact_force_N", "backward_whirl",
                    "whirl_frequency_hz", "final_sleeve_speed_rpm"):
            assert key in m["planes"][p]
    assert 300 < m["planes"]["RB1"]["max_displacement_um"] < 700
    for png in ("orbits.png", "contact_forces.png", "speeds.png", "retainer.png"):
        assert (out / png).stat().st_size > 10_000
    ts = np.load(out / "timeseries.npz")
    assert ts["t"][-1] == 0.2 and ts["RB1_contact_force"].max() == m["planes"]["RB1"]["peak_contact_force_N"]
    post = ts["t"] >= m["t_fault_s"]                  # the retainer metrics come from the same series
    assert ts["RB1_bearing_load"][post].max() == m["planes"]["RB1"]["peak_bearing_load_N"]
    assert ts["RB1_max_ball_load"][post].max() == m["planes"]["RB1"]["max_ball_load_N"] > 0.0
    p, t = ts["RB1_friction_power"][post], ts["t"][post]
    assert m["planes"]["RB1"]["friction_heat_J"] == pytest.approx(
        float(np.sum(0.5 * (p[1:] + p[:-1]) * np.diff(t))), rel=1e-12)
    assert m["planes"]["RB1"]["friction_heat_J"] > 0.0
    assert "contact.friction" not in capsys.readouterr().err
    assert "friction = 0.1" in (out / "scene.toml").read_text()


def test_drop_without_balls_or_fault_has_no_ball_metrics(tmp_path):
    """A rigid retainer mount has no balls (ball load and pressure None) and, with the AMBs
    still on at the end, no contact: no bearing load, so no safety factor either."""
    out = tmp_path / "rigid"
    assert main(["drop", "--t-end", "0.05", "--set", "effects.retainer_bearing=rigid", "--set",
                 "amb.off_time=0.5", "--out", str(out), "--quiet"]) == 0
    m = json.loads((out / "metrics.json").read_text())
    assert m["t_fault_s"] is None
    for e in m["planes"].values():
        assert e["max_ball_load_N"] is None and e["max_contact_pressure_MPa"] is None
        assert e["peak_bearing_load_N"] == 0.0 and e["static_safety_factor"] is None
        assert e["friction_heat_J"] == 0.0
    assert worst_plane(m, "max_contact_pressure_MPa") is None
    assert (out / "retainer.png").stat().st_size > 10_000
    assert not np.load(out / "timeseries.npz")["RB1_max_ball_load"].any()


def test_params_lists_every_key(capsys):
    assert main(["params"]) == 0
    text = capsys.readouterr().out
    for key in ("contact.friction", "support.damping", "effects.retainer_bearing", "solver.rtol"):
        assert key in text


def test_bad_override_is_a_one_line_error_not_a_traceback():
    proc = subprocess.run([sys.executable, "-m", "agents.cli", "drop", "--set",
                           "contact.friction=2", "--out", "/tmp/never"], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "contact.friction" in proc.stderr and "[0, 1]" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_a_closed_pipe_is_not_a_traceback():
    """`rotordrop params | head -1`: the reader leaves early; no BrokenPipeError traceback."""
    proc = subprocess.run(f"{sys.executable} -m agents.cli params | head -1", shell=True,
                          capture_output=True, text=True)
    assert proc.stdout.count("\n") == 1
    assert "Traceback" not in proc.stderr and "BrokenPipe" not in proc.stderr
