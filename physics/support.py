"""Elastic housing: outer ring + housing on linear spring-dampers K_s, C_s to ground (spec §1)."""
from ._jit import njit


@njit
def housing_force(hx, hy, vx, vy, K_s, C_s):
    """Spring-damper force on the housing from the ground."""
    return -K_s * hx - C_s * vx, -K_s * hy - C_s * vy
