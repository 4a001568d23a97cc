"""Rotor-stator contact at the AMB planes (``effects.stator_contact``, docs/physics.md).

Once the rotor axis at an AMB plane reaches the magnetic air gap ``amb.air_gap`` it touches the
stator's laminated pole stack: the same circle-in-circle geometry as the rotor-sleeve contact
(spec §3), with the stator fixed to ground. Normal law: a linear spring-dashpot (Kelvin-Voigt)
whose force never pulls,

    F_n = max(k δ + c δ̇, 0),  δ = |p| − g_0,

k the stack's contact stiffness (``stator.stiffness``), c set by :func:`damping_coefficient` so
that a normal impact of the rotor's mass share at the plane on the immovable stator rebounds with
the restitution coefficient ``stator.restitution``. Dry friction μ_st F_n opposes the slip of the
rotor surface over the stator, v = ė·t + Ω R_a (R_a = ``stator.rotor_radius``), regularised like
the rotor-sleeve friction (eq. 19, threshold ω_l R_a); its torque −R_a F_μ acts on the rotor spin.
"""
from __future__ import annotations

import math

from ._jit import njit, njit_borrow, njit_inline
from .amb import weight_shares
from .rotor import ST_AMB1, add_dissipated, add_station_force, add_torque, axis_motion
from .contact import geometry, half_width_approach, smooth_sign
from .roots import bisect_decreasing

SCENE_KEYS = ("stator.*", "amb.air_gap", "contact.threshold_rpm", "rotor.mass", "positions.amb1",
              "positions.amb2", "effects.stator_contact", "effects.stator_mount")
#: the stator on its mount at each AMB plane (4 states per plane, effects.stator_mount)
MOUNT_STATES = ("x", "y", "vx", "vy")
MOUNT_STRIDE = len(MOUNT_STATES)      # the stator-mount states of one AMB plane


def declare(layout) -> None:
    """The stator contact's and mount's parameters (gap, stiffness, damping, friction, rotor
    radius, threshold speed; mount stiffness, damping, mass per AMB plane), flag, state slot and
    per-AMB-plane diagnostics: the stator's normal force (zero without stator contact), the
    contact's dashpot and friction powers, its mount's dashpot power."""
    layout.params.add_each("stator.gap", "stator.stiffness", consts=("P_ST_GAP", "P_ST_K"))
    layout.params.add("stator.damping", 2, "P_ST_C")         # per AMB plane: its mass share
    layout.params.add_each(
        "stator.friction", "stator.rotor_radius", "stator.threshold_velocity",
        "stator.mount_stiffness", "stator.mount_damping", "stator.mount_mass",
        consts=("P_ST_MU", "P_ST_R", "P_ST_VL", "P_STM_K", "P_STM_C", "P_STM_M"))
    layout.index.add("flag.stator", const="F_STATOR")
    layout.index.add("state.stator_mount", const="I_STM")
    for name, const in (("stator.normal_force", "A_STATOR"), ("stator.damping_power", "A_ST_PDAMP"),
                        ("stator.friction_power", "A_ST_PFRIC"),
                        ("stator.mount_power", "A_ST_PMOUNT")):
        layout.aux.add(name, 2, const)


def pack(scene, P, I, layout) -> None:
    """The stator contact's parameters and flag; the dashpot of each AMB plane for the rotor's
    mass share there (lever rule)."""
    s, p = scene, layout.params
    I[layout.index["flag.stator"]] = s.effects.stator_contact
    st = s.stator
    shares = weight_shares(s.rotor.mass, s.positions.amb1, s.positions.amb2)
    P[p["stator.gap"]], P[p["stator.stiffness"]] = s.amb.air_gap, st.stiffness
    P[p["stator.friction"]], P[p["stator.rotor_radius"]] = st.friction, st.rotor_radius
    for k, share in enumerate(shares):
        P[p["stator.damping"] + k] = damping_coefficient(st.stiffness, max(abs(share), 1e-3),
                                                         st.restitution)
    P[p["stator.threshold_velocity"]] = s.contact.threshold_rpm * math.pi / 30.0 * st.rotor_radius
    P[p["stator.mount_stiffness"]], P[p["stator.mount_mass"]] = st.mount_stiffness, st.mount_mass
    P[p["stator.mount_damping"]] = 2.0 * st.mount_damping_ratio * math.sqrt(st.mount_stiffness
                                                                            * st.mount_mass)


def states(scene, I, layout, sizes, add) -> None:
    """The stators on their mounts: x, y, vx, vy of AMB1's stator, then AMB2's."""
    if not (scene.effects.stator_contact and scene.effects.stator_mount):
        return
    c, v = sizes.clearance, sizes.velocity
    first = -1
    for plane in ("AMB1", "AMB2"):
        for n, sz, obs in (("x", 0.1 * c, c), ("y", 0.1 * c, c), ("vx", 0.01, v),
                           ("vy", 0.01, v)):
            i = add(f"{plane}.stator_{n}", sz, obs)
            first = i if first < 0 else first
    I[layout.index["state.stator_mount"]] = first


def restitution_of_damping(zeta: float) -> float:
    """Restitution e of a point mass hitting a rigid wall through a linear spring-dashpot of
    damping ratio ζ < 1 whose force cannot pull: the mass leaves when k δ + c δ̇ = 0, i.e. at
    ω_d t = π − 2 asin ζ, with e = exp(−ζ (π − 2 asin ζ) / √(1 − ζ²)) (from the free damped
    response x = v_0/ω_d e^(−ζ ω_n t) sin ω_d t; without the no-pull clamp it would be
    exp(−ζ π / √(1 − ζ²)))."""
    if zeta <= 0.0:
        return 1.0
    return math.exp(-zeta * (math.pi - 2.0 * math.asin(zeta)) / math.sqrt(1.0 - zeta * zeta))


def damping_ratio(e: float) -> float:
    """The damping ratio ζ in [0, 1) with :func:`restitution_of_damping` (ζ) = e (bisection; e is
    strictly decreasing in ζ from 1 at ζ = 0 to 0 as ζ → 1)."""
    if e >= 1.0:
        return 0.0
    return bisect_decreasing(restitution_of_damping, e, 0.0, 1.0 - 1e-12)


def damping_coefficient(stiffness: float, mass: float, e: float) -> float:
    """Dashpot c = 2 ζ √(k m) [N s/m] giving restitution ``e`` for ``mass`` on ``stiffness``."""
    return 2.0 * damping_ratio(e) * math.sqrt(stiffness * mass)


def penetration_bound(rotor_radius: float, gap: float) -> float:
    """δ_b [m]: the stator penetration at which the law leaves its assumptions.

    ``stator.stiffness`` is the secant of Johnson's internal line contact of the rotor (radius
    R_a) in the stator bore (radial gap g_0), so the spring's penetration stands for that
    contact's approach; the same half-width criterion as the retainer's hertz_line law, b <= 0.3 R_a
    (:func:`physics.contact.half_width_load`), is reached at the approach
    :func:`physics.contact.half_width_approach` (R_a, g_0), which depends on the geometry only
    (55.9 µm = 0.093 g_0 for R_a = 45 mm, g_0 = 600 µm; the stack's length and modulus are not
    scene parameters, the load bound would need them). A fraction of the air gap would not
    measure the contact's deformation, so it is not used."""
    return half_width_approach(rotor_radius, gap)


@njit
def stator_force(px, py, pvx, pvy, W, gap, k, c, mu, radius, v_l):
    """Contact of the rotor axis at (px, py), moving at (pvx, pvy) and spinning at W, with the
    fixed stator bore of radial gap ``gap`` centred at the origin.

    Returns (fx, fy, torque, f_n, elastic, p_damp, p_fric): the force (fx, fy) and spin torque on
    the rotor, the normal force F_n >= 0, its elastic part k δ and the powers the contact's
    dashpot, (F_n − k δ) δ̇, and friction, F_μ v, take out of the motion (both >= 0). All zero
    while the rotor is inside the gap.
    """
    r, nx, ny = geometry(px, py)
    delta = r - gap
    if delta <= 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    tx, ty = -ny, nx
    ddelta = nx * pvx + ny * pvy
    elastic = k * delta
    f_n = elastic + c * ddelta
    if f_n <= 0.0:
        f_n = 0.0
    slip = tx * pvx + ty * pvy + W * radius     # rotor surface velocity over the stator, along t
    f_mu = mu * f_n * smooth_sign(slip, v_l)
    return (-f_n * nx - f_mu * tx, -f_n * ny - f_mu * ty, -radius * f_mu, f_n, elastic,
            (f_n - elastic) * ddelta, f_mu * slip)


@njit
def mount_rates(sfx, sfy, qx, qy, qvx, qvy, k, c, m):
    """(x', y', vx', vy') of a stator (mass m) on its mount (stiffness k, damping c) at (qx, qy)
    moving at (qvx, qvy), under the reaction of the rotor's contact force (sfx, sfy)."""
    return qvx, qvy, (-sfx - k * qx - c * qvx) / m, (-sfy - k * qy - c * qvy) / m


@njit
def mount_energy(qx, qy, qvx, qvy, k, m):
    """Kinetic energy of a stator (mass m) on its mount plus the mount spring's (stiffness k)."""
    return 0.5 * m * (qvx * qvx + qvy * qvy) + 0.5 * k * (qx * qx + qy * qy)


@njit
def mount_power(qvx, qvy, c):
    """Power [W] the mount's dashpot c dissipates."""
    return c * (qvx * qvx + qvy * qvy)


@njit
def stator_potential(px, py, gap, k):
    """Elastic energy ½ k δ² stored in the stator contact (energy audit)."""
    delta = math.sqrt(px * px + py * py) - gap
    return 0.5 * k * delta * delta if delta > 0.0 else 0.0


# ----------------------------------------------------------------------------- kernels --
@njit_inline
def stator_motion(y, I, k):
    """Stator position and velocity at AMB plane k on its mount; zeros when fixed to ground."""
    i = I[I_STM]
    if i < 0:
        return 0.0, 0.0, 0.0, 0.0
    i += MOUNT_STRIDE * k
    return y[i], y[i + 1], y[i + 2], y[i + 3]


@njit_inline
def contact(y, P, I, dy, aux, load):
    """Rotor-stator contact at both AMB planes: forces and torque into the load, the contact's
    and the mount's dissipated power, the mounts' rates and the stator diagnostics."""
    W = y[I[S_W]]
    for k in range(2):
        px, py, pvx, pvy = axis_motion(y, P, I, ST_AMB1 + k)
        qx, qy, qvx, qvy = stator_motion(y, I, k)
        sfx, sfy, torque, f_n, _, p_sd, p_sf = stator_force(
            px - qx, py - qy, pvx - qvx, pvy - qvy, W, P[P_ST_GAP], P[P_ST_K], P[P_ST_C + k],
            P[P_ST_MU], P[P_ST_R], P[P_ST_VL])
        p_mount = 0.0
        i_q = I[I_STM]
        if i_q >= 0:                         # the stator on its mount takes the reaction
            i_q += MOUNT_STRIDE * k
            p_mount = mount_power(qvx, qvy, P[P_STM_C])
            load = add_dissipated(load, p_mount)
            if dy is not None:
                dy[i_q], dy[i_q + 1], dy[i_q + 2], dy[i_q + 3] = mount_rates(
                    sfx, sfy, qx, qy, qvx, qvy, P[P_STM_K], P[P_STM_C], P[P_STM_M])
        load = add_station_force(load, P, I, aux, ST_AMB1 + k, sfx, sfy)
        load = add_dissipated(add_torque(load, torque), p_sd + p_sf)
        aux[A_STATOR + k] = f_n
        aux[A_ST_PDAMP + k] = p_sd
        aux[A_ST_PFRIC + k] = p_sf
        aux[A_ST_PMOUNT + k] = p_mount
    return load


@njit_inline
def clear(aux):
    """Zero the stator diagnostics (no stator contact)."""
    for j in range(A_STATOR, A_ST_PMOUNT + 2):
        aux[j] = 0.0


@njit_borrow
def energy(y, P, I, k, E):
    """E plus the stator contact's elastic energy at AMB plane k and its mount's energy."""
    ax, ay, _, _ = axis_motion(y, P, I, ST_AMB1 + k)
    qx, qy, qvx, qvy = stator_motion(y, I, k)
    E += stator_potential(ax - qx, ay - qy, P[P_ST_GAP], P[P_ST_K])
    return E + mount_energy(qx, qy, qvx, qvy, P[P_STM_K], P[P_STM_M])
