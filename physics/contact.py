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


# --------------------------------------------------------------- hertz_line law (contact.law) --
# Johnson's internal line contact: a journal in a conforming bore of radial clearance c, contact
# length L, effective modulus E* (1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2), approach
#     delta(F) = F / (pi L E*) [ln(4 pi L E* c / F) - 1]
# (Johnson, Contact Mechanics, 1985, §5.6; the internal form as compared by Pereira, Ramalho &
# Ambrosio, Nonlinear Dyn. 63, 2011). With a = pi L E*, u = F / (4 a c): delta / (4 c) = u (-ln u - 1),
# which grows up to u = e^-2 and has no solution beyond delta = 4 c / e^2: the law holds only up to
# a fraction of the clearance. It is used up to u = e^-3 (delta_v = 8 c / e^3 = 0.40 c, where its
# tangent stiffness has risen to a) and continued linearly with stiffness a beyond.
LINE_U_MAX = math.exp(-3.0)


def line_validity(clearance: float) -> float:
    """delta_v = 8 c / e^3 [m]: where the internal line-contact law is continued linearly (its
    tangent stiffness reaches pi L E*; it has no solution past 4 c / e^2 = 0.54 c)."""
    return 8.0 * clearance * LINE_U_MAX


@njit
def line_deflection(F, a, c):
    """Approach delta(F) of Johnson's internal line contact, a = pi L E*, clearance c [m]."""
    if F <= 0.0:
        return 0.0
    return F / a * (math.log(4.0 * a * c / F) - 1.0)


@njit
def line_elastic_force(delta, a, c):
    """F(delta) inverting :func:`line_deflection` (Newton on ln F; quadratic convergence from
    the fixed-point start), continued linearly with slope a past delta_v = 8 c / e^3."""
    if delta <= 0.0:
        return 0.0
    f_v = 4.0 * a * c * LINE_U_MAX
    d_v = 8.0 * c * LINE_U_MAX
    if delta >= d_v:
        return f_v + a * (delta - d_v)
    F = a * delta / max(math.log(4.0 * c / delta), 2.0)    # ln(4ac/F) - 1 ~ ln(4c/delta)
    for _ in range(50):
        lg = math.log(4.0 * a * c / F)
        g = F / a * (lg - 1.0) - delta
        step = g / ((lg - 2.0) / a * F)                     # d(delta)/d(ln F) = F (lg - 2) / a
        F *= math.exp(-step)
        if abs(step) < 1e-15:
            break
    return F


@njit
def line_potential(delta, a, c):
    """Elastic energy of the line contact, ∫ F d delta = F^2 / (2a) [ln(4ac/F) - 3/2] (from
    F delta - ∫ delta dF), plus the linear continuation's share past delta_v."""
    if delta <= 0.0:
        return 0.0
    d_v = 8.0 * c * LINE_U_MAX
    F = line_elastic_force(min(delta, d_v), a, c)
    V = F * F / (2.0 * a) * (math.log(4.0 * a * c / F) - 1.5)
    if delta > d_v:
        x = delta - d_v
        V += F * x + 0.5 * a * x * x
    return V


@njit
def hunt_crossley(elastic, delta_dot, chi):
    """Hunt-Crossley force F = F_el (1 + chi delta_dot) >= 0: hysteresis damping that vanishes
    with the elastic force (no jump at first touch); chi = 3 (1 - e^2) / (4 v_ref) of
    Lankarani & Nikravesh (J. Mech. Des. 112, 1990) gives restitution ~e at impact speed v_ref."""
    f = elastic * (1.0 + chi * delta_dot)
    return f if f > 0.0 else 0.0


def hysteresis_factor(restitution: float, v_ref: float) -> float:
    """chi [s/m] of :func:`hunt_crossley` for restitution e at impact speed v_ref."""
    return 3.0 * (1.0 - restitution ** 2) / (4.0 * v_ref)
