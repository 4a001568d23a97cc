"""The regularisations the laws share: the cubic STEP polynomial (paper eq. 18), which ramps the
paper law's damping in, and the regularised sign of a slip (eq. 19), which every friction law
(rotor-sleeve, rotor-stator, the bearing's drag) follows."""
from .._jit import njit


@njit
def step(g, g0, h0, g1, h1):
    """Cubic STEP polynomial, eq. 18: h0 below g0, h1 above g1, C1-smooth in between."""
    if g <= g0:
        return h0
    if g >= g1:
        return h1
    s = (g - g0) / (g1 - g0)
    return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)


@njit
def smooth_sign(slip, threshold):
    """sign(slip) * STEP(|slip|, 0, 0, threshold, 1): the regularised friction direction (eq. 19)."""
    a = step(abs(slip), 0.0, 0.0, threshold, 1.0)
    return a if slip >= 0.0 else -a
