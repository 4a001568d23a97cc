"""The ``kinematic`` slip law (``effects.friction = "kinematic"``, the default): the friction
opposes the sliding velocity of the contact points, v = e_t + Ω r − ω_s R, regularised below
the threshold ω_l r, so it only dissipates. Registered in :mod:`physics.laws`."""
from __future__ import annotations

from .._jit import njit_inline

NAME = "kinematic"
DOC = "the friction opposes the contact points' sliding velocity e_t + Omega r - omega_s R"
#: what the metrics say when the contact friction's power comes out negative (None: a defect)
NEGATIVE_POWER = None


@njit_inline
def slip(et, W, ws, P):
    """(the velocity the friction opposes, its regularisation threshold) with a spinning sleeve."""
    return et + W * P[P_RJ] - ws * P[P_RS], P[P_VL]


@njit_inline
def rolling(et, W, P):
    """Massless sleeve: (its rolling speed w*, the velocity the friction's sign follows, the
    threshold)."""
    return (et + W * P[P_RJ]) / P[P_RS], et + W * P[P_RJ], P[P_VL]
