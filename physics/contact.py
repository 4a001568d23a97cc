"""Rotor-sleeve circle-in-circle contact (paper eqs. 14-19, spec §3)."""
import math

from ._jit import njit


@njit
def step(g, g0, h0, g1, h1):
    """Cubic STEP polynomial, eq. 18: h0 below g0, h1 above g1, C1-smooth in between."""
    if g <= g0:
        return h0
    if g >= g1:
        return h1
    s = (g - g0) / (g1 - g0)
    return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)


@njit
def normal_force(delta, delta_dot, K, e, c_max, d):
    """Radial contact force F_r >= 0 for penetration delta and its rate, eq. 14.

    Returns (F_r, K delta^e): the force and its elastic part (the energy audit needs both).
    """
    if delta <= 0.0:
        return 0.0, 0.0
    elastic = K * delta ** e
    f = elastic + step(delta, 0.0, 0.0, d, c_max) * delta_dot
    return (f if f > 0.0 else 0.0), elastic


@njit
def contact_potential(delta, K, e):
    """Elastic energy K delta^(e+1)/(e+1) stored in the contact (energy audit)."""
    if delta <= 0.0:
        return 0.0
    return K * delta ** (e + 1.0) / (e + 1.0)


@njit
def smooth_sign(slip, threshold):
    """sign(slip) * STEP(|slip|, 0, 0, threshold, 1): the regularised friction direction (eq. 19)."""
    a = step(abs(slip), 0.0, 0.0, threshold, 1.0)
    return a if slip >= 0.0 else -a


@njit
def friction_force(mu, f_r, slip, threshold):
    """Signed friction magnitude F_mu = mu F_r sgn(slip) STEP(|slip|, 0, 0, threshold, 1), eq. 19.

    F_mu acts on the sleeve along +t and on the rotor along -t (t = z x n), with spin torques
    -r F_mu on the rotor and +R F_mu on the sleeve.
    """
    return mu * f_r * smooth_sign(slip, threshold)


@njit
def geometry(ex, ey):
    """Radial distance e_r and unit normal n = e/e_r (n = +X for a centred rotor)."""
    er = math.sqrt(ex * ex + ey * ey)
    if er > 0.0:
        return er, ex / er, ey / er
    return 0.0, 1.0, 0.0
