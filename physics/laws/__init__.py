"""The registry of the rotor-sleeve contact laws (``contact.law``) and friction slip laws
(``effects.friction``): each law is one module of this package, registered here once, and
looked up by name (:func:`contact_law`, :func:`slip_law`) or, in the kernels, by its index (the
runtime flags ``flag.law``, ``flag.friction``), never compared by name elsewhere.

A **contact law** module provides ``NAME``, ``DOC``, its kernels ``force(delta, ddelta, P)`` ->
(F_r, elastic part) and ``potential(delta, P)`` (``@njit_inline``, reading its parameters from
``P`` by the layout's constants), its validity bound ``validity_bound(scene)`` -> (penetration,
load, criterion) (:mod:`physics.validity`) and its metrics hook ``tangent_stiffness(scene,
load)`` (:func:`physics.metrics.contact_period`). A **slip law** module provides ``NAME``,
``DOC``, ``slip(et, W, ws, P)`` and ``rolling(et, W, P)`` (the velocity the friction opposes,
with a spinning and a massless sleeve) and ``NEGATIVE_POWER`` (the metrics' note when its
friction creates energy). docs/howto/contact-law.md adds one.
"""
from __future__ import annotations

from .._jit import njit_inline
from . import hertz_line, power_law, slip_kinematic, slip_paper

#: the contact laws, by name; a law's index here is its runtime flag (the registration line)
CONTACT_LAWS = {m.NAME: m for m in (power_law, hertz_line)}
#: the slip laws, by name; index 0 is no friction, a law's index here is its runtime flag
SLIP_LAWS = {"none": None, **{m.NAME: m for m in (slip_paper, slip_kinematic)}}
#: every law module (their kernels read the layout's constants, bound by physics.model)
MODULES = (power_law, hertz_line, slip_paper, slip_kinematic)


def _lookup(table: dict, name: str, what: str):
    if name not in table:
        raise KeyError(f"unknown {what} {name!r}; registered: {', '.join(table)}")
    return table[name]


def contact_law(name: str):
    """The contact law module registered as ``name`` (KeyError naming the registered ones)."""
    return _lookup(CONTACT_LAWS, name, "contact law")


def slip_law(name: str):
    """The slip law module registered as ``name`` (None for ``"none"``)."""
    return _lookup(SLIP_LAWS, name, "slip law")


def contact_law_flag(name: str) -> int:
    """The runtime flag (``flag.law``) of contact law ``name``."""
    contact_law(name)
    return list(CONTACT_LAWS).index(name)


def slip_law_flag(name: str) -> int:
    """The runtime flag (``flag.friction``) of slip law ``name`` (0: no friction)."""
    slip_law(name)
    return list(SLIP_LAWS).index(name)


# the kernels' dispatch on the runtime flags (in registration order)
@njit_inline
def normal_force(law, delta, ddelta, P):
    """(F_r, elastic part) of contact law number ``law`` at penetration delta > 0."""
    if law == 0:
        return power_law.force(delta, ddelta, P)
    return hertz_line.force(delta, ddelta, P)


@njit_inline
def potential(law, delta, P):
    """Elastic energy of contact law number ``law`` at penetration delta."""
    if law == 0:
        return power_law.potential(delta, P)
    return hertz_line.potential(delta, P)


@njit_inline
def has_friction(slip):
    """Slip law number ``slip`` applies a friction force."""
    return slip != 0


@njit_inline
def slip_velocity(slip, et, W, ws, P):
    """(velocity the friction opposes, threshold) of slip law number ``slip`` > 0."""
    if slip == 1:
        return slip_paper.slip(et, W, ws, P)
    return slip_kinematic.slip(et, W, ws, P)


@njit_inline
def rolling(slip, et, W, P):
    """(w*, velocity of the friction's sign, threshold) of slip law number ``slip`` > 0 with a
    massless sleeve."""
    if slip == 1:
        return slip_paper.rolling(et, W, P)
    return slip_kinematic.rolling(et, W, P)
