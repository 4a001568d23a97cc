"""Rigid rotor with small tilts, gyroscopic coupling and unbalance (spec §1).

An effect of the drop model (docs/architecture.md "Adding an effect"): its scene keys, packed
slots, states and parameter packing are declared here; :mod:`physics.model` composes them.

The rotor also owns the interface every force effect goes through: the **load** (Fx, Fy, Ma,
Mb, T, p_diss, p_ext), a tuple of the forces, moments about the centre of mass and spin torque
on the rotor and the audit's dissipated and external powers, which :func:`physics.model.rhs`
threads through the effects' kernels in a fixed order; :func:`add_station_force` adds a force
at a force station (also to the station forces a flexible rotor's modes are driven by), and
:func:`axis_motion` reads the rotor axis at a station (the rigid body's motion plus the elastic
modes'). The slot constants (``P_M`` ...) are the layout's, bound by :mod:`physics.model`.
"""
import math

from ._jit import njit, njit_borrow, njit_inline
from .flexible.floating import MAX_MODES as FX_ROW          # a station's row of mode shapes
from .flexible_rotor import elastic_energy, elastic_motion, elastic_rates, tilt_coupling

#: the scene keys this effect reads
SCENE_KEYS = ("rotor.mass", "rotor.polar_inertia", "rotor.diametral_inertia",
              "rotor.journal_radius", "rotor.speed_rpm", "world.gravity", "positions.rb1",
              "positions.rb2", "positions.amb1", "positions.amb2", "unbalance.mass",
              "unbalance.radius", "unbalance.angle_deg", "unbalance.z", "effects.gravity",
              "effects.unbalance", "effects.gyroscopic")
#: the rotor's states (positions, then velocities) and their index slots
STATE_NAMES = ("x", "y", "a", "b", "vx", "vy", "va", "vb", "Omega")
#: the force stations, in the order of their axial positions' block in P (ST_*: station index)
STATIONS = ("rb1.z", "rb2.z", "amb1.z", "amb2.z", "unbalance.z")
ST_RB1, ST_AMB1, ST_UB = (STATIONS.index(n) for n in ("rb1.z", "amb1.z", "unbalance.z"))


def declare(layout) -> None:
    """The rotor's slots: mass properties, the axial stations, unbalance; its flags and states."""
    p = layout.params
    p.add_each("rotor.mass", "rotor.polar_inertia", "rotor.diametral_inertia", "world.gravity",
               "rotor.journal_radius", consts=("P_M", "P_IP", "P_ID", "P_G", "P_RJ"))
    # the force stations, one block (physics/flexible/floating.py STATIONS order; ST_*)
    p.block(*STATIONS,
            consts=("P_Z_RB1", "P_Z_RB2", "P_Z_AMB1", "P_Z_AMB2", "P_Z_UB"))
    p.add_each("unbalance.me", "unbalance.phase", consts=("P_MUE", "P_UB_PHASE"))
    i = layout.index
    i.add_each("flag.gravity", "flag.unbalance", "flag.gyroscopic",
               consts=("F_GRAV", "F_UNB", "F_GYRO"))
    i.add_each(*("state." + n for n in STATE_NAMES + ("phi",)),
               consts=("S_X", "S_Y", "S_A", "S_B", "S_VX", "S_VY", "S_VA", "S_VB", "S_W",
                       "S_PHI"))


def pack(scene, P, I, layout) -> None:
    """The rotor's parameters and flags."""
    s, fx, p = scene, scene.effects, layout.params
    i = layout.index
    I[i["flag.gravity"]] = fx.gravity
    I[i["flag.unbalance"]] = fx.unbalance and s.unbalance.mass * s.unbalance.radius > 0.0
    I[i["flag.gyroscopic"]] = fx.gyroscopic
    g = s.world.gravity if fx.gravity else 0.0
    P[p["rotor.mass"]], P[p["rotor.polar_inertia"]] = s.rotor.mass, s.rotor.polar_inertia
    P[p["rotor.diametral_inertia"]], P[p["world.gravity"]] = s.rotor.diametral_inertia, g
    P[p["rotor.journal_radius"]] = s.rotor.journal_radius
    P[p["rb1.z"]], P[p["rb2.z"]] = s.positions.rb1, s.positions.rb2
    P[p["amb1.z"]], P[p["amb2.z"]] = s.positions.amb1, s.positions.amb2
    P[p["unbalance.me"]] = s.unbalance.mass * s.unbalance.radius
    P[p["unbalance.phase"]] = math.radians(s.unbalance.angle_deg)
    P[p["unbalance.z"]] = s.unbalance.z


def states(scene, I, layout, sizes, add) -> None:
    """The rotor's states. Observation sizes are physical: the clearance, VELOCITY, and for tilt
    rates VELOCITY over the lever arm to the farther retainer plane (0.1 m/s / 0.38 m = 0.26
    rad/s). Where a tolerance size is tighter (tilt rates) it is kept as it is: it sets the step
    sizes."""
    c, tilt, spin, v = sizes.clearance, sizes.tilt, sizes.spin, sizes.velocity
    i = layout.index
    for name, size, obs in (("x", c, None), ("y", c, None), ("a", tilt, None), ("b", tilt, None),
                            ("vx", v, None), ("vy", v, None), ("va", 0.1 * tilt, v / sizes.lever),
                            ("vb", 0.1 * tilt, v / sizes.lever), ("Omega", spin, None)):
        I[i["state." + name]] = add(name, size, obs)
    if I[i["flag.unbalance"]]:
        I[i["state.phi"]] = add("phi", math.pi)


@njit
def axis_at(z, x, y, a, b):
    """Rotor axis position at axial station z: (x + z a, y + z b)."""
    return x + z * a, y + z * b


@njit
def tilt_accelerations(Ma, Mb, va, vb, Omega, I_d, I_p, gyroscopic):
    """Tilt accelerations from I_d a'' + I_p Omega b' = Ma and I_d b'' - I_p Omega a' = Mb.

    Ma = sum z Fx, Mb = sum z Fy. A free spinning rotor nutates forward at I_p Omega / I_d.
    """
    if gyroscopic:
        return (Ma - I_p * Omega * vb) / I_d, (Mb + I_p * Omega * va) / I_d
    return Ma / I_d, Mb / I_d


@njit
def unbalance_force(m_e, Omega, angle):
    """Rotating unbalance force m_u e Omega^2 along the unbalance direction (angle = phi + phase)."""
    f = m_e * Omega * Omega
    return f * math.cos(angle), f * math.sin(angle)


@njit
def rotor_energy(m, I_d, I_p, vx, vy, va, vb, Omega):
    """Kinetic energy of the rigid rotor: translation, tilt and spin [J]."""
    return 0.5 * m * (vx * vx + vy * vy) + 0.5 * I_d * (va * va + vb * vb) + 0.5 * I_p * Omega * Omega


@njit
def unbalance_load(m_e, Omega, phi, phase, z, vx, vy, va, vb):
    """The unbalance's force (fx, fy), moments (z fx, z fy) about the centre of mass and power
    at spin angle ``phi`` (station z; the rotor's velocities vx, vy, va, vb): what the drop
    model's right-hand side adds (its spin-angle rate is Omega)."""
    fx, fy = unbalance_force(m_e, Omega, phi + phase)
    return fx, fy, z * fx, z * fy, fx * (vx + z * va) + fy * (vy + z * vb)


def steady_unbalance_orbit(m_u_e: float, Omega: float, mass: float, k: float, c: float) -> complex:
    """Complex amplitude Z of the settled translational orbit x + iy = Z e^{i Omega t}.

    Solves (k - m Omega^2 + i c Omega) Z = m_u e Omega^2 for the total support stiffness k and
    damping c (unbalance at the centre of a symmetric support excites no tilt). Without
    excitation (no spin or no unbalance) the orbit is 0 whatever the support; an undamped
    support exactly at resonance has no settled orbit (ValueError).
    """
    force = m_u_e * Omega ** 2
    if force == 0.0:
        return 0j
    dyn = complex(k - mass * Omega ** 2, c * Omega)
    if dyn == 0.0:
        raise ValueError("the AMB support is undamped and exactly at resonance with the spin "
                         "(amb.stiffness = rotor.mass x Omega^2, amb.damping = 0): no settled "
                         "unbalance orbit; change amb.stiffness, amb.damping or rotor.speed_rpm")
    return force / dyn


# ----------------------------------------------------------------------------- kernels --
@njit_inline
def axis_motion(y, P, I, s):
    """Rotor axis position and velocity (px, py, vx, vy) at force station s (``ST_RB1 + k``,
    ``ST_AMB1 + k``, ``ST_UB``; axial station P[P_Z_RB1 + s]): the rigid body's, plus the elastic
    modes' of a flexible rotor (physics/flexible_rotor.py)."""
    z = P[P_Z_RB1 + s]
    px, py = axis_at(z, y[I[S_X]], y[I[S_Y]], y[I[S_A]], y[I[S_B]])
    vx, vy = axis_at(z, y[I[S_VX]], y[I[S_VY]], y[I[S_VA]], y[I[S_VB]])
    if I[I_FX_N] > 0:
        ex, ey, evx, evy = elastic_motion(y, P, I[I_FX], I[I_FX_N], P_FX_SHAPE + s * FX_ROW)
        return px + ex, py + ey, vx + evx, vy + evy
    return px, py, vx, vy


@njit_inline
def add_force_at(load, z, fx, fy):
    """The load with the force (fx, fy) on the rotor axis at axial position z added (its moments
    z F about the centre of mass)."""
    Fx, Fy, Ma, Mb, T, p_diss, p_ext = load
    return Fx + fx, Fy + fy, Ma + z * fx, Mb + z * fy, T, p_diss, p_ext


@njit_inline
def add_station_force(load, P, I, aux, s, fx, fy):
    """The load with the force (fx, fy) at force station s added; with a flexible rotor also
    collected per station (aux ``rotor.station_force``), which drives its elastic modes."""
    if I[I_FX_N] > 0:
        aux[A_STF + 2 * s] += fx
        aux[A_STF + 2 * s + 1] += fy
    return add_force_at(load, P[P_Z_RB1 + s], fx, fy)


@njit_inline
def add_torque(load, torque):
    """The load with a spin torque added."""
    Fx, Fy, Ma, Mb, T, p_diss, p_ext = load
    return Fx, Fy, Ma, Mb, T + torque, p_diss, p_ext


@njit_inline
def add_dissipated(load, power):
    """The load with the audit's dissipated power increased by ``power`` [W]."""
    Fx, Fy, Ma, Mb, T, p_diss, p_ext = load
    return Fx, Fy, Ma, Mb, T, p_diss + power, p_ext


@njit_inline
def add_external(load, power):
    """The load with the audit's external (and non-potential) power increased by ``power``."""
    Fx, Fy, Ma, Mb, T, p_diss, p_ext = load
    return Fx, Fy, Ma, Mb, T, p_diss, p_ext + power


@njit_inline
def weight(P):
    """The load of gravity alone: (0, -m g, 0, 0, 0, 0, 0)."""
    return 0.0, -P[P_M] * P[P_G], 0.0, 0.0, 0.0, 0.0, 0.0


@njit_inline
def unbalance(y, P, I, dy, aux, load):
    """The unbalance's load (its station's elastic motion included) and the spin angle's rate."""
    dy[I[S_PHI]] = y[I[S_W]]
    return unbalance_of(y, P, I, aux, load, P[P_MUE], P[P_UB_PHASE])


@njit_inline
def unbalance_of(y, P, I, aux, load, m_e, phase):
    """The load with an unbalance m_e [kg m] at ``phase`` [rad] from the spin angle, at the
    unbalance station, added: its force, moments and power (the station's elastic motion
    included); the rotor's own unbalance and a change of it (physics/unbalance_change.py)."""
    W = y[I[S_W]]
    ux, uy, _, _, p = unbalance_load(m_e, W, y[I[S_PHI]], phase, P[P_Z_UB],
                                     y[I[S_VX]], y[I[S_VY]], y[I[S_VA]], y[I[S_VB]])
    load = add_external(add_station_force(load, P, I, aux, ST_UB, ux, uy), p)
    if I[I_FX_N] > 0:                            # the unbalance station's elastic motion
        _, _, evx, evy = elastic_motion(y, P, I[I_FX], I[I_FX_N], P_FX_SHAPE + ST_UB * FX_ROW)
        load = add_external(load, ux * evx + uy * evy)
    return load


@njit_inline
def equations_of_motion(y, P, I, dy, aux, load):
    """The rotor's (and its elastic modes') rates under the load."""
    Fx, Fy, Ma, Mb, T, _, _ = load
    m = P[P_M]
    va, vb, W = y[I[S_VA]], y[I[S_VB]], y[I[S_W]]
    dy[I[S_X]] = y[I[S_VX]]
    dy[I[S_Y]] = y[I[S_VY]]
    dy[I[S_A]] = va
    dy[I[S_B]] = vb
    dy[I[S_VX]] = Fx / m
    dy[I[S_VY]] = Fy / m
    n_fx = I[I_FX_N]
    if n_fx > 0:                                 # elastic modes (physics/flexible_rotor.py)
        spin = W if I[F_GYRO] else 0.0
        if spin != 0.0:
            cx, cy = tilt_coupling(y, P, I[I_FX], n_fx, P_FX_G1)
            Ma -= spin * cy
            Mb += spin * cx
        elastic_rates(y, P, I[I_FX], n_fx, aux, A_STF, P_FX_W2, P_FX_DAMP, P_FX_SHAPE, P_FX_G1,
                      P_FX_G, spin, va, vb, dy)
    aa, ab = tilt_accelerations(Ma, Mb, va, vb, W, P[P_ID], P[P_IP], I[F_GYRO])
    dy[I[S_VA]] = aa
    dy[I[S_VB]] = ab
    dy[I[S_W]] = T / P[P_IP]


@njit_borrow
def energy(y, P, I):
    """The rotor's kinetic energy (its elastic modes' strain and kinetic energy included) plus
    its gravitational energy [J]."""
    m = P[P_M]
    E = rotor_energy(m, P[P_ID], P[P_IP], y[I[S_VX]], y[I[S_VY]], y[I[S_VA]], y[I[S_VB]],
                     y[I[S_W]])
    if I[I_FX_N] > 0:
        E += elastic_energy(y, P, I[I_FX], I[I_FX_N], P_FX_W2)
    return E + m * P[P_G] * y[I[S_Y]]
