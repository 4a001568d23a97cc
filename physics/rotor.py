"""Rigid rotor with small tilts, gyroscopic coupling and unbalance (spec §1)."""
import math

from ._jit import njit


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
