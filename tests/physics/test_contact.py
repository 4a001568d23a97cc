"""Contact law of paper eqs. 14-19 (spec §3)."""
import numpy as np
import pytest

from physics.contact import friction_force, normal_force, smooth_sign, step


def fr(*args):
    return normal_force(*args)[0]

K, E, C, D = 1e8, 1.1, 1000.0, 1e-5


def test_step_polynomial_endpoints_midpoint_and_flat_ends():
    assert step(-1.0, 0.0, 2.0, 1.0, 5.0) == 2.0
    assert step(3.0, 0.0, 2.0, 1.0, 5.0) == 5.0
    assert step(0.5, 0.0, 2.0, 1.0, 5.0) == pytest.approx(3.5)          # s^2(3-2s) = 1/2
    assert step(0.25, 0.0, 0.0, 1.0, 1.0) == pytest.approx(0.25 ** 2 * 2.5)
    eps = 1e-7                                                             # C1: zero slope at ends
    assert (step(eps, 0.0, 0.0, 1.0, 1.0) - step(0.0, 0.0, 0.0, 1.0, 1.0)) / eps < 1e-6
    assert (step(1.0, 0.0, 0.0, 1.0, 1.0) - step(1 - eps, 0.0, 0.0, 1.0, 1.0)) / eps < 1e-6


def test_step_is_monotone_between_levels():
    g = np.linspace(-0.5, 1.5, 401)
    h = np.array([step(v, 0.0, 1.0, 1.0, 3.0) for v in g])
    assert np.all(np.diff(h) >= 0.0)


def test_normal_force_is_zero_outside_contact_and_elastic_at_rest():
    assert fr(-1e-6, -5.0, K, E, C, D) == 0.0
    assert fr(0.0, 1.0, K, E, C, D) == 0.0
    delta = 20e-6
    assert fr(delta, 0.0, K, E, C, D) == pytest.approx(K * delta ** E)


def test_damping_ramps_in_with_penetration_and_never_pulls():
    v = 0.1
    shallow = fr(1e-9, v, K, E, C, D) - K * 1e-9 ** E         # damping ~0 at contact
    assert abs(shallow) < 1e-3 * C * v
    deep = fr(2 * D, v, K, E, C, D) - K * (2 * D) ** E        # full C_max beyond d
    assert deep == pytest.approx(C * v)
    assert fr(2 * D, -10.0, K, E, C, D) == 0.0                 # no adhesion


def test_friction_magnitude_direction_and_regularisation():
    mu, fr, wl = 0.3, 400.0, 1.0
    assert friction_force(mu, fr, 50.0, wl) == pytest.approx(mu * fr)
    assert friction_force(mu, fr, -50.0, wl) == pytest.approx(-mu * fr)   # |slip| (spec note)
    assert friction_force(mu, fr, 0.0, wl) == 0.0
    assert 0.0 < friction_force(mu, fr, 0.5, wl) < mu * fr
    assert smooth_sign(-0.5, 1.0) == -smooth_sign(0.5, 1.0)
