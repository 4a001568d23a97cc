"""The ``paper`` slip law (``effects.friction = "paper"``, eq. 19 as printed): the friction
follows Ω − ω_s, regularised below ω_l; for r != R it can push along the sliding and create
energy (the metrics report the energy created). Registered in :mod:`physics.laws`."""
from __future__ import annotations

from .._jit import njit_inline

NAME = "paper"
DOC = "eq. 19 as printed: the friction follows Omega - omega_s"
#: what the metrics say when the contact friction's power comes out negative
NEGATIVE_POWER = ("effects.friction = 'paper' drives the friction by Omega - omega_s, not by the"
                  " contact's sliding velocity; its heat and energy figures are not physical"
                  " (effects.friction = 'kinematic' dissipates)")


@njit_inline
def slip(et, W, ws, P):
    """(the velocity the friction opposes, its regularisation threshold) with a spinning sleeve."""
    return W - ws, P[P_WL]


@njit_inline
def rolling(et, W, P):
    """Massless sleeve: (its rolling speed w*, the velocity the friction's sign follows, the
    threshold)."""
    return W, W, P[P_WL]
