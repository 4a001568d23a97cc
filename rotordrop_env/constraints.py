"""Episode constraints: the physical events that end an episode (``terminated``), as objects an
environment is given (env kwarg ``constraints``, by name or object; default: all of them).

==================  =============================================================  ==============
constraint          violated in a control step when, at any monitor sample          parameters
==================  =============================================================  ==============
stator_contact      the rotor reaches the AMB stator: radial displacement           ``amb.air_gap``
                    >= ``amb.air_gap`` at an AMB plane
bearing_overload    a rotor-sleeve contact force exceeds the retainer bearing's     ``bearing.static_load_rating``
                    static load rating C_0
contact_validity    a penetration passes its contact law's validity bound           :func:`physics.validity.validity_bound`
                    (rotor-sleeve; rotor-stator with ``effects.stator_contact``)
==================  =============================================================  ==============

Every constraint is monitored in every environment, whether it ends the episode or not: its
``info`` cost (``cost_stator_contact``, ...: 1 in a violating step, Safety-Gymnasium
convention) and its latched KPI (``kpi_stator_contact``, ...) are reported either way, so that
the ``info`` keys are the same for every choice. The checks run in the step kernel, per monitor
sample (:func:`plane_events`) and per step (:func:`step_events`); a constraint object carries its
parameters (written into the kernel configuration ``C``) and its slot ``C[C_ENDS + index]``,
which says whether it ends the episode.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Iterable

from physics.jit import njit
from physics.model import A_DELTA, N_AUX_PLANE, ST_AMB1, axis_motion, stator_motion
from physics.scene import Scene
from physics.validity import validity_bound

from .tasks import CONSTRAINT_NAMES
from .slots import (C_ENDS, C_GAP, C_LOAD_RATING, C_PEN_BOUND, C_STATOR_BOUND, M_BEYOND, M_LEFT_T,
                    M_OVERLOAD, M_STATOR, O_BEYOND, O_OVERLOAD, O_STATOR)


def _stator_parameters(scene: Scene) -> dict[int, float]:
    return {C_GAP: scene.amb.air_gap}


def _overload_parameters(scene: Scene) -> dict[int, float]:
    return {C_LOAD_RATING: scene.bearing.static_load_rating}


def _validity_parameters(scene: Scene) -> dict[int, float]:
    return {C_PEN_BOUND: validity_bound(scene, "retainer").penetration,
            C_STATOR_BOUND: (validity_bound(scene, "stator").penetration
                             if scene.effects.stator_contact else math.inf)}


@dataclass(frozen=True)
class Constraint:
    """One episode constraint: its ``name`` (the env kwarg's shorthand), its slot
    ``C[C_ENDS + index]`` in the kernel configuration, its ``info`` cost and KPI keys, and
    ``parameters(scene)``: its kernel parameters {C slot: value} for the episode's scene."""
    name: str
    index: int
    cost_key: str
    kpi_key: str
    parameters: Callable[[Scene], dict[int, float]]
    doc: str = ""

    def configure(self, C, scene: Scene, ends: bool) -> None:
        """Write its parameters for ``scene`` and whether it ends the episode into ``C``."""
        for slot, value in self.parameters(scene).items():
            C[slot] = value
        C[C_ENDS + self.index] = 1.0 if ends else 0.0


STATOR_CONTACT = Constraint("stator_contact", 0, "cost_stator_contact", "kpi_stator_contact",
                            _stator_parameters, "the rotor reaches the AMB stator")
BEARING_OVERLOAD = Constraint("bearing_overload", 1, "cost_bearing_overload",
                              "kpi_bearing_overload", _overload_parameters,
                              "a contact force exceeds the retainer bearing's static load rating")
CONTACT_VALIDITY = Constraint("contact_validity", 2, "cost_contact_validity",
                              "kpi_beyond_validity", _validity_parameters,
                              "a penetration passes its contact law's validity bound")
#: every constraint, by name, in the order of their kernel slots
CONSTRAINTS = {c.name: c for c in (STATOR_CONTACT, BEARING_OVERLOAD, CONTACT_VALIDITY)}
assert tuple(CONSTRAINTS) == CONSTRAINT_NAMES          # the names a task declaration may use


def resolve_constraints(given: Iterable[str | Constraint] | None, terminate_on_failure: bool,
                        default: tuple[str, ...] = tuple(CONSTRAINTS)) -> tuple[Constraint, ...]:
    """The constraints that end an episode: ``given`` (names or objects; None: ``default``, the
    task's), none with ``terminate_on_failure=False``. ValueError naming the allowed ones for an
    unknown name, a repeated one, or constraints given together with
    ``terminate_on_failure=False`` (one of the two would be silently dropped)."""
    if given is not None and not terminate_on_failure and list(given):
        raise ValueError(f"constraints = {given!r} and terminate_on_failure = False contradict "
                         "each other; give one of them (constraints=() ends no episode)")
    if isinstance(given, (str, Constraint)):
        given = (given,)
    out = []
    for c in (default if given is None else given):
        constraint = CONSTRAINTS.get(c) if isinstance(c, str) else c
        if not isinstance(constraint, Constraint) or CONSTRAINTS.get(constraint.name) != constraint:
            raise ValueError(f"constraints: {c!r} is not an episode constraint; the constraints "
                             f"are {', '.join(repr(n) for n in CONSTRAINTS)}")
        if constraint in out:
            raise ValueError(f"constraints: {constraint.name!r} is given twice")
        out.append(constraint)
    return tuple(out) if terminate_on_failure else ()


def configure(C, scene: Scene, ends: tuple[Constraint, ...]) -> None:
    """Every constraint's parameters for ``scene`` (all are monitored) and which of them end the
    episode (``ends``) into the kernel configuration ``C``."""
    for constraint in CONSTRAINTS.values():
        constraint.configure(C, scene, constraint in ends)


# ------------------------------------------------------------------------ the checks --
@njit
def plane_events(ys, P, I, aux, k, C):
    """(at the stator, past a validity bound) at AMB / retainer plane ``k`` in the state ``ys``
    of one monitor sample (``aux``: its diagnostics). The stator penetration is checked only past
    the gap, relative to the stator (on its mount with ``effects.stator_mount``)."""
    stator = False
    beyond = False
    ax, ay, _, _ = axis_motion(ys, P, I, ST_AMB1 + k)
    a2 = ax * ax + ay * ay
    if a2 >= C[C_GAP] * C[C_GAP]:
        stator = True
        qx, qy, _, _ = stator_motion(ys, I, k)
        if math.hypot(ax - qx, ay - qy) - C[C_GAP] > C[C_STATOR_BOUND]:
            beyond = True
    if aux[k * N_AUX_PLANE + A_DELTA] > C[C_PEN_BOUND]:
        beyond = True
    return stator, beyond


@njit
def latch_validity(beyond, ts, M):
    """The first monitor sample past a validity bound: latched with its time."""
    if beyond and M[M_BEYOND] == 0.0:
        M[M_BEYOND] = 1.0
        M[M_LEFT_T] = ts


@njit
def step_events(f_step, stator, beyond, C, M, out):
    """The control step's constraint events into ``out`` (this step) and ``M`` (latched: it
    happened this episode), from the peak contact force ``f_step`` and the samples' events;
    True when a constraint that ends the episode was violated."""
    overload = f_step > C[C_LOAD_RATING]
    out[O_STATOR] = 1.0 if stator else 0.0
    out[O_OVERLOAD] = 1.0 if overload else 0.0
    out[O_BEYOND] = 1.0 if beyond else 0.0
    M[M_STATOR] = max(M[M_STATOR], out[O_STATOR])
    M[M_OVERLOAD] = max(M[M_OVERLOAD], out[O_OVERLOAD])
    return ((stator and C[C_ENDS] > 0.0) or (overload and C[C_ENDS + 1] > 0.0)
            or (beyond and C[C_ENDS + 2] > 0.0))
