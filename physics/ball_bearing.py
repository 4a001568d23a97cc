"""Planar Sopanen-Mikkola deep-groove ball bearing (spec §4), or a linear spring bearing, and the
sleeve (the bearing's inner ring) it carries.

Python side: Hertz and film constants from the bearing geometry (computed once per scene).
Kernel side: per-ball Hertz loads with clearance and film, bearing friction torque.

An effect of the drop model (docs/architecture.md "Adding an effect"): its scene keys, packed
slots, per-plane states and parameter packing are declared here; :mod:`physics.model` composes
them.
"""
import math
from dataclasses import dataclass

import numpy as np

from ._jit import njit, njit_borrow, njit_inline
from .amb import static_weight_share
from .laws.step import smooth_sign
from .rotor import add_dissipated, add_external
from .support import body_energy, spin_energy, spring_energy

SCENE_KEYS = ("sleeve.mass", "sleeve.spin_inertia", "bearing.*", "effects.retainer_bearing",
              "effects.ehl_film", "effects.bearing_friction", "effects.sleeve_inertia")
RB_RIGID, RB_LINEAR, RB_SM = 0, 1, 2
#: per retainer plane: sleeve position and velocity, cage angle, sleeve spin (index slots)
PLANE_STATES = ("sx", "sy", "svx", "svy", "theta", "omega_s")


def declare(layout) -> None:
    """The sleeve's and the bearing's parameters, flags and per-plane state slots."""
    layout.params.add_each(
        "sleeve.mass", "sleeve.spin_inertia", "bearing.balls", "bearing.half_play",
        "bearing.stiffness", "bearing.film_coef", "bearing.damping", "bearing.linear_stiffness",
        "bearing.cage_ratio", "bearing.m0_low", "bearing.m0_coef", "bearing.m1_coef",
        "bearing.seal_torque",
        consts=("P_MS", "P_JS", "P_NB", "P_HALF_PLAY", "P_KTOT", "P_FILM", "P_CB", "P_KLIN",
                "P_CAGE", "P_M0_LOW", "P_M0_COEF", "P_M1_COEF", "P_MSEAL"))
    layout.index.add_each("flag.retainer_bearing", "flag.ehl_film", "flag.bearing_friction",
                          "flag.sleeve_inertia", consts=("F_RB", "F_FILM", "F_BFRIC", "F_SLEEVE_J"))
    layout.plane.add_each(*PLANE_STATES, consts=("J_SX", "J_SY", "J_SVX", "J_SVY", "J_TH", "J_WS"))


def pack(scene, P, I, layout) -> None:
    """The bearing's parameters (film reference load, spec §4: Q_n = 5 x static bearing load /
    z) and flags."""
    s, fx, p, i = scene, scene.effects, layout.params, layout.index
    I[i["flag.retainer_bearing"]] = {"rigid": RB_RIGID, "linear": RB_LINEAR,
                                     "sopanen_mikkola": RB_SM}[fx.retainer_bearing]
    I[i["flag.ehl_film"]] = fx.ehl_film and fx.retainer_bearing == "sopanen_mikkola"
    I[i["flag.bearing_friction"]] = fx.bearing_friction
    I[i["flag.sleeve_inertia"]] = fx.sleeve_inertia
    P[p["sleeve.mass"]], P[p["sleeve.spin_inertia"]] = s.sleeve.mass, s.sleeve.spin_inertia
    b = s.bearing
    bc = bearing_constants(b, static_weight_share(s))
    P[p["bearing.balls"]], P[p["bearing.half_play"]] = b.balls, b.clearance / 2.0
    P[p["bearing.stiffness"]], P[p["bearing.film_coef"]] = bc.K_tot, bc.film_coef
    P[p["bearing.damping"]], P[p["bearing.linear_stiffness"]] = b.damping, b.linear_stiffness
    P[p["bearing.cage_ratio"]] = cage_ratio(b)
    P[p["bearing.m0_low"]], P[p["bearing.m0_coef"]] = bc.m0_low, bc.m0_coef
    P[p["bearing.m1_coef"]], P[p["bearing.seal_torque"]] = bc.m1_coef, b.seal_torque


def plane_states(scene, I, base, layout, sizes, plane, add) -> None:
    """Retainer plane ``plane``'s sleeve states: its position and velocity (unless rigidly mounted
    in the housing), the cage angle (Sopanen-Mikkola balls), its spin (with sleeve inertia)."""
    fx, j, c = scene.effects, layout.plane, sizes.clearance
    if fx.retainer_bearing != "rigid":
        for n, sz in (("sx", c), ("sy", c), ("svx", sizes.velocity), ("svy", sizes.velocity)):
            I[base + j[n]] = add(f"{plane}.{n}", sz)
    if fx.retainer_bearing == "sopanen_mikkola":
        I[base + j["theta"]] = add(f"{plane}.theta", math.pi)
    if fx.sleeve_inertia:
        I[base + j["omega_s"]] = add(f"{plane}.omega_s", sizes.spin)


# ------------------------------------------------------------------------------- constants --
def reduced_modulus(E: float, nu: float) -> float:
    """E' = E / (1 - nu^2) (spec §4)."""
    return E / (1.0 - nu * nu)


def contact_radii(D: float, r_x: float, r_y: float) -> tuple[float, float]:
    """Effective radii R_x = (2/D + 1/r_x)^-1, R_y = (2/D + 1/r_y)^-1 of a ball-race contact."""
    return 1.0 / (2.0 / D + 1.0 / r_x), 1.0 / (2.0 / D + 1.0 / r_y)


def brewe_hamrock(R_x: float, R_y: float) -> tuple[float, float, float, float]:
    """(R, k, E, F) of a point contact: the curvature sum R = (1/R_x + 1/R_y)^-1 and the
    Brewe-Hamrock fits of the ellipticity k = a/b and of the elliptic integrals E and F."""
    return (1.0 / (1.0 / R_x + 1.0 / R_y), 1.0339 * (R_y / R_x) ** 0.636,
            1.0003 + 0.5968 * R_x / R_y, 1.5277 + 0.6023 * math.log(R_y / R_x))


def hertz_constant(R_x: float, R_y: float, E_red: float) -> float:
    """Brewe-Hamrock point-contact constant K in Q = K delta^1.5 [N/m^1.5]."""
    R, k, E_bar, F_bar = brewe_hamrock(R_x, R_y)
    return math.pi * k * E_red * math.sqrt(R * E_bar / (4.5 * F_bar ** 3))


def contact_pressure_coef(R_x: float, R_y: float, E_red: float) -> float:
    """c in p_max = c Q^(1/3): the largest Hertz pressure of a point contact under ball load Q
    [Pa for N], p_max = 3 Q / (2 pi a b) with the Brewe-Hamrock semi-axes
    a = (6 k^2 E Q R / (pi E'))^(1/3), b = (6 E Q R / (pi k E'))^(1/3) (R, k, E from
    :func:`brewe_hamrock`, E' = ``E_red``; the ellipse of :func:`hertz_constant`)."""
    R, k, E_bar, _ = brewe_hamrock(R_x, R_y)
    return 1.5 / math.pi * (math.pi ** 2 * E_red ** 2
                            / (36.0 * k * E_bar ** 2 * R ** 2)) ** (1.0 / 3.0)


def raceway_radii(b) -> list[tuple[float, float]]:
    """(R_x, R_y) of the inner and the outer ball-race contact of a bearing description."""
    D, dm, Pd, f = b.ball_diameter, b.pitch_diameter, b.clearance, b.conformity
    return [contact_radii(D, r_x, -f * D)
            for r_x in ((dm - D - Pd / 2.0) / 2.0, -(dm + D + Pd / 2.0) / 2.0)]


def max_contact_pressure(b, Q):
    """Largest Hertz contact pressure [Pa] at either raceway for ball load(s) Q [N]."""
    E_red = reduced_modulus(b.youngs_modulus, b.poisson)
    c = max(contact_pressure_coef(R_x, R_y, E_red) for R_x, R_y in raceway_radii(b))
    return c * np.cbrt(Q)


@dataclass(frozen=True)
class BearingConstants:
    """Everything the kernels need from a 6016-type bearing description."""
    K_in: float
    K_out: float
    K_tot: float        # N/m^1.5, series combination of inner and outer contacts
    film_coef: float    # h = film_coef * |omega|^0.67 [m, omega in rad/s]
    m0_low: float       # N m, Palmgren viscous torque below nu*n = 2000
    m0_coef: float      # N m / (rad/s)^(2/3), Palmgren viscous torque above
    m1_coef: float      # N m / N^1.5, load torque M_1 = m1_coef * P^1.5


def ball_stiffness(b) -> tuple[float, float, float]:
    """(K_in, K_out, K_tot) [N/m^1.5]: the inner and outer ball-race Hertz constants and their
    series combination, Q = K_tot delta^1.5 for the total approach of one ball."""
    E_red = reduced_modulus(b.youngs_modulus, b.poisson)
    K_in, K_out = (hertz_constant(R_x, R_y, E_red) for R_x, R_y in raceway_radii(b))
    return K_in, K_out, (K_in ** (-2.0 / 3.0) + K_out ** (-2.0 / 3.0)) ** (-1.5)


def static_max_ball_load(b, load: float) -> float:
    """Most heavily loaded ball's load [N] when the bearing carries the static radial ``load``
    [N] with a ball under it and no film (the model's ball forces, :func:`ball_forces`; the
    ring displacement by bisection). About 4.5 load / z at C_0 (Stribeck's 5 load / z at
    small loads, where the clearance leaves fewer balls loaded)."""
    K_tot = ball_stiffness(b)[2]
    half_play = b.clearance / 2.0

    def forces(u: float) -> tuple:                 # ring displaced by u towards the ball at 0
        return ball_forces(u, 0.0, 0.0, b.balls, half_play, 0.0, K_tot)

    lo = half_play
    hi = lo + (load / K_tot) ** (2.0 / 3.0)        # one ball alone carries the load
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if forces(mid)[0] < load:
            lo = mid
        else:
            hi = mid
    return forces(hi)[5]


def bearing_constants(b, static_load: float) -> BearingConstants:
    """Constants for a :class:`physics.scene.Bearing` carrying ``static_load`` newtons."""
    D, dm = b.ball_diameter, b.pitch_diameter
    E_red = reduced_modulus(b.youngs_modulus, b.poisson)
    K_in, K_out, K_tot = ball_stiffness(b)

    # Hamrock-Dowson central film, h_c = 2.69 R_x U^.67 G^.53 W^-.067 (1 - .61 e^-.73k), with
    # U proportional to the entrainment speed u_e = (dm^2 - D^2)/(4 dm) |omega|.
    Q_n = 5.0 * static_load / b.balls
    G = b.pressure_viscosity * E_red
    film_coef = 0.0
    for R_x, R_y in raceway_radii(b):
        k = brewe_hamrock(R_x, R_y)[1]
        U_per_omega = b.viscosity * (dm * dm - D * D) / (4.0 * dm) / (E_red * R_x)
        W = Q_n / (E_red * R_x * R_x)
        film_coef += (2.69 * R_x * U_per_omega ** 0.67 * G ** 0.53 * W ** -0.067
                      * (1.0 - 0.61 * math.exp(-0.73 * k)))

    # Friction torque in SI from the catalogue forms (N mm, cSt, rpm, mm).
    dm_mm3 = (dm * 1e3) ** 3
    nu_cst = b.viscosity / b.oil_density * 1e6
    rpm_per_rad_s = 60.0 / (2.0 * math.pi)
    m0_low = 160e-7 * b.f0 * dm_mm3 * 1e-3
    m0_coef = 1e-7 * b.f0 * (nu_cst * rpm_per_rad_s) ** (2.0 / 3.0) * dm_mm3 * 1e-3
    m1_coef = 0.0007 / math.sqrt(b.static_load_rating) * dm
    return BearingConstants(K_in, K_out, K_tot, film_coef, m0_low, m0_coef, m1_coef)


def cage_ratio(b) -> float:
    """Cage speed / inner-ring speed with the outer ring still: (1 - D/d_m) / 2."""
    return 0.5 * (1.0 - b.ball_diameter / b.pitch_diameter)


# --------------------------------------------------------------------------------- kernels --
@njit
def film_thickness(omega_rel, film_coef):
    """Total EHL film h(omega) [m] and dh/domega; h ~ |omega|^0.67, regularised at 1 rad/s so it
    is smooth through omega = 0."""
    w2 = omega_rel * omega_rel + 1.0
    p = w2 ** 0.335
    return film_coef * (p - 1.0), film_coef * 0.67 * omega_rel * p / w2


@njit
def ball_forces(ux, uy, cage, n_balls, half_play, h, K_tot):
    """Sum of Hertz ball loads for inner-ring displacement (ux, uy) relative to the outer ring.

    delta_j = ux cos(b_j) + uy sin(b_j) - P_d/2 + h,  Q_j = K_tot delta_j^1.5 (delta_j > 0),
    b_j = cage + 2 pi j / z. Returns (Fx, Fy, V, dV/dcage, sum Q_j, max Q_j): the force on the
    outer ring (the inner ring gets the opposite), the stored energy sum K_tot delta^2.5/2.5, its
    cage-angle derivative (work the planar model does not return as a torque), dV/dh (both for
    the energy audit) and the most heavily loaded ball's load (diagnostics).
    """
    return _ball_sums(ux, uy, cage, n_balls, half_play, h, K_tot, False)[:6]


@njit
def ball_forces_with_dry(ux, uy, cage, n_balls, half_play, h, K_tot):
    """:func:`ball_forces` at film ``h`` followed by (Fx, Fy, dV/dcage) at zero film, from one
    pass over the balls (the massless-sleeve energy audit needs both; two calls cost ~20 % of
    a right-hand side). Each result is bit-identical to the separate call's."""
    return _ball_sums(ux, uy, cage, n_balls, half_play, h, K_tot, True)


@njit
def _ball_sums(ux, uy, cage, n_balls, half_play, h, K_tot, dry):
    """The ball loop of :func:`ball_forces`; with ``dry`` also the zero-film sums (else zeros)."""
    c0 = math.cos(cage)
    s0 = math.sin(cage)
    dc = math.cos(2.0 * math.pi / n_balls)
    ds = math.sin(2.0 * math.pi / n_balls)
    fx = 0.0
    fy = 0.0
    V = 0.0
    dV = 0.0
    qsum = 0.0
    qmax = 0.0
    fx0 = 0.0
    fy0 = 0.0
    dV0 = 0.0
    clear = half_play - h
    for _ in range(n_balls):
        proj = ux * c0 + uy * s0
        d = proj - clear
        if d > 0.0:
            q = K_tot * d * math.sqrt(d)
            fx += q * c0
            fy += q * s0
            V += 0.4 * q * d
            dV += q * (-ux * s0 + uy * c0)
            qsum += q
            qmax = max(qmax, q)
            if dry:
                d = proj - half_play
                if d > 0.0:
                    q = K_tot * d * math.sqrt(d)
                    fx0 += q * c0
                    fy0 += q * s0
                    dV0 += q * (-ux * s0 + uy * c0)
        c0, s0 = c0 * dc - s0 * ds, s0 * dc + c0 * ds
    return fx, fy, V, dV, qsum, qmax, fx0, fy0, dV0


@njit
def drag_torque_magnitude(omega_rel, load, m0_low, m0_coef, m1_coef, seal):
    """|M| = M_0 + M_1 + M_s [N m] (Palmgren viscous, load-dependent, seal).

    M_0 uses max(low-speed value, high-speed law): equal to the catalogue form except within 1 %
    around nu*n = 2000, where it removes the catalogue's small jump.
    """
    m0 = m0_coef * np.cbrt(omega_rel * omega_rel)
    if m0 < m0_low:
        m0 = m0_low
    return m0 + m1_coef * load * math.sqrt(load) + seal


# ------------------------------------------------------------------ the retainer plane's kernel --
@njit_inline
def sleeve_motion(y, I, k):
    """Sleeve centre position and velocity at plane k (the housing's when rigidly mounted)."""
    base = I_PLANES + k * N_PLANE_IDX
    i, j = I[base + J_SX], I[base + J_SVX]
    if i < 0:
        i, j = I[base + J_HX], I[base + J_HVX]
        if i < 0:
            return 0.0, 0.0, 0.0, 0.0
    return y[i], y[i + 1], y[j], y[j + 1]


@njit_inline
def sleeve_on_bearing(y, P, I, dy, aux, k, load, f_r, f_mu, cfx, cfy, ws, p_drag, sx, sy, svx,
                      svy, hx, hy, hvx, hvy):
    """Retainer plane k's bearing between the sleeve (inner ring, at (sx, sy) moving at (svx,
    svy)) and the housing (outer ring, at (hx, hy) moving at (hvx, hvy)) under the contact's
    normal and friction forces f_r, f_mu and its force (cfx, cfy) on the sleeve: the bearing's
    dissipated and non-potential powers into the load, the sleeve's and the cage's rates, the
    plane's bearing diagnostics. Returns (load, rx, ry): the force on the housing (the bearing's
    reaction, or the contact's through a sleeve rigidly mounted in it)."""
    base = I_PLANES + k * N_PLANE_IDX
    i_ws = I[base + J_WS]
    bfx = 0.0                                # bearing force on the sleeve
    bfy = 0.0
    p_bdamp = 0.0                            # power of the bearing's dashpot c_b
    bload = f_r
    qsum = 0.0
    qmax = 0.0                               # most heavily loaded ball (SM bearing only)
    dh_dw = 0.0
    ux, uy = sx - hx, sy - hy
    uvx, uvy = svx - hvx, svy - hvy
    i_th = I[base + J_TH]
    if I[F_RB] == RB_SM:
        h = 0.0
        if I[F_FILM]:
            h, dh_dw = film_thickness(ws, P[P_FILM])
        cage = P[P_CAGE] * y[i_th]
        if I[F_FILM] and i_ws < 0:
            # massless sleeve: the film follows the algebraic rolling speed, so the audit
            # keeps the ball potential at zero film (mechanical_energy) and counts the
            # film's share of the ball forces as a non-potential force (dV: the zero-film
            # cage derivative, to match); one pass over the balls gives both
            qx, qy, _, _, qsum, qmax, qx0, qy0, dV = ball_forces_with_dry(
                ux, uy, cage, int(P[P_NB]), P[P_HALF_PLAY], h, P[P_KTOT])
            load = add_external(load, (qx0 - qx) * uvx + (qy0 - qy) * uvy)
        else:
            qx, qy, _, dV, qsum, qmax = ball_forces(ux, uy, cage, int(P[P_NB]),
                                                    P[P_HALF_PLAY], h, P[P_KTOT])
        bfx = -qx - P[P_CB] * uvx
        bfy = -qy - P[P_CB] * uvy
        bload = math.sqrt(qx * qx + qy * qy)
        p_bdamp = P[P_CB] * (uvx * uvx + uvy * uvy)
        load = add_external(add_dissipated(load, p_bdamp), dV * P[P_CAGE] * ws)
        if dy is not None:                   # cage rotation under load (no torque in the model)
            dy[i_th] = ws
    elif I[F_RB] == RB_LINEAR:
        bfx = -P[P_KLIN] * ux - P[P_CB] * uvx
        bfy = -P[P_KLIN] * uy - P[P_CB] * uvy
        bload = P[P_KLIN] * math.sqrt(ux * ux + uy * uy)
        p_bdamp = P[P_CB] * (uvx * uvx + uvy * uvy)
        load = add_dissipated(load, p_bdamp)

    # --- sleeve spin ---
    drag_t = 0.0
    if i_ws >= 0:
        if I[F_BFRIC]:
            drag_t = drag_torque_magnitude(ws, bload, P[P_M0_LOW], P[P_M0_COEF], P[P_M1_COEF],
                                           P[P_MSEAL]) * smooth_sign(ws, P[P_WL])
            p_drag = drag_t * ws
            load = add_dissipated(load, p_drag)
        if dy is not None:
            dws = (P[P_RS] * f_mu - drag_t) / P[P_JS]
            dy[i_ws] = dws
            if I[F_RB] == RB_SM and I[F_FILM]:
                # film growth changes the ball potential without a force doing work
                load = add_external(load, qsum * dh_dw * dws)

    # --- sleeve translation ---
    i_sx = I[base + J_SX]
    if dy is not None and i_sx >= 0:
        ms = P[P_MS]
        dy[i_sx] = svx
        dy[I[base + J_SY]] = svy
        dy[I[base + J_SVX]] = (cfx + bfx) / ms
        dy[I[base + J_SVY]] = (cfy + bfy) / ms - P[P_G]
    o = k * N_AUX_PLANE
    aux[o + A_LOAD] = bload
    aux[o + A_WS] = ws
    aux[o + A_DRAG] = drag_t
    aux[o + A_QMAX] = qmax
    aux[o + A_PBDAMP] = p_bdamp
    aux[o + A_PDRAG] = p_drag
    if i_sx >= 0:
        return load, -bfx, -bfy
    return load, cfx, cfy


@njit_borrow
def sleeve_energy(y, P, I, k, E, sx, sy, svx, svy):
    """E plus the kinetic and gravitational energy of retainer plane k's sleeve."""
    base = I_PLANES + k * N_PLANE_IDX
    if I[base + J_SX] >= 0:
        E += body_energy(P[P_MS], svx, svy, P[P_G], sy)
    i_ws = I[base + J_WS]
    if i_ws >= 0:
        E += spin_energy(P[P_JS], y[i_ws])
    return E


@njit_borrow
def bearing_energy(y, P, I, k, E, sx, sy, hx, hy):
    """E plus the elastic energy of retainer plane k's bearing (the balls' at zero film without
    sleeve inertia, see :func:`sleeve_on_bearing`)."""
    base = I_PLANES + k * N_PLANE_IDX
    i_ws = I[base + J_WS]
    ux, uy = sx - hx, sy - hy
    if I[F_RB] == RB_SM:
        ws = y[i_ws] if i_ws >= 0 else 0.0
        h = film_thickness(ws, P[P_FILM])[0] if I[F_FILM] and i_ws >= 0 else 0.0
        _, _, V, _, _, _ = ball_forces(ux, uy, P[P_CAGE] * y[I[base + J_TH]], int(P[P_NB]),
                                       P[P_HALF_PLAY], h, P[P_KTOT])
        E += V
    elif I[F_RB] == RB_LINEAR:
        E += spring_energy(P[P_KLIN], ux, uy)
    return E
