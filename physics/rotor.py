"""Rigid rotor with small tilts, gyroscopic coupling and unbalance (spec §1).

An effect of the drop model (docs/architecture.md "Adding an effect"): its scene keys, packed
slots, states and parameter packing are declared here; :mod:`physics.model` composes them.
"""
import math

from ._jit import njit

#: the scene keys this effect reads
SCENE_KEYS = ("rotor.mass", "rotor.polar_inertia", "rotor.diametral_inertia",
              "rotor.journal_radius", "rotor.speed_rpm", "world.gravity", "positions.rb1",
              "positions.rb2", "positions.amb1", "positions.amb2", "unbalance.mass",
              "unbalance.radius", "unbalance.angle_deg", "unbalance.z", "effects.gravity",
              "effects.unbalance", "effects.gyroscopic")
#: the rotor's states (positions, then velocities) and their index slots
STATE_NAMES = ("x", "y", "a", "b", "vx", "vy", "va", "vb", "Omega")


def declare(layout) -> None:
    """The rotor's slots: mass properties, the axial stations, unbalance; its flags and states."""
    p = layout.params
    for name in ("rotor.mass", "rotor.polar_inertia", "rotor.diametral_inertia", "world.gravity",
                 "rotor.journal_radius"):
        p.add(name)
    # the force stations, one block (physics/flexible/floating.py STATIONS order)
    p.block("rb1.z", "rb2.z", "amb1.z", "amb2.z", "unbalance.z")
    for name in ("unbalance.me", "unbalance.phase"):
        p.add(name)
    i = layout.index
    for name in ("gravity", "unbalance", "gyroscopic"):
        i.add("flag." + name)
    for name in STATE_NAMES + ("phi",):
        i.add("state." + name)


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
