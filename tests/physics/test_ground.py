"""Base excitation (physics/ground.py): the ground's frame against closed forms (free fall under
g + a_g, a half-sine pulse's velocity change 2 A T / pi, the quasi-static deflection on the AMB
springs), the energy audit with a shock, the record's interpolation, and that the effect is off
by default, adds no state and refuses bad input by name."""
import math

import numpy as np
import pytest

from physics import load_scene, simulate
from physics.amb import weight_shares
from physics.ground import acceleration
from physics.model import build_model
from physics.scene import SceneError

from helpers import energy_residual, free_flight

FREE = {"effects.unbalance": False, "effects.base_excitation": True}


def _record(tmp_path, rows):
    path = tmp_path / "record.csv"
    path.write_text("# t, a_x, a_y\n" + "\n".join(", ".join(map(str, r)) for r in rows))
    return str(path)


def test_a_free_rotor_under_a_constant_ground_acceleration_falls_with_g_plus_a(tmp_path):
    """In the ground's frame a free rotor accelerates by -(g + a_g): x = -a_x t^2/2,
    y = -(g + a_y) t^2/2 (the rotor flies free for the first 5 ms: 120 of the 300 µm gap)."""
    ax, ay = 1.5, 2.5
    scene = load_scene("paper", {**FREE, "ground.record": _record(tmp_path, [(0, ax, ay),
                                                                              (1, ax, ay)])})
    t, Y, model = free_flight(scene, {}, 0.005, 51)
    g = scene.world.gravity
    assert Y[:, model.index("x")] == pytest.approx(-0.5 * ax * t ** 2, rel=1e-9, abs=1e-15)
    assert Y[:, model.index("y")] == pytest.approx(-0.5 * (g + ay) * t ** 2, rel=1e-9, abs=1e-15)
    assert np.all(np.abs(Y[:, model.index("y")]) < scene.contact.clearance)


def test_a_half_sine_pulse_changes_a_free_rotors_velocity_by_2_A_T_over_pi():
    A, T, theta, t0 = 20.0, 2e-3, 30.0, 5e-4
    scene = load_scene("paper", {**FREE, "effects.gravity": False, "ground.pulse_peak": A,
                                 "ground.pulse_duration": T, "ground.pulse_angle_deg": theta,
                                 "ground.pulse_start": t0, "solver.rtol": 1e-10,
                                 "solver.max_step": 1e-5})     # steps that resolve the pulse
    t, Y, model = free_flight(scene, {}, 3e-3, 31)
    dv = 2.0 * A * T / math.pi                  # the rotor lags the ground by this much
    vx, vy = Y[-1, model.index("vx")], Y[-1, model.index("vy")]
    assert vx == pytest.approx(-dv * math.cos(math.radians(theta)), rel=1e-7)
    assert vy == pytest.approx(-dv * math.sin(math.radians(theta)), rel=1e-7)
    assert np.all(Y[t < t0, model.index("vx")] == 0.0)          # nothing before the pulse


def test_the_peak_may_be_given_in_g():
    a = build_model(load_scene("paper", {**FREE, "ground.pulse_peak_g": 2.0}))
    b = build_model(load_scene("paper", {**FREE, "ground.pulse_peak": 2.0 * 9.80665}))
    assert np.array_equal(a.P, b.P)


def test_on_linear_ambs_a_slow_pulse_deflects_the_rotor_by_m_a_over_k():
    """A slow horizontal pulse (0.5 s against the AMB suspension's 23 Hz) with the AMBs on: each
    AMB plane's relative deflection is the quasi-static -F_k / k_amb, F_k that plane's share of
    m a_g (the lever rule), within 1 % at the pulse's peak."""
    A, T, t0 = 2.0, 0.5, 0.05
    scene = load_scene("paper", {**FREE, "amb.off_time": 10.0, "ground.pulse_peak": A,
                                 "ground.pulse_duration": T, "ground.pulse_angle_deg": 0.0,
                                 "ground.pulse_start": t0, "solver.output_rate": 1000.0})
    r = simulate(scene, t_end=t0 + T / 2)
    x1, _, x2, _ = r.model.sensor_positions(r.Y[-1])
    f1, f2 = weight_shares(scene.rotor.mass * A, scene.positions.amb1, scene.positions.amb2)
    k = scene.amb.stiffness
    assert x1 == pytest.approx(-f1 / k, rel=0.01)
    assert x2 == pytest.approx(-f2 / k, rel=0.01)


def test_the_energy_audit_closes_through_a_shock_and_the_drop_that_follows():
    """A 10 g, 11 ms upward-sideways shock while levitated, then the fault: the d'Alembert
    forces' power is booked as external work and the audit closes."""
    r = simulate(load_scene("paper", {"effects.base_excitation": True, "ground.pulse_peak_g": 10.0,
                                      "ground.pulse_angle_deg": 60.0, "ground.pulse_start": 0.05,
                                      "ground.pulse_duration": 0.011}), t_end=0.3)
    res, e = energy_residual(r)
    assert abs(e["external"][-1]) > 1.0                # the shock did work on the bodies
    assert res.max() < 1e-5 * e["dissipated"][-1]


def test_the_record_is_linear_between_its_samples_and_zero_outside(tmp_path):
    scene = load_scene("paper", {"effects.base_excitation": True,
                                 "ground.record": _record(tmp_path, [(0.1, 0, 0), (0.2, 10, -4),
                                                                     (0.4, 0, 2)])})
    m = build_model(scene)
    for t, want in ((0.05, (0, 0)), (0.15, (5, -2)), (0.2, (10, -4)), (0.35, (2.5, 0.5)),
                    (0.5, (0, 0))):
        assert acceleration(t, m.P, m.I) == pytest.approx(want, abs=1e-12)


def test_off_by_default_no_state_and_nothing_changes():
    on = build_model(load_scene("paper", FREE | {"ground.pulse_peak": 5.0}))
    off = build_model(load_scene("paper", {"effects.unbalance": False}))
    assert load_scene("paper").effects.base_excitation is False
    assert on.names == off.names
    a = simulate(load_scene("paper"), t_end=0.05)
    b = simulate(load_scene("paper", {"ground.pulse_peak": 500.0}), t_end=0.05)   # off: unused
    assert np.array_equal(a.Y, b.Y)


@pytest.mark.parametrize("overrides, match", [
    ({"ground.pulse_peak": -1.0}, r"ground\.pulse_peak = -1.0 is out of range"),
    ({"ground.pulse_duration": 0.0}, r"ground\.pulse_duration"),
    ({"effects.base_excitation": True}, r"needs ground\.pulse_peak"),
    ({"effects.base_excitation": True, "ground.pulse_peak": 1.0, "ground.pulse_peak_g": 1.0},
     r"give the pulse's peak once"),
    ({"effects.base_excitation": True, "ground.record": "/nonexistent.csv"}, r"no such file"),
])
def test_bad_input_is_named(overrides, match):
    with pytest.raises(SceneError, match=match):
        load_scene("paper", overrides)


@pytest.mark.parametrize("rows, match", [
    ([(0, 1, 1), (0, 2, 2)], "strictly increasing"),
    ([(0, 1), (1, 2)], "3 columns"),
    ([(0, 1, 1), (1, 1e5, 0)], r"accelerations must lie in"),
])
def test_a_bad_record_is_named(tmp_path, rows, match):
    with pytest.raises(SceneError, match=r"ground\.record = .*" + match):
        load_scene("paper", {"effects.base_excitation": True,
                             "ground.record": _record(tmp_path, rows)})
