"""Retainer ball bearing against the spec's derived numbers (spec §4)."""
import math

import numpy as np
import pytest

from physics.ball_bearing import (ball_forces, ball_forces_with_dry, bearing_constants, contact_pressure_coef,
                                  drag_torque_magnitude, film_thickness, hertz_constant,
                                  max_contact_pressure, raceway_radii, reduced_modulus)
from physics.scene import Scene

B = Scene().bearing
BC = bearing_constants(B, 477.0)
HALF = B.clearance / 2


def approach_under(load, cage):
    """Inner-ring approach [m] under a downward radial load (bisection, no film)."""
    lo, hi = -1e-3, 0.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if -ball_forces(0.0, mid, cage, B.balls, HALF, 0.0, BC.K_tot)[1] > load:
            lo = mid
        else:
            hi = mid
    return -0.5 * (lo + hi)


def test_hertz_constant_matches_spec():
    assert BC.K_tot == pytest.approx(1.444e10, rel=2e-3)


def test_static_approach_and_largest_ball_load_under_477N():
    """Spec §4 check: 477 N static radial load, no film -> 14.6 µm approach, linear stiffness
    about 1.16e8 N/m, largest ball load about 271 N."""
    cage = math.pi / B.balls           # a ball straight under the load (270 deg)
    u = approach_under(477.0, cage)
    assert u * 1e6 == pytest.approx(14.6, rel=0.01)
    assert ball_forces(0.0, -u, cage, B.balls, HALF, 0.0, BC.K_tot)[5] == pytest.approx(271, rel=0.01)
    # linear stiffness at that load
    dk = 1e-8
    k = (ball_forces(0.0, -u - dk, cage, B.balls, HALF, 0.0, BC.K_tot)[1]
         - ball_forces(0.0, -u + dk, cage, B.balls, HALF, 0.0, BC.K_tot)[1]) / (2 * dk)
    assert -k == pytest.approx(1.16e8, rel=0.02)


def test_ball_loads_balance_the_load_and_vanish_inside_the_play():
    u = approach_under(477.0, 0.0)
    fx, fy, V, _, qsum, _ = ball_forces(0.0, -u, 0.0, B.balls, HALF, 0.0, BC.K_tot)
    assert fy == pytest.approx(-477.0, rel=1e-6) and abs(fx) < 1e-6 * 477
    assert qsum >= 477.0 and V > 0.0
    assert ball_forces(0.0, -0.9 * HALF, 0.0, B.balls, HALF, 0.0, BC.K_tot)[:2] == (0.0, 0.0)


def test_film_is_6um_at_spun_up_sleeve_speed_zero_at_rest_and_smooth():
    assert film_thickness(1037.0, BC.film_coef)[0] * 1e6 == pytest.approx(6.0, rel=0.03)
    assert film_thickness(0.0, BC.film_coef)[0] == 0.0
    w = np.linspace(-2.0, 2.0, 81)
    h = np.array([film_thickness(v, BC.film_coef)[0] for v in w])
    assert np.all(np.abs(np.diff(h, 2)) < 1e-9)       # no kink through zero speed
    assert film_thickness(-500.0, BC.film_coef)[0] == film_thickness(500.0, BC.film_coef)[0]
    dh = (film_thickness(800.0 + 1e-3, BC.film_coef)[0] - film_thickness(800.0 - 1e-3, BC.film_coef)[0]) / 2e-3
    assert film_thickness(800.0, BC.film_coef)[1] == pytest.approx(dh, rel=1e-6)


@pytest.mark.parametrize("h", [0.0, 2e-6, 6e-6])
def test_one_pass_film_and_dry_sums_equal_two_calls_bit_for_bit(h):
    """The massless-sleeve audit reads the zero-film forces from the same ball pass as the film
    forces (one loop instead of two): the results must be the separate calls' exactly."""
    rng = np.random.default_rng(3)
    for ux, uy, cage in rng.uniform((-2e-5, -2e-5, 0.0), (2e-5, 2e-5, 6.3), size=(50, 3)):
        both = ball_forces_with_dry(ux, uy, cage, B.balls, HALF, h, BC.K_tot)
        film = ball_forces(ux, uy, cage, B.balls, HALF, h, BC.K_tot)
        dry = ball_forces(ux, uy, cage, B.balls, HALF, 0.0, BC.K_tot)
        assert both[:6] == film
        assert both[6:] == (dry[0], dry[1], dry[3])


def test_film_closes_most_of_the_radial_play():
    h = film_thickness(1037.0, BC.film_coef)[0]
    assert 0.7 * HALF < h < HALF


def test_friction_torque_follows_palmgren_and_load_terms():
    dm_mm, nu = 110.0, B.viscosity / B.oil_density * 1e6
    w = 1047.2                                        # 10 000 rpm
    n = w * 30 / math.pi
    m0 = 1e-7 * B.f0 * (nu * n) ** (2 / 3) * dm_mm ** 3 * 1e-3
    P = 477.0
    m1 = 0.0007 * (P / B.static_load_rating) ** 0.5 * P * dm_mm * 1e-3
    got = drag_torque_magnitude(w, P, BC.m0_low, BC.m0_coef, BC.m1_coef, 0.0)
    assert got == pytest.approx(m0 + m1, rel=1e-9)
    low = drag_torque_magnitude(0.1, 0.0, BC.m0_low, BC.m0_coef, BC.m1_coef, 0.0)
    assert low == pytest.approx(160e-7 * B.f0 * dm_mm ** 3 * 1e-3, rel=1e-9)


def test_contact_pressure_of_a_circular_contact_is_classical_hertz():
    """Equal effective radii R_x = R_y = R: p_0 = (6 Q E*^2 / (pi^3 R^2))^(1/3) with E* = E' / 2
    (Johnson, Contact Mechanics, §4.2); the Brewe-Hamrock fits (k = 1.0339 instead of 1,
    E = 1.5971 instead of pi/2) put it 2.2 % lower."""
    E_red = reduced_modulus(B.youngs_modulus, B.poisson)
    R, Q = 0.01, 500.0
    p0 = (6.0 * Q * (E_red / 2.0) ** 2 / (math.pi ** 3 * R ** 2)) ** (1.0 / 3.0)
    assert contact_pressure_coef(R, R, E_red) * Q ** (1.0 / 3.0) == pytest.approx(0.978 * p0, rel=2e-3)


def test_static_load_rating_gives_about_the_iso_pressure():
    """ISO 76 rates C_0 at 4 200 MPa in the worst ball contact. With Stribeck's Q_max = 5 C_0 / Z
    the 6016's Hertz contacts reach 3.8 GPa at the inner race: the same order, 10 % lower."""
    p = max_contact_pressure(B, 5.0 * B.static_load_rating / B.balls)
    assert 3.5e9 < p < 4.5e9


def exact_hertz(R_x, R_y, E_red, Q):
    """Largest pressure and approach of a point contact (R_y > R_x) from the complete elliptic
    integrals, without the Brewe-Hamrock fits (Johnson, Contact Mechanics, §4.2): the ellipse's
    eccentricity e^2 = m solves R_y / R_x = (E / (1 - m) - K) / (K - E) (bisection), then
    a^3 = 6 Q R_y (K - E) / (pi E' m), b = a sqrt(1 - m), p_0 = 3 Q / (2 pi a b) and
    delta = 2 p_0 b K / E'."""
    def ellip(m):                   # K(m), E(m) by the arithmetic-geometric mean
        a, b, c, p, s = 1.0, math.sqrt(1.0 - m), math.sqrt(m), 0.5, 0.5 * m
        while c > 1e-16:
            a, b, c = 0.5 * (a + b), math.sqrt(a * b), 0.5 * (a - b)
            p *= 2.0
            s += p * c * c
        return math.pi / (2.0 * a), math.pi / (2.0 * a) * (1.0 - s)

    lo, hi = 1e-9, 1.0 - 1e-12
    for _ in range(100):
        m = 0.5 * (lo + hi)
        K, E = ellip(m)
        lo, hi = (m, hi) if (E / (1.0 - m) - K) / (K - E) < R_y / R_x else (lo, m)
    a = (6.0 * Q * R_y * (K - E) / (math.pi * E_red * m)) ** (1.0 / 3.0)
    b = a * math.sqrt(1.0 - m)
    p0 = 3.0 * Q / (2.0 * math.pi * a * b)
    return p0, 2.0 * p0 * b * K / E_red


@pytest.mark.parametrize("race", [0, 1])
def test_raceway_pressure_and_approach_are_the_exact_hertz_ellipse(race):
    """The 6016's inner (k = 9.3) and outer (k = 7.4) contacts: the fitted pressure coefficient
    and Q = K delta^1.5 describe the same ellipse as the exact solution, to within 0.6 % and
    1.1 % (the accuracy of the Brewe-Hamrock fits)."""
    E_red = reduced_modulus(B.youngs_modulus, B.poisson)
    R_x, R_y = raceway_radii(B)[race]
    c, K = contact_pressure_coef(R_x, R_y, E_red), hertz_constant(R_x, R_y, E_red)
    for Q in (100.0, 6817.0):
        p0, delta = exact_hertz(R_x, R_y, E_red, Q)
        assert c * Q ** (1.0 / 3.0) == pytest.approx(p0, rel=6e-3)
        assert (Q / K) ** (2.0 / 3.0) == pytest.approx(delta, rel=1.1e-2)
        assert max_contact_pressure(B, Q) >= c * Q ** (1.0 / 3.0)     # the worse raceway
