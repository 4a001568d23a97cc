"""Elastic housing: outer ring + housing on linear spring-dampers K_s, C_s to ground (spec §1),
and the semi-active support damper (spec §6): C_s a controlled state lagging its command.

An effect of the drop model (docs/architecture.md "Adding an effect"): its scene keys, packed
slots, states and parameter packing are declared here; :mod:`physics.model` composes them.
"""
from ._jit import njit, njit_borrow, njit_inline
from .amb import clamp
from .rotor import add_dissipated

SCENE_KEYS = ("support.stiffness", "support.housing_mass", "support.damping",
              "support.damping_min", "support.damping_max", "support.damper_time_constant",
              "sleeve.mass", "effects.housing", "effects.semi_active_damper",
              "effects.retainer_bearing")
#: per retainer plane: the housing's position and velocity (index slots)
PLANE_STATES = ("hx", "hy", "hvx", "hvy")


def declare(layout) -> None:
    """The support's parameters, flag, the damper's state slot and the per-housing damping
    controls ``support.damping`` + k (the damper's command with effects.semi_active_damper)."""
    layout.params.add_each("support.stiffness", "support.housing_mass", "support.damping_min",
                           "support.damping_max", "support.damper_time_constant",
                           consts=("P_KS", "P_MH", "P_CS_MIN", "P_CS_MAX", "P_CS_TAU"))
    layout.index.add("flag.housing", const="F_HOUSING")
    layout.index.add("state.damper", const="I_CS")
    layout.plane.add_each(*PLANE_STATES, consts=("J_HX", "J_HY", "J_HVX", "J_HVY"))
    layout.controls.block("rb1.support_damping", "rb2.support_damping", consts=("U_CS1", "U_CS2"))


def pack(scene, P, I, layout) -> None:
    """The support's parameters (a rigidly mounted sleeve moves with its housing: its mass
    counts to the housing's) and flag."""
    s, p = scene, layout.params
    I[layout.index["flag.housing"]] = s.effects.housing
    has_sleeve_xy = s.effects.retainer_bearing != "rigid"
    P[p["support.stiffness"]] = s.support.stiffness
    P[p["support.housing_mass"]] = s.support.housing_mass + (0.0 if has_sleeve_xy
                                                             else s.sleeve.mass)
    P[p["support.damping_min"]], P[p["support.damping_max"]] = (s.support.damping_min,
                                                                s.support.damping_max)
    P[p["support.damper_time_constant"]] = s.support.damper_time_constant


def plane_states(scene, I, base, layout, sizes, plane, add) -> None:
    """Retainer plane ``plane``'s housing states (elastic housings only). The tolerance sizes are
    deliberately tighter than the observation sizes: they set the step sizes."""
    if not scene.effects.housing:
        return
    j, c, v = layout.plane, sizes.clearance, sizes.velocity
    for n, sz, obs in (("hx", 0.1 * c, c), ("hy", 0.1 * c, c), ("hvx", 0.01, v),
                       ("hvy", 0.01, v)):
        I[base + j[n]] = add(f"{plane}.{n}", sz, obs)


def states(scene, I, layout, sizes, add) -> None:
    """The semi-active damper's C_s of each housing (spec §6)."""
    if scene.effects.semi_active_damper:
        I[layout.index["state.damper"]] = add("RB1.Cs", scene.support.damping_max)
        add("RB2.Cs", scene.support.damping_max)


@njit
def housing_force(hx, hy, vx, vy, K_s, C_s):
    """Spring-damper force on the housing from the ground."""
    return -K_s * hx - C_s * vx, -K_s * hy - C_s * vy


@njit
def housing_rates(hx, hy, vx, vy, K_s, C_s, rx, ry, m_h, g):
    """(hx', hy', vx', vy') of a housing (mass m_h, gravity g) on its support under the force
    (rx, ry) of what it carries (the bearing's reaction, or the contact through a rigidly
    mounted sleeve)."""
    gx, gy = housing_force(hx, hy, vx, vy, K_s, C_s)
    gx += rx
    gy += ry
    return vx, vy, gx / m_h, gy / m_h - g


@njit
def damper_rate(command, C_s, c_min, c_max, tau):
    """dC_s/dt of the semi-active damper: C_s lags its command, clamped to [c_min, c_max] (the
    command is a public input, and even C_min + frac (C_max - C_min) can exceed C_max by one ulp
    at frac = 1)."""
    return (clamp(command, c_min, c_max) - C_s) / tau


@njit
def support_power(vx, vy, C_s):
    """Power [W] the support dashpot C_s dissipates."""
    return C_s * (vx * vx + vy * vy)


@njit
def body_energy(m, vx, vy, g, y):
    """Kinetic plus gravitational energy of a body of mass m moving in the x-y plane [J] (a
    housing here, the sleeve in the model's energy audit)."""
    return 0.5 * m * (vx * vx + vy * vy) + m * g * y


@njit
def spring_energy(k, x, y):
    """Energy of an isotropic linear spring k at deflection (x, y) [J] (the support spring, the
    linear retainer bearing)."""
    return 0.5 * k * (x * x + y * y)


@njit
def spin_energy(J, w):
    """Kinetic energy of a body of spin inertia J at speed w [J] (a sleeve)."""
    return 0.5 * J * w * w


# ------------------------------------------------------------------ the retainer plane's kernel --
@njit_inline
def housing_motion(y, I, k):
    """Housing (outer ring) position and velocity at retainer plane k; zeros when fixed."""
    base = I_PLANES + k * N_PLANE_IDX
    i = I[base + J_HX]
    if i < 0:
        return 0.0, 0.0, 0.0, 0.0
    j = I[base + J_HVX]
    return y[i], y[i + 1], y[j], y[j + 1]


@njit_inline
def housing(y, P, I, U, dy, aux, k, load, rx, ry):
    """Retainer plane k's housing on its support under the force (rx, ry) of what it carries:
    the support dashpot's power into the load, the housing's and the damper's rates."""
    hx, hy, hvx, hvy = housing_motion(y, I, k)
    i_hx = I[I_PLANES + k * N_PLANE_IDX + J_HX]
    p_support = 0.0                          # power of the support dashpot C_s
    if i_hx >= 0:
        cs = U[U_CS1 + k]
        if I[I_CS] >= 0:                     # semi-active damper lags its command (spec §6)
            cs = y[I[I_CS] + k]
        p_support = support_power(hvx, hvy, cs)
        load = add_dissipated(load, p_support)
        if dy is not None:
            if I[I_CS] >= 0:
                dy[I[I_CS] + k] = damper_rate(U[U_CS1 + k], cs, P[P_CS_MIN], P[P_CS_MAX],
                                              P[P_CS_TAU])
            i_hvx = I[I_PLANES + k * N_PLANE_IDX + J_HVX]
            dy[i_hx], dy[i_hx + 1], dy[i_hvx], dy[i_hvx + 1] = housing_rates(
                hx, hy, hvx, hvy, P[P_KS], cs, rx, ry, P[P_MH], P[P_G])
    aux[k * N_AUX_PLANE + A_PSUPPORT] = p_support
    return load


@njit_borrow
def energy(y, P, I, k, E):
    """E plus retainer plane k's housing's kinetic, gravitational and support-spring energy."""
    if I[I_PLANES + k * N_PLANE_IDX + J_HX] >= 0:
        hx, hy, hvx, hvy = housing_motion(y, I, k)
        E += body_energy(P[P_MH], hvx, hvy, P[P_G], hy)
        E += spring_energy(P[P_KS], hx, hy)
    return E
