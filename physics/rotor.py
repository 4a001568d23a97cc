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
    damping c (unbalance at the centre of a symmetric support excites no tilt).
    """
    return m_u_e * Omega ** 2 / complex(k - mass * Omega ** 2, c * Omega)
