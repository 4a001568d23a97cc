"""A transient external load on the rotor: a process load, possibly beyond the AMBs' force
capacity (``effects.external_load``, scene group ``external_load``; docs/physics.md "Transient
external load").

A force of peak F in the direction θ (from +x towards +y) acts on the rotor axis at the axial
position z_F from the start t_0 for a duration T, with the time profile f(s), s = t − t_0:

    F(t) = F f(t − t_0) (cos θ, sin θ),
    half_sine:  f(s) = sin(π s / T)                         (0 <= s <= T; impulse 2 F T / π),
    step:       f(s) = min(1, s / τ, (T − s) / τ)           (0 <= s <= T; ramps τ, impulse F (T − τ)),

and f = 0 outside. It is an applied force on the rotor: moments z_F F about the centre of mass;
on a flexible rotor it acts at the unbalance station (its modes see it; the scene requires
z_F = unbalance.z there). Its power F · v(z_F) is external work, so the energy audit closes.
The profile's corners (t_0, t_0 + τ, t_0 + T − τ, t_0 + T) are where the integration is split
(:func:`breaks`). Off (the default) the effect adds no state, no slot the kernel reads and no
work.
"""
from __future__ import annotations

import math

from ._jit import njit_inline
from .rotor import ST_UB, add_external, add_force_at, add_station_force, axis_at, axis_motion

#: the scene keys this effect reads
SCENE_KEYS = ("external_load.*", "effects.external_load")


def declare(layout) -> None:
    """The force's (x, y) peak, axial position, start, duration and ramp; the profile and the
    on/off flag."""
    layout.params.add_each("external_load.fx", "external_load.fy", "external_load.z",
                           "external_load.start", "external_load.duration", "external_load.ramp",
                           consts=("P_XL_FX", "P_XL_FY", "P_XL_Z", "P_XL_T0", "P_XL_T",
                                   "P_XL_RAMP"))
    layout.index.add("flag.external_load", const="F_XLOAD")
    layout.index.add("external_load.step", const="I_XL_STEP")


def pack(scene, P, I, layout) -> None:
    """The load's components and timing (only with effects.external_load)."""
    e, p, i = scene.external_load, layout.params, layout.index
    on = scene.effects.external_load
    I[i["flag.external_load"]] = on
    I[i["external_load.step"]] = e.profile == "step"
    if not on:
        return
    angle = math.radians(e.angle_deg)
    P[p["external_load.fx"]] = e.peak * math.cos(angle)
    P[p["external_load.fy"]] = e.peak * math.sin(angle)
    P[p["external_load.z"]], P[p["external_load.start"]] = e.z, e.start
    P[p["external_load.duration"]] = e.duration
    P[p["external_load.ramp"]] = e.ramp if e.profile == "step" else 0.0


def impulse(scene) -> float:
    """The load's impulse magnitude ∫|F| dt [N s]: 2 F T / π (half-sine), F (T − τ) (step)."""
    e = scene.external_load
    if e.profile == "half_sine":
        return 2.0 * e.peak * e.duration / math.pi
    return e.peak * (e.duration - e.ramp)


def breaks(scene) -> tuple[float, ...]:
    """The profile's corners, where the integration is split."""
    if not scene.effects.external_load:
        return ()
    e = scene.external_load
    t = {e.start, e.start + e.duration}
    if e.profile == "step" and e.ramp > 0.0:
        t |= {e.start + e.ramp, e.start + e.duration - e.ramp}
    return tuple(sorted(t))


@njit_inline
def profile(t, P, I):
    """f(t − t_0) in [0, 1]: the half-sine or the ramped step, zero outside [t_0, t_0 + T]."""
    s, T = t - P[P_XL_T0], P[P_XL_T]
    if s < 0.0 or s > T:
        return 0.0
    if not I[I_XL_STEP]:
        return math.sin(math.pi * s / T)
    r = P[P_XL_RAMP]
    if r > 0.0:
        return min(1.0, s / r, (T - s) / r)
    return 1.0


@njit_inline
def force(t, y, P, I, aux, load):
    """The load with the external force (at z_F; on a flexible rotor at the unbalance station)
    and its power added."""
    f = profile(t, P, I)
    if f == 0.0:
        return load
    fx, fy = P[P_XL_FX] * f, P[P_XL_FY] * f
    if I[I_FX_N] > 0:
        _, _, vx, vy = axis_motion(y, P, I, ST_UB)
        load = add_station_force(load, P, I, aux, ST_UB, fx, fy)
    else:
        vx, vy = axis_at(P[P_XL_Z], y[I[S_VX]], y[I[S_VY]], y[I[S_VA]], y[I[S_VB]])
        load = add_force_at(load, P[P_XL_Z], fx, fy)
    return add_external(load, fx * vx + fy * vy)
