"""Active magnetic bearings (spec §5). Level 'linear': F = -k_amb x - c_amb x' + weight share.

The actuator level (differential electromagnets, current limit, PID) is added with the
re-levitation environment; the kernel dispatches on the scene's AMB level flag.
"""
from ._jit import njit


@njit
def linear_force(d, v, k_amb, c_amb, bias):
    """Force of one AMB axis for displacement d and velocity v at its plane, plus a bias force."""
    return -k_amb * d - c_amb * v + bias


def weight_shares(weight: float, z1: float, z2: float) -> tuple[float, float]:
    """Static weight carried by supports at z1 and z2 (centre of mass at z = 0), lever rule."""
    return weight * z2 / (z2 - z1), -weight * z1 / (z2 - z1)
