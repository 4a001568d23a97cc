"""The ``hertz_line`` contact law (``contact.law = "hertz_line"``; docs/physics.md): Johnson's
internal line contact of the steel journal in the steel sleeve over ``contact.length``, with
Hunt-Crossley hysteresis damping. Registered in :mod:`physics.laws`.

Validity bound: the approach at which the Hertz half-width reaches HALF_WIDTH_LIMIT x the
journal radius (:func:`half_width_approach`; it depends on the geometry only). Metrics hook: the
tangent stiffness a / (ln(4ac/F) - 2), capped at a (:func:`tangent_stiffness`).
"""
from __future__ import annotations

import math

from .._jit import njit, njit_inline

NAME = "hertz_line"
DOC = ("Johnson's internal line contact of steel on steel over contact.length, Hunt-Crossley"
       " damping")

# Johnson's internal line contact: a journal in a conforming bore of radial clearance c, contact
# length L, effective modulus E* (1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2), approach
#     delta(F) = F / (pi L E*) [ln(4 pi L E* c / F) - 1]
# (Johnson, Contact Mechanics, 1985, §5.6; the internal form as compared by Pereira, Ramalho &
# Ambrosio, Nonlinear Dyn. 63, 2011). With a = pi L E*, u = F / (4 a c): delta / (4 c) = u (-ln u - 1).
# The formula rests on Hertz's half-space assumption (contact half-width b << the radii), which
# :func:`half_width_approach` bounds at b = HALF_WIDTH_LIMIT r, far below u = e^-3; the kernel
# still needs a force at any penetration, so past u = e^-3 (:func:`line_continuation`, where the
# tangent stiffness has risen to a) the law is continued linearly with stiffness a.
LINE_U_MAX = math.exp(-3.0)
HALF_WIDTH_LIMIT = 0.3      # b / r: the contact arc within ±17.5°, see half_width_load


@njit
def line_continuation(clearance):
    """delta_c = 8 c / e^3 [m]: where the kernel continues the line-contact law linearly (a
    numerical continuation, far past the law's validity bound :func:`half_width_approach`)."""
    return 8.0 * clearance * LINE_U_MAX


def effective_modulus(youngs_modulus: float, poisson: float) -> float:
    """E* = E / (2 (1 - nu^2)) [Pa] of two bodies of the same material
    (1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2)."""
    return youngs_modulus / (2.0 * (1.0 - poisson ** 2))


def conforming_radius(r: float, clearance: float) -> float:
    """R_eff = r R / (R - r) [m] of a journal of radius r in a bore of radius R = r + c
    (1/R_eff = 1/r - 1/R: the concave bore counts negative, Johnson §4.3)."""
    return r * (r + clearance) / clearance


def line_half_width(force: float, r: float, clearance: float, a: float) -> float:
    """Hertz half-width b = sqrt(4 F R_eff / (pi L E*)) [m] of the internal line contact carrying
    ``force`` F (Johnson §4.3, two cylinders in line contact, load per length F / L), a = pi L E*."""
    return math.sqrt(4.0 * force * conforming_radius(r, clearance) / a)


def half_width_load(r: float, clearance: float, a: float,
                    limit: float = HALF_WIDTH_LIMIT) -> float:
    """F_b = a (limit r)^2 / (4 R_eff) [N]: the load at which :func:`line_half_width` reaches
    ``limit`` times the journal radius r.

    Why b <= 0.3 r (a chosen limit, stated by its geometry): Hertz's solution treats each body as an elastic half-space, valid while the
    contact is small against the radii. At b = 0.3 r the contact arc spans ±17.5° of the journal,
    the surface normal at its edges has turned by 17.5° (its radial share cos 17.5° = 0.954) and
    the arc is 1.6 % longer than its chord: still a nearly flat contact. Beyond it the conforming
    contact's pressure spreads over an arc that Hertz's flat-strip pressure no longer describes."""
    if not 0.0 < limit < 1.0:
        raise ValueError(f"limit (half-width / radius) must be in (0, 1); got {limit!r}")
    b = limit * r
    return a * b * b / (4.0 * conforming_radius(r, clearance))


def half_width_approach(r: float, clearance: float, limit: float = HALF_WIDTH_LIMIT) -> float:
    """Approach delta_b [m] of Johnson's internal line contact when its half-width reaches
    ``limit`` r: delta_b = 4 c u_b (-ln u_b - 1) with u_b = F_b / (4 a c) = limit^2 r / (16 (r + c)).

    a = pi L E* cancels, so delta_b depends on the geometry (r, c) only: 28.0 µm = 0.093 c for the
    paper's journal (r = 30 mm, c = 300 µm); 55.9 µm for the stator (R_a = 45 mm, g_0 = 600 µm)."""
    if r <= 0.0 or clearance <= 0.0:
        raise ValueError(f"r and clearance must be > 0; got r = {r!r}, clearance = {clearance!r}")
    u = limit * limit * r / (16.0 * (r + clearance))
    return 4.0 * clearance * u * (-math.log(u) - 1.0)


@njit
def line_deflection(F, a, c):
    """Approach delta(F) of Johnson's internal line contact, a = pi L E*, clearance c [m]."""
    if F <= 0.0:
        return 0.0
    return F / a * (math.log(4.0 * a * c / F) - 1.0)


@njit
def line_elastic_force(delta, a, c):
    """F(delta) inverting :func:`line_deflection` (Newton on ln F; quadratic convergence from
    the fixed-point start), continued linearly with slope a past :func:`line_continuation`."""
    if delta <= 0.0:
        return 0.0
    f_v = 4.0 * a * c * LINE_U_MAX
    d_v = line_continuation(c)
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
    F delta - ∫ delta dF), plus the linear continuation's share past :func:`line_continuation`."""
    if delta <= 0.0:
        return 0.0
    d_v = line_continuation(c)
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


def line_stiffness(scene) -> float:
    """a = π L E* [N/m] of the retainer's steel line contact (``contact.length``, the bearing
    steel's E and ν)."""
    b = scene.bearing
    return math.pi * scene.contact.length * effective_modulus(b.youngs_modulus, b.poisson)


def validity_bound(scene) -> tuple[float, float, str]:
    """(penetration [m], elastic force there [N], criterion) past which the law leaves its
    assumptions (module docstring)."""
    c, r = scene.contact, scene.rotor.journal_radius
    d = half_width_approach(r, c.clearance)
    return (d, float(line_elastic_force(d, line_stiffness(scene), c.clearance)),
            f"Hertz half-width b = {HALF_WIDTH_LIMIT:g} x rotor.journal_radius (line-contact"
            " approach)")


def tangent_stiffness(scene, load: float) -> float:
    """dF/dδ [N/m] at ``load``: a / (ln(4ac/F) − 2) (from :func:`line_deflection`), capped at a."""
    a = line_stiffness(scene)
    lg = math.log(4.0 * a * scene.contact.clearance / load) if load > 0.0 else math.inf
    return a / (lg - 2.0) if lg > 3.0 else a


@njit_inline
def force(delta, ddelta, P):
    """(F_r, elastic part) at penetration delta > 0 and its rate."""
    f_el = line_elastic_force(delta, P[P_HL_A], P[P_CLR])
    return hunt_crossley(f_el, ddelta, P[P_HL_CHI]), f_el


@njit_inline
def potential(delta, P):
    """Elastic energy stored at penetration delta."""
    return line_potential(delta, P[P_HL_A], P[P_CLR])
