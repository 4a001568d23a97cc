"""Rigid-rotor dynamics: gyroscopic whirl frequencies, levitated unbalance orbit (spec §1)."""
import math

import numpy as np
import pytest

from physics import build_model, load_scene, simulate
from physics.equilibrium import levitated_state

from helpers import free_flight

FREE = {"effects.amb": "none", "effects.gravity": False, "effects.unbalance": False,
        "effects.friction": "none", "solver.rtol": 1e-9}


def _whirl_rate(t, a, b):
    """Mean angular rate of the tilt-velocity vector (a', b') [rad/s], sign = direction."""
    ang = np.unwrap(np.arctan2(np.gradient(b, t), np.gradient(a, t)))
    return (ang[-1] - ang[0]) / (t[-1] - t[0])


def test_free_spinning_rotor_nutates_forward_at_Ip_Omega_over_Id():
    scene = load_scene("paper", FREE)
    omega = scene.rotor.speed_rpm * np.pi / 30
    t, Y, m = free_flight(scene, {"Omega": omega, "va": 1e-5}, 0.02, 4001)
    rate = _whirl_rate(t, Y[:, m.index("a")], Y[:, m.index("b")])
    expected = scene.rotor.polar_inertia * omega / scene.rotor.diametral_inertia
    assert rate == pytest.approx(expected, rel=1e-3)          # forward: same sign as Omega


def test_reversed_spin_reverses_the_nutation():
    scene = load_scene("paper", FREE)
    omega = -scene.rotor.speed_rpm * np.pi / 30
    t, Y, m = free_flight(scene, {"Omega": omega, "va": 1e-5}, 0.02, 4001)
    assert _whirl_rate(t, Y[:, m.index("a")], Y[:, m.index("b")]) < 0


def test_the_other_whirl_frequency_is_zero_a_tilted_rotor_stays_put():
    scene = load_scene("paper", FREE)
    t, Y, m = free_flight(scene, {"Omega": 1000.0, "a": 1e-4, "b": -5e-5}, 0.05, 11)
    np.testing.assert_array_equal(Y[:, m.index("a")], 1e-4)       # no moment acts: exactly
    np.testing.assert_array_equal(Y[:, m.index("b")], -5e-5)


def test_without_gyroscopic_coupling_tilt_velocity_keeps_its_direction():
    scene = load_scene("paper", dict(FREE, **{"effects.gyroscopic": False}))
    t, Y, m = free_flight(scene, {"Omega": 1000.0, "va": 1e-5}, 0.02, 101)
    np.testing.assert_array_equal(Y[:, m.index("vb")], 0.0)
    np.testing.assert_array_equal(Y[:, m.index("va")], 1e-5)


def test_levitated_start_is_the_settled_unbalance_orbit():
    scene = load_scene("spec", {"amb.off_time": 1.0, "solver.rtol": 1e-8})
    r = simulate(scene, t_end=0.05)
    o = r.orbit("RB1")
    radius = np.hypot(o[:, 0], o[:, 1])                               # centred orbit
    # mass-controlled response above the rigid-body modes: |Z| ~ m_u e / m
    expected = scene.unbalance.mass * scene.unbalance.radius / scene.rotor.mass
    assert radius.mean() == pytest.approx(expected, rel=0.05)
    assert radius.max() - radius.min() < 1e-3 * radius.mean()       # no transient
    assert np.abs(o[:, 1].mean()) < 0.05e-6                          # AMBs carry the weight
    s = r.sleeve("RB1")[:, 1]
    assert np.ptp(s) < 1e-9                                          # sleeve at rest on balls


def test_levitated_sleeve_rests_on_its_balls_and_housing_sags_by_weight_over_stiffness():
    scene = load_scene("paper")
    model = build_model(scene)
    y = levitated_state(model)
    hy = y[model.index("RB1.hy")]
    sy = y[model.index("RB1.sy")]
    g = scene.world.gravity
    assert hy == pytest.approx(-(scene.support.housing_mass + scene.sleeve.mass) * g
                               / scene.support.stiffness)
    # the inner ring drops through the radial play (P_d/2) plus the Hertz approach under the
    # sleeve's weight. Cage at 0: of the 6016's 10 balls (every 36 deg) the two at 252 and 288 deg
    # straddle the bottom at psi = 18 deg and carry it alone (2 K delta^1.5 cos psi = m_s g,
    # drop u = (P_d/2 + delta) / cos psi); the next pair, at 3 psi, stays clear.
    from physics.ball_bearing import bearing_constants
    b = scene.bearing
    assert b.balls == 10
    psi = math.pi / b.balls
    K = bearing_constants(b, 0.5 * scene.rotor.mass * g).K_tot
    delta = (scene.sleeve.mass * g / (2 * K * math.cos(psi))) ** (2 / 3)
    u = (b.clearance / 2 + delta) / math.cos(psi)
    assert u * math.cos(3 * psi) < b.clearance / 2
    assert -(sy - hy) == pytest.approx(u, rel=1e-9)


def test_no_excitation_means_no_orbit_whatever_the_support():
    """A rotor at standstill (or without unbalance) has no unbalance orbit, even on a support
    without stiffness or damping, where the formula's denominator vanishes too; a scene like
    that (amb.stiffness = 0, rotor.speed_rpm = 0) simply falls onto its retainer bearings."""
    from physics.rotor import steady_unbalance_orbit
    assert steady_unbalance_orbit(1e-3 * 0.03, 0.0, 97.3, 0.0, 0.0) == 0j
    with pytest.raises(ValueError, match="amb.damping"):
        steady_unbalance_orbit(1e-3 * 0.03, 100.0, 1.0, 1e4, 0.0)
    r = simulate(load_scene("paper", {"amb.stiffness": 0.0, "rotor.speed_rpm": 0.0}), t_end=0.13)
    assert np.isfinite(r.Y).all()
    assert np.abs(r.state("x")).max() < 1e-9              # no spin: straight down, no orbit
