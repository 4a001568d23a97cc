"""Rotor-sleeve circle-in-circle contact (paper eqs. 14-19, spec §3).

An effect of the drop model (docs/architecture.md "Adding an effect"): its scene keys, packed
slots and parameter packing are declared here (no state of its own), and the retainer plane's
diagnostics table (its own entries and the retainer bearing's, in the order of ``Result.aux``).
"""
import math

from ._jit import njit, njit_borrow, njit_inline
from . import ball_bearing, laws
from .laws.hertz_line import (HALF_WIDTH_LIMIT, LINE_U_MAX, conforming_radius,  # noqa: F401
                              effective_modulus, half_width_approach, half_width_load,
                              hunt_crossley, hysteresis_factor, line_continuation,
                              line_deflection, line_elastic_force, line_half_width,
                              line_potential)
from .laws.power_law import contact_potential, normal_force, power_law_approach  # noqa: F401
from .laws.step import smooth_sign, step  # noqa: F401
from .rotor import ST_RB1, add_dissipated, add_station_force, add_torque
from .thermal import contact_friction

SCENE_KEYS = ("contact.clearance", "contact.stiffness", "contact.exponent", "contact.damping",
              "contact.damping_depth", "contact.friction", "contact.threshold_rpm",
              "contact.law", "contact.length", "contact.restitution", "rotor.journal_radius",
              "bearing.youngs_modulus", "bearing.poisson", "effects.friction")
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
    layout.params.add_each(
        "contact.clearance", "sleeve.radius", "contact.stiffness", "contact.exponent",
        "contact.damping", "contact.damping_depth", "contact.friction", "contact.threshold_speed",
        "contact.threshold_velocity", "contact.line_coefficient", "contact.hysteresis",
        consts=("P_CLR", "P_RS", "P_KC", "P_EC", "P_CMAX", "P_DC", "P_MU", "P_WL", "P_VL",
                "P_HL_A", "P_HL_CHI"))
    layout.index.add("flag.friction", const="F_FRIC")
    layout.index.add("flag.law", const="F_LAW")
    layout.plane_aux.add_each(*PLANE_DIAGNOSTICS, consts=(
        "A_FR", "A_FMU", "A_DELTA", "A_LOAD", "A_WS", "A_DRAG", "A_PFRIC", "A_QMAX", "A_PCDAMP",
        "A_PBDAMP", "A_PDRAG", "A_PSUPPORT"))


def pack(scene, P, I, layout) -> None:
    """The contact's parameters (the hertz_line law's pi L E* and Hunt-Crossley factor chi) and
    flags (friction slip law, normal-force law)."""
    s, p, i = scene, layout.params, layout.index
    c = s.contact.clearance
    I[i["flag.friction"]] = laws.slip_law_flag(s.effects.friction)
    I[i["flag.law"]] = laws.contact_law_flag(s.contact.law)
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




# ------------------------------------------------------------------ the retainer plane's kernel --
@njit_inline
def sleeve_contact(y, P, I, aux, k, load, px, py, pvx, pvy, sx, sy, svx, svy, ws):
    """Retainer plane k's rotor-sleeve contact (eqs. 14-19): the rotor axis at (px, py) moving at
    (pvx, pvy), the sleeve at (sx, sy) moving at (svx, svy) spinning at ws. Adds the contact's
    force and torque on the rotor and its dissipated power to the load and writes the plane's
    contact diagnostics. Returns (load, f_r, f_mu, cfx, cfy, ws, p_drag): the normal and friction
    forces, the force on the sleeve, the sleeve speed (a massless sleeve rolls at the algebraic
    speed w*) and the drag power a massless sleeve passes on."""
    W = y[I[S_W]]
    mu = contact_friction(y, P, I, k)
    er, nx, ny = geometry(px - sx, py - sy)
    tx, ty = -ny, nx
    delta = er - P[P_CLR]
    rel_vx, rel_vy = pvx - svx, pvy - svy
    f_r = 0.0
    f_mu = 0.0
    p_fric = 0.0                             # power dissipated by the contact friction
    p_cdamp = 0.0                            # ... by the contact's normal damping
    p_drag = 0.0                             # ... by the retainer bearing's drag torque
    if delta > 0.0:
        ddelta = nx * rel_vx + ny * rel_vy
        f_r, f_el = laws.normal_force(I[F_LAW], delta, ddelta, P)    # the contact law
        p_cdamp = (f_r - f_el) * ddelta
        load = add_dissipated(load, p_cdamp)
    et = tx * rel_vx + ty * rel_vy           # whirl velocity along t
    fric = I[F_FRIC]                         # the slip law
    if laws.has_friction(fric) and f_r > 0.0:
        if I[F_SLEEVE_J]:
            slip, threshold = laws.slip_velocity(fric, et, W, ws, P)
            f_mu = friction_force(mu, f_r, slip, threshold)
            p_fric = f_mu * (et + W * P[P_RJ] - ws * P[P_RS])
            load = add_dissipated(load, p_fric)
        else:
            # massless-sleeve limit: the sleeve rolls at w* and passes on only the drag torque
            w_roll, v_sign, threshold = laws.rolling(fric, et, W, P)
            sgn = smooth_sign(v_sign, threshold)
            drag = 0.0
            if I[F_BFRIC]:
                drag = ball_bearing.drag_torque_magnitude(w_roll, f_r, P[P_M0_LOW], P[P_M0_COEF],
                                                         P[P_M1_COEF], P[P_MSEAL]) / P[P_RS]
            f_mu = sgn * min(mu * f_r, drag)
            ws = w_roll * min(1.0, mu * f_r / drag) if drag > 0.0 else w_roll
            p_fric = f_mu * (et + W * P[P_RJ] - ws * P[P_RS])
            # all the rotor loses: p_fric plus the bearing drag f_mu ws R the sleeve passes on
            p_drag = f_mu * P[P_RS] * ws      # the drag F_mu R the sleeve passes on
            load = add_dissipated(load, f_mu * (et + W * P[P_RJ]))
    # forces on the rotor at this plane: -F_r n - F_mu t, spin torque -r F_mu
    cfx = f_r * nx + f_mu * tx               # force on the sleeve side
    cfy = f_r * ny + f_mu * ty
    load = add_torque(add_station_force(load, P, I, aux, ST_RB1 + k, -cfx, -cfy),
                      -(P[P_RJ] * f_mu))
    o = k * N_AUX_PLANE
    aux[o + A_FR] = f_r
    aux[o + A_FMU] = f_mu
    aux[o + A_DELTA] = delta
    aux[o + A_PFRIC] = p_fric
    aux[o + A_PCDAMP] = p_cdamp
    return load, f_r, f_mu, cfx, cfy, ws, p_drag


@njit_borrow
def energy(y, P, I, k, E, px, py, sx, sy):
    """E plus the elastic energy stored in retainer plane k's contact."""
    er, _, _ = geometry(px - sx, py - sy)
    return E + laws.potential(I[F_LAW], er - P[P_CLR], P)
