"""Flexible rotor: elastic modes on top of the rigid rotor's motion (``rotor.model = "flexible"``).

An effect of the drop model (docs/architecture.md "Adding an effect"). The rotor's x, y, a, b
stay the rigid-body coordinates about the centre of mass (physics/rotor.py); the effect adds
``n`` elastic modal coordinates per bending plane (eta_x, eta_y and their rates: 4 n states),
which displace the axis at each force station s by ``S[s, :] . eta`` (the floating-frame model
of physics/flexible/floating.py, equations there). Gravity does no work on them; the spin
couples them gyroscopically to each other and to the rigid tilts; a modal damping ratio
dissipates ``2 zeta omega eta'^2``; their strain energy ``omega^2 eta^2 / 2`` and kinetic energy
``eta'^2 / 2`` join the energy audit. Off (rigid, the default) it adds no state and no work.

The station forces the right-hand side collects (retainer contact, AMB, stator, unbalance) are
kept in the diagnostics slot ``rotor.station_force`` (x, y per station, stations in
:data:`physics.flexible.floating.STATIONS` order) and projected on the modes here.
"""
from __future__ import annotations

import numpy as np

from ._jit import njit_borrow, njit_inline
from .flexible.floating import MAX_MODES, STATIONS

#: the scene keys this effect reads
SCENE_KEYS = ("rotor.model", "flexible.shaft", "flexible.modulus_scale", "flexible.mode_cutoff_hz",
              "flexible.static_modes", "flexible.damping_ratio", "flexible.element_length")
N_STATIONS = len(STATIONS)


def declare(layout) -> None:
    """The modal frequencies, damping, station shapes and gyroscopic couplings; the mode count
    (0: rigid) and first elastic state; the station forces and the damping power."""
    p = layout.params
    p.add("flex.omega2", MAX_MODES, "P_FX_W2")
    p.add("flex.damping", MAX_MODES, "P_FX_DAMP")
    p.add("flex.shape", N_STATIONS * MAX_MODES, "P_FX_SHAPE")
    p.add("flex.gyro_rigid", MAX_MODES, "P_FX_G1")
    p.add("flex.gyro", MAX_MODES * MAX_MODES, "P_FX_G")
    layout.index.add("flex.modes", const="I_FX_N")
    layout.index.add("state.elastic", const="I_FX")
    layout.aux.add("rotor.station_force", 2 * N_STATIONS, "A_STF")
    layout.aux.add("rotor.damping_power", const="A_FX_PDAMP")


def pack(scene, P, I, layout) -> None:
    """The reduced model's frequencies, damping, station shapes and gyroscopic couplings (the
    rigid rotor's mass properties stay physics/rotor.py's: the scene checks that they are the
    shaft's, physics/scene.py)."""
    I[layout.index["flex.modes"]] = 0
    if scene.rotor.model != "flexible":
        return
    from .flexible.shafts import drop_rotor
    fm = drop_rotor(scene)
    n, p = fm.n_modes, layout.params
    I[layout.index["flex.modes"]] = n
    P[p["flex.omega2"]:p["flex.omega2"] + n] = fm.omega ** 2
    P[p["flex.damping"]:p["flex.damping"] + n] = 2.0 * scene.flexible.damping_ratio * fm.omega
    for s in range(N_STATIONS):
        P[p["flex.shape"] + s * MAX_MODES:p["flex.shape"] + s * MAX_MODES + n] = fm.shape[s]
    P[p["flex.gyro_rigid"]:p["flex.gyro_rigid"] + n] = fm.g
    for j in range(n):
        P[p["flex.gyro"] + j * MAX_MODES:p["flex.gyro"] + j * MAX_MODES + n] = fm.G[j]


def states(scene, I, layout, sizes, add) -> None:
    """eta_x1 ... eta_xn, eta_y1 ..., then their rates. Sizes: the modal amplitude that moves a
    station by one clearance, and by VELOCITY."""
    n = int(I[layout.index["flex.modes"]])
    if n == 0:
        return
    from .flexible.shafts import drop_rotor
    reach = np.abs(drop_rotor(scene).shape).max(axis=0)
    reach = np.where(reach > 0.0, reach, 1.0)
    first = -1
    for rate, size in (("", sizes.clearance), ("d", sizes.velocity)):
        for plane in "xy":
            for j in range(n):
                i = add(f"{rate}eta_{plane}{j + 1}", size / reach[j])
                first = i if first < 0 else first
    I[layout.index["state.elastic"]] = first


@njit_borrow
def elastic_motion(y, P, i0, n, row):
    """Elastic displacement and velocity (dx, dy, dvx, dvy) of the axis at the station whose
    mode shapes start at P[row] (the modal states start at y[i0])."""
    dx = dy = dvx = dvy = 0.0
    for j in range(n):
        s = P[row + j]
        dx += s * y[i0 + j]
        dy += s * y[i0 + n + j]
        dvx += s * y[i0 + 2 * n + j]
        dvy += s * y[i0 + 3 * n + j]
    return dx, dy, dvx, dvy


@njit_borrow
def damping_power(y, P, i0, n, damp):
    """Power the modal damping takes out: sum 2 zeta omega (eta_x'^2 + eta_y'^2) [W]."""
    p = 0.0
    for j in range(n):
        vx, vy = y[i0 + 2 * n + j], y[i0 + 3 * n + j]
        p += P[damp + j] * (vx * vx + vy * vy)
    return p


@njit_borrow
def tilt_coupling(y, P, i0, n, g1):
    """g . eta_x' and g . eta_y': the elastic rates' gyroscopic share in the tilt equations."""
    cx = cy = 0.0
    for j in range(n):
        cx += P[g1 + j] * y[i0 + 2 * n + j]
        cy += P[g1 + j] * y[i0 + 3 * n + j]
    return cx, cy


@njit_borrow
def elastic_rates(y, P, i0, n, aux, a_force, w2, damp, shape, g1, gyro, Omega, va, vb, dy):
    """d/dt of the modal states (module docstring of physics/flexible/floating.py); the station
    forces are aux[a_force + 2 s], aux[a_force + 2 s + 1]; Omega = 0 switches the gyroscopic
    terms off."""
    for j in range(n):
        qx = qy = 0.0
        for s in range(N_STATIONS):
            sh = P[shape + s * MAX_MODES + j]
            qx += sh * aux[a_force + 2 * s]
            qy += sh * aux[a_force + 2 * s + 1]
        ex, ey = y[i0 + j], y[i0 + n + j]
        vx, vy = y[i0 + 2 * n + j], y[i0 + 3 * n + j]
        ax = qx - P[w2 + j] * ex - P[damp + j] * vx
        ay = qy - P[w2 + j] * ey - P[damp + j] * vy
        if Omega != 0.0:
            gx = P[g1 + j] * vb
            gy = P[g1 + j] * va
            for k in range(n):
                gjk = P[gyro + j * MAX_MODES + k]
                gx += gjk * y[i0 + 3 * n + k]
                gy += gjk * y[i0 + 2 * n + k]
            ax -= Omega * gx
            ay += Omega * gy
        dy[i0 + j] = vx
        dy[i0 + n + j] = vy
        dy[i0 + 2 * n + j] = ax
        dy[i0 + 3 * n + j] = ay


@njit_borrow
def elastic_energy(y, P, i0, n, w2):
    """Strain + kinetic energy of the elastic modes: sum (omega^2 eta^2 + eta'^2) / 2 [J]."""
    e = 0.0
    for j in range(n):
        ex, ey = y[i0 + j], y[i0 + n + j]
        vx, vy = y[i0 + 2 * n + j], y[i0 + 3 * n + j]
        e += 0.5 * (P[w2 + j] * (ex * ex + ey * ey) + vx * vx + vy * vy)
    return e


def strain_energy(model, y: np.ndarray) -> np.ndarray | float:
    """Strain energy of the elastic modes [J] in state ``y`` (or per row of a state array);
    0 for a rigid rotor."""
    n = model.elastic_modes
    y = np.asarray(y)
    if n == 0:
        return 0.0 if y.ndim == 1 else np.zeros(len(y))
    i0 = model.state_index("eta_x1")
    w2 = model.P[model.param_index("flex.omega2"):][:n]
    eta = y[..., i0:i0 + 2 * n]
    return 0.5 * np.sum(np.concatenate([w2, w2]) * eta * eta, axis=-1)


@njit_inline
def clear_station_forces(aux):
    """Zero the station forces and the damping power before the effects add theirs."""
    for j in range(A_STF, A_FX_PDAMP + 1):
        aux[j] = 0.0


@njit_inline
def modal_damping(y, P, I, aux):
    """The modal damping's power [W] (also into aux ``rotor.damping_power``)."""
    p = damping_power(y, P, I[I_FX], I[I_FX_N], P_FX_DAMP)
    aux[A_FX_PDAMP] = p
    return p
