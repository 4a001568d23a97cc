"""A sudden unbalance change: blade or fragment loss (``effects.unbalance_change``, scene group
``unbalance_change``; docs/physics.md "Sudden unbalance change").

At time t_s the rotor's unbalance steps from m_u e at angle β (``unbalance.*``) to m_u' e' at
β' (``unbalance_change.*``), at the same axial station z_u. The rotating unbalance is linear in
its complex amount U = m_u e e^{iβ}, so from t_s on the effect adds the unbalance force of the
difference

    ΔU = m_u' e' e^{iβ'} − m_u e e^{iβ},   F = |ΔU| Ω² (cos(φ + arg ΔU), sin(φ + arg ΔU)),

at z_u (moments z_u F about the centre of mass; on a flexible rotor at the unbalance station,
so its modes see it), through the rotor's own unbalance load (:func:`physics.rotor.unbalance_of`).
Its power F · v is external work, as the rotor's unbalance's is, so the energy audit closes
across the step. The force jumps at t_s: the drivers split the integration there
(:func:`breaks`), so a step boundary meets the jump. Off (the default) the effect adds no state,
no slot the kernel reads and no work.
"""
from __future__ import annotations

import cmath
import math

from ._jit import njit_inline
from .rotor import unbalance_of

#: the scene keys this effect reads
SCENE_KEYS = ("unbalance_change.*", "effects.unbalance_change")


def declare(layout) -> None:
    """The change's time, the difference's amount |ΔU| and phase arg ΔU; the on/off flag."""
    layout.params.add_each("unbalance_change.time", "unbalance_change.me",
                           "unbalance_change.phase", consts=("P_UC_T", "P_UC_ME", "P_UC_PHASE"))
    layout.index.add("flag.unbalance_change", const="F_UCHANGE")


def difference(scene) -> complex:
    """ΔU = m_u' e' e^{iβ'} − m_u e e^{iβ} [kg m]: what the change adds to the unbalance."""
    u, c = scene.unbalance, scene.unbalance_change
    return (cmath.rect(c.mass * c.radius, math.radians(c.angle_deg))
            - cmath.rect(u.mass * u.radius, math.radians(u.angle_deg)))


def pack(scene, P, I, layout) -> None:
    """The change's time and ΔU (only with effects.unbalance_change)."""
    p = layout.params
    on = scene.effects.unbalance_change
    I[layout.index["flag.unbalance_change"]] = on
    if not on:
        return
    d = difference(scene)
    P[p["unbalance_change.time"]] = scene.unbalance_change.time
    P[p["unbalance_change.me"]], P[p["unbalance_change.phase"]] = abs(d), cmath.phase(d)


def breaks(scene) -> tuple[float, ...]:
    """The times the effect's force jumps (the integration is split there)."""
    return (scene.unbalance_change.time,) if scene.effects.unbalance_change else ()


@njit_inline
def force(t, y, P, I, aux, load):
    """From t_s on, the load with the unbalance difference ΔU added."""
    if t < P[P_UC_T]:
        return load
    return unbalance_of(y, P, I, aux, load, P[P_UC_ME], P[P_UC_PHASE])
