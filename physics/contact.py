"""Rotor-sleeve circle-in-circle contact (paper eqs. 14-19, spec §3).

An effect of the drop model (docs/architecture.md "Adding an effect"): its scene keys, packed
slots and parameter packing are declared here (no state of its own), and the retainer plane's
diagnostics table (its own entries and the retainer bearing's, in the order of ``Result.aux``).
"""
import math

from ._jit import njit

SCENE_KEYS = ("contact.clearance", "contact.stiffness", "contact.exponent", "contact.damping",
              "contact.damping_depth", "contact.friction", "contact.threshold_rpm",
              "contact.law", "contact.length", "contact.restitution", "rotor.journal_radius",
              "bearing.youngs_modulus", "bearing.poisson", "effects.friction")
FRIC_NONE, FRIC_PAPER, FRIC_KINEMATIC = 0, 1, 2
LAW_PAPER, LAW_HERTZ_LINE = 0, 1
STANDARD_GRAVITY = 9.80665  # m/s^2: sets the hertz_line reference impact speed sqrt(2 g c)
#: the per-plane diagnostics (Result.aux columns): contact normal force, friction force,
#: penetration, bearing load, sleeve speed, bearing drag torque, then the powers [W] each
#: dissipative element takes out of the mechanical energy (physics/dissipation.py checks each is
#: >= 0): contact friction, (largest ball load), contact normal damping, ball-bearing dashpot,
#: bearing drag, support dashpot
PLANE_DIAGNOSTICS = ("contact_force", "friction_force", "penetration", "bearing_load",
                     "sleeve_speed", "drag_torque", "friction_power", "ball_load_max",
                     "contact_damping_power", "bearing_damping_power", "drag_power",
                     "support_power")


def declare(layout) -> None:
    """The contact's parameters and flags, and the retainer plane's diagnostics."""
    for name in ("contact.clearance", "sleeve.radius", "contact.stiffness", "contact.exponent",
                 "contact.damping", "contact.damping_depth", "contact.friction",
                 "contact.threshold_speed", "contact.threshold_velocity",
                 "contact.line_coefficient", "contact.hysteresis"):
        layout.params.add(name)
    layout.index.add("flag.friction")
    layout.index.add("flag.law")
    for name in PLANE_DIAGNOSTICS:
        layout.plane_aux.add(name)


def pack(scene, P, I, layout) -> None:
    """The contact's parameters (the hertz_line law's pi L E* and Hunt-Crossley factor chi) and
    flags (friction slip law, normal-force law)."""
    s, p, i = scene, layout.params, layout.index
    c = s.contact.clearance
    I[i["flag.friction"]] = {"none": FRIC_NONE, "paper": FRIC_PAPER,
                             "kinematic": FRIC_KINEMATIC}[s.effects.friction]
    I[i["flag.law"]] = {"paper": LAW_PAPER, "hertz_line": LAW_HERTZ_LINE}[s.contact.law]
    P[p["contact.clearance"]] = c
    P[p["sleeve.radius"]] = s.rotor.journal_radius + c
    P[p["contact.stiffness"]], P[p["contact.exponent"]] = s.contact.stiffness, s.contact.exponent
    P[p["contact.damping"]], P[p["contact.damping_depth"]] = (s.contact.damping,
                                                              s.contact.damping_depth)
    P[p["contact.friction"]] = s.contact.friction
    P[p["contact.threshold_speed"]] = s.contact.threshold_rpm * math.pi / 30.0
    P[p["contact.threshold_velocity"]] = P[p["contact.threshold_speed"]] * s.rotor.journal_radius
    b, ct = s.bearing, s.contact
    e_star = b.youngs_modulus / (2.0 * (1.0 - b.poisson ** 2))     # steel journal in a steel sleeve
    P[p["contact.line_coefficient"]] = math.pi * ct.length * e_star
    P[p["contact.hysteresis"]] = hysteresis_factor(ct.restitution,
                                                   math.sqrt(2.0 * STANDARD_GRAVITY * ct.clearance))


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


def power_law_approach(load: float, K: float, e: float) -> float:
    """delta = (F / K)^(1/e) [m]: the penetration at which the paper's law K delta^e (eq. 14)
    carries ``load``."""
    if load < 0.0 or K <= 0.0 or e <= 0.0:
        raise ValueError(f"load >= 0, K > 0, e > 0 required; got {load!r}, {K!r}, {e!r}")
    return (load / K) ** (1.0 / e)


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
