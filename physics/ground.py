"""Base excitation: the ground under the housings and the AMB stators moves
(``effects.base_excitation``, scene group ``ground``; docs/physics.md "Base excitation").

The ground, and with it everything fixed to it (the housings' supports, the AMB stators and
their sensors, a stator's mount), moves with a prescribed acceleration a_g(t) in the x-y plane:
half-sine pulses (shock tests: peak A, duration T, direction angle θ from +x, start t_0)

    a_g(t) = A sin(π (t − t_0) / T) (cos θ, sin θ),   t_0 <= t <= t_0 + T,

and/or a tabulated record (t_i, a_x,i, a_y,i), linear between its samples and zero outside.

**Formulation: the ground's frame.** Every body's coordinates are measured from the moving
ground, so every spring, dashpot, contact, AMB and sensor law keeps its form (they depend on
relative positions and velocities only, and the AMB sensors sit on the stators, which move with
the ground: they measure the rotor relative to their stator as they should). The frame is
accelerated, not rotating, so the only change to the equations of motion is the d'Alembert
force −m a_g(t) on each mass m, applied at its centre of mass: on the rotor (no moment about its
centre of mass), on each sleeve and each housing with their states, and on each stator on its
mount. A flexible rotor's elastic modes feel nothing: they are mass-orthogonal to the rigid
translations (physics/flexible/floating.py), so a uniform acceleration field has no modal
participation. Gravity stays what it was (it is a uniform field too; a_g adds to it).

The energy audit stays in the ground's frame: the mechanical energy is the relative one, and
the power of the d'Alembert forces, −a_g · Σ m v, is booked as external work (``p_ext``), so
the audit still closes. Off (the default) the effect adds no state, no slot the kernel reads
and no work.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ._jit import njit_inline
from .rotor import add_external, add_force_at
from .stator import MOUNT_STRIDE

#: the scene keys this effect reads
SCENE_KEYS = ("ground.*", "effects.base_excitation")
#: the most samples a tabulated record may have (packed into P)
MAX_RECORD = 1024
#: a tabulated record's acceleration bound [m/s^2] (1000 g)
MAX_ACCELERATION = 1000.0 * 9.80665


def declare(layout) -> None:
    """The pulse's (x, y) peak, duration and start; the record's sample count and samples
    (times, then a_x, then a_y; MAX_RECORD each); the on/off flag."""
    p = layout.params
    p.add_each("ground.pulse_x", "ground.pulse_y", "ground.pulse_duration", "ground.pulse_start",
               consts=("P_GR_AX", "P_GR_AY", "P_GR_T", "P_GR_T0"))
    p.add("ground.record", 3 * MAX_RECORD, "P_GR_REC")
    layout.index.add("flag.base_excitation", const="F_GROUND")
    layout.index.add("ground.record_points", const="I_GR_N")


def pack(scene, P, I, layout) -> None:
    """The pulse's components and the record (only with effects.base_excitation)."""
    g, p, i = scene.ground, layout.params, layout.index
    on = scene.effects.base_excitation
    I[i["flag.base_excitation"]] = on
    I[i["ground.record_points"]] = 0
    if not on:
        return
    peak = pulse_peak(g)
    angle = math.radians(g.pulse_angle_deg)
    P[p["ground.pulse_x"]], P[p["ground.pulse_y"]] = peak * math.cos(angle), peak * math.sin(angle)
    P[p["ground.pulse_duration"]], P[p["ground.pulse_start"]] = g.pulse_duration, g.pulse_start
    if g.record:
        t, ax, ay = load_record(g.record)
        n, first = len(t), p["ground.record"]
        P[first:first + n] = t
        P[first + MAX_RECORD:first + MAX_RECORD + n] = ax
        P[first + 2 * MAX_RECORD:first + 2 * MAX_RECORD + n] = ay
        I[i["ground.record_points"]] = n


def pulse_peak(ground) -> float:
    """The pulse's peak [m/s^2]: ``ground.pulse_peak``, or ``ground.pulse_peak_g`` standard
    gravities (the scene allows one of them)."""
    return ground.pulse_peak if ground.pulse_peak > 0.0 else ground.pulse_peak_g * 9.80665


def load_record(path: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A tabulated record: a CSV (comma or whitespace separated, ``#`` comments) of times [s] and
    a_x, a_y [m/s^2], one sample per row, times strictly increasing, at most MAX_RECORD rows.
    A ValueError names what is wrong."""
    file = Path(path).expanduser()
    if not file.is_file():
        raise ValueError(f"ground.record = {path!r}: no such file (a CSV of t, a_x, a_y rows)")
    text = file.read_text().replace(",", " ")
    try:
        data = np.loadtxt(text.splitlines(), ndmin=2)
    except ValueError as exc:
        raise ValueError(f"ground.record = {path!r}: not a table of numbers ({exc})") from None
    if data.shape[1] != 3 or not 2 <= data.shape[0] <= MAX_RECORD:
        raise ValueError(f"ground.record = {path!r}: needs 3 columns (t [s], a_x, a_y [m/s^2]) and"
                         f" 2 to {MAX_RECORD} rows; got {data.shape[0]} x {data.shape[1]}")
    t, ax, ay = data.T
    if not np.all(np.isfinite(data)):
        raise ValueError(f"ground.record = {path!r}: every value must be finite")
    if np.any(np.diff(t) <= 0.0) or t[0] < 0.0:
        raise ValueError(f"ground.record = {path!r}: the times must be >= 0 and strictly increasing")
    if np.max(np.abs(data[:, 1:])) > MAX_ACCELERATION:
        raise ValueError(f"ground.record = {path!r}: accelerations must lie in"
                         f" [-{MAX_ACCELERATION:g}, {MAX_ACCELERATION:g}] m/s^2")
    return t, ax, ay


@njit_inline
def acceleration(t, P, I):
    """a_g(t) = (a_x, a_y) [m/s^2]: the half-sine pulse plus the record's linear interpolation."""
    ax = ay = 0.0
    s = t - P[P_GR_T0]
    if 0.0 <= s <= P[P_GR_T] and (P[P_GR_AX] != 0.0 or P[P_GR_AY] != 0.0):
        f = math.sin(math.pi * s / P[P_GR_T])
        ax, ay = P[P_GR_AX] * f, P[P_GR_AY] * f
    n = I[I_GR_N]
    if n > 0 and P[P_GR_REC] <= t <= P[P_GR_REC + n - 1]:
        lo, hi = 0, n - 1                        # bisection: P[lo] <= t <= P[hi]
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if P[P_GR_REC + mid] <= t:
                lo = mid
            else:
                hi = mid
        t0, t1 = P[P_GR_REC + lo], P[P_GR_REC + hi]
        w = (t - t0) / (t1 - t0)
        ix, iy = P_GR_REC + MAX_RECORD, P_GR_REC + 2 * MAX_RECORD
        ax += (1.0 - w) * P[ix + lo] + w * P[ix + hi]
        ay += (1.0 - w) * P[iy + lo] + w * P[iy + hi]
    return ax, ay


@njit_inline
def _body(y, dy, i_vx, m, ax, ay):
    """−a_g on the acceleration of the body whose velocity states are y[i_vx], y[i_vx + 1]; the
    d'Alembert force's power −m a_g · v."""
    dy[i_vx] -= ax
    dy[i_vx + 1] -= ay
    return -m * (ax * y[i_vx] + ay * y[i_vx + 1])


@njit_inline
def inertial_forces(t, y, P, I, dy, load):
    """The d'Alembert forces −m a_g(t) of the ground's frame: on the rotor into the load, on the
    sleeves, housings and mounted stators into their rates (written before), and their power as
    external work."""
    ax, ay = acceleration(t, P, I)
    if ax == 0.0 and ay == 0.0:
        return load
    m = P[P_M]
    load = add_force_at(load, 0.0, -m * ax, -m * ay)
    p = -m * (ax * y[I[S_VX]] + ay * y[I[S_VY]])
    for k in range(2):
        base = I_PLANES + k * N_PLANE_IDX
        if I[base + J_SVX] >= 0:
            p += _body(y, dy, I[base + J_SVX], P[P_MS], ax, ay)
        if I[base + J_HVX] >= 0:
            p += _body(y, dy, I[base + J_HVX], P[P_MH], ax, ay)
        if I[I_STM] >= 0:
            p += _body(y, dy, I[I_STM] + MOUNT_STRIDE * k + 2, P[P_STM_M], ax, ay)
    return add_external(load, p)
