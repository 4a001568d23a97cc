"""The ``paper`` contact law (``contact.law = "paper"``, paper eq. 14): F_r = K δ^e plus the
STEP-ramped damping C(δ) δ̇, never pulling. Registered in :mod:`physics.laws`.

Validity bound: K lumps the journal-sleeve contact, so its δ is not a steel approach; the bound
is the load at which a steel line contact of the same geometry (``contact.length``,
``rotor.journal_radius``, ``contact.clearance``, E* of the bearing steel) reaches the hertz_line
law's half-width bound (:func:`physics.laws.hertz_line.half_width_load`), converted to δ through
K δ^e. Metrics hook: the tangent stiffness e K (F/K)^((e-1)/e).
"""
from __future__ import annotations

from .._jit import njit, njit_inline
from .hertz_line import HALF_WIDTH_LIMIT, half_width_load, line_stiffness
from .step import step

NAME = "paper"
DOC = "K delta^e with the STEP damping (paper eq. 14)"


@njit
def normal_force(delta, delta_dot, K, e, c_max, d):
    """Radial contact force F_r >= 0 for penetration delta and its rate, eq. 14.

    Returns (F_r, K delta^e): the force and its elastic part (the energy audit needs both).
    """
    if delta <= 0.0:
        return 0.0, 0.0
    elastic = K * delta ** e
    f = elastic + step(delta, 0.0, 0.0, d, c_max) * delta_dot
    return (f if f > 0.0 else 0.0), elastic


@njit
def contact_potential(delta, K, e):
    """Elastic energy K delta^(e+1)/(e+1) stored in the contact (energy audit)."""
    if delta <= 0.0:
        return 0.0
    return K * delta ** (e + 1.0) / (e + 1.0)


def power_law_approach(load: float, K: float, e: float) -> float:
    """delta = (F / K)^(1/e) [m]: the penetration at which the paper's law K delta^e (eq. 14)
    carries ``load``."""
    if load < 0.0 or K <= 0.0 or e <= 0.0:
        raise ValueError(f"load >= 0, K > 0, e > 0 required; got {load!r}, {K!r}, {e!r}")
    return (load / K) ** (1.0 / e)


def validity_bound(scene) -> tuple[float, float, str]:
    """(penetration [m], elastic force there [N], criterion) past which the law leaves its
    assumptions (module docstring)."""
    c = scene.contact
    load = half_width_load(scene.rotor.journal_radius, c.clearance, line_stiffness(scene))
    return (power_law_approach(load, c.stiffness, c.exponent), load,
            f"load at which a steel line contact reaches Hertz half-width b ="
            f" {HALF_WIDTH_LIMIT:g} x rotor.journal_radius, through K delta^e")


def tangent_stiffness(scene, load: float) -> float:
    """dF/dδ [N/m] of K δ^e at ``load``: e K (F/K)^((e-1)/e)."""
    c = scene.contact
    return c.exponent * c.stiffness * (load / c.stiffness) ** ((c.exponent - 1.0) / c.exponent)


@njit_inline
def force(delta, ddelta, P):
    """(F_r, elastic part) at penetration delta > 0 and its rate."""
    return normal_force(delta, ddelta, P[P_KC], P[P_EC], P[P_CMAX], P[P_DC])


@njit_inline
def potential(delta, P):
    """Elastic energy stored at penetration delta."""
    return contact_potential(delta, P[P_KC], P[P_EC])
