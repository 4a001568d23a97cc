"""Drop KPIs per retainer plane: displacement, contact force, first contact, backward whirl."""
from __future__ import annotations

import math

import numpy as np

from .ball_bearing import max_contact_pressure
from .model import F_RB, PLANES, RB_SM
from .results import Result

WHIRL_MIN_REVOLUTIONS = 3.0     # net backward orbit revolutions that make a backward whirl
WHIRL_RADIUS_FRACTION = 0.5     # only orbit samples beyond this fraction of the clearance count
RPM = 30.0 / math.pi            # rad/s -> rpm
ISO76_C0_PRESSURE = 4.2e9       # Pa: contact pressure at the static load rating C_0 (ball bearings)


def first_contact_time(result: Result) -> float | None:
    """Earliest time either plane's gap closes, interpolated between samples [s]."""
    best = None
    for p in PLANES:
        d = result.penetration(p)
        hit = np.flatnonzero(d > 0.0)
        if hit.size == 0:
            continue
        k = hit[0]
        t = result.t[k]
        if k > 0 and d[k - 1] < 0.0:
            t = result.t[k - 1] + (result.t[k] - result.t[k - 1]) * (-d[k - 1]) / (d[k] - d[k - 1])
        best = t if best is None else min(best, t)
    return best


def whirl(result: Result, plane: str, after: float) -> dict:
    """Backward-whirl detection from the orbit of the rotor relative to its sleeve.

    The orbit angle is accumulated over consecutive samples that both lie beyond half the
    clearance; turning against the spin direction is backward. A backward whirl needs at least
    WHIRL_MIN_REVOLUTIONS net backward revolutions; its frequency is the backward angular rate
    over the samples that counted. Also reports the mean orbit angular momentum sign.
    """
    sel = result.t >= after
    e = (result.orbit(plane) - result.sleeve(plane))[sel]
    t = result.t[sel]
    c = result.model.scene.contact.clearance
    spin = np.sign(result.rotor_speed[sel].mean()) or 1.0
    r = np.hypot(e[:, 0], e[:, 1])
    ang = np.arctan2(e[:, 1], e[:, 0])
    far = r > WHIRL_RADIUS_FRACTION * c
    both = far[1:] & far[:-1]
    dang = (np.diff(ang) + np.pi) % (2 * np.pi) - np.pi
    dang = dang[both]
    backward_rad = -spin * dang.sum()
    revs = backward_rad / (2 * np.pi)
    dt = np.diff(t)[both]
    moving_back = -spin * dang > 0
    t_back = dt[moving_back].sum()
    freq = (-spin * dang[moving_back]).sum() / (2 * np.pi * t_back) if t_back > 0 else None
    aliased = bool(dang.size and np.max(np.abs(dang)) > 0.75 * np.pi)
    is_whirl = bool(revs >= WHIRL_MIN_REVOLUTIONS)
    return dict(backward_whirl=is_whirl, whirl_revolutions=float(revs),
                whirl_frequency_hz=float(freq) if (is_whirl and freq is not None) else None,
                whirl_sampling_aliased=aliased)


def friction_heat(result: Result, plane: str, post: np.ndarray) -> np.ndarray:
    """Cumulative heat [J] generated at the rotor-sleeve contact over the samples ``post``
    (trapezoidal rule on ``Result.friction_power``); its last value is ``friction_heat_J``."""
    p, t = result.friction_power(plane)[post], result.t[post]
    return np.concatenate(([0.0], np.cumsum(0.5 * (p[1:] + p[:-1]) * np.diff(t))))[:len(t)]


def retainer_loading(result: Result, plane: str, post: np.ndarray) -> dict:
    """Retainer-bearing design numbers after the fault: the peak radial bearing load and the
    static safety factor s_0 = C_0 / P_0 (ISO 76, P_0 = the peak radial load; below about 1
    the races deform permanently), the friction heat generated at the rotor-sleeve contact
    (∫ F_mu v_slip dt, trapezoidal rule over the output samples; a net value, which the paper's
    slip law can make negative, see ``Result.friction_power``) and the highest sleeve speed.
    With the Sopanen-Mikkola bearing also the most heavily loaded ball's peak load and its
    largest Hertz contact pressure (either raceway; ISO 76 rates C_0 at ``ISO76_C0_PRESSURE``,
    the pressure that leaves a permanent dent of 1e-4 ball diameters); None for the linear and
    rigid mounts, which have no balls."""
    t = result.t[post]
    load = result.bearing_load(plane)[post]
    peak = float(load.max()) if len(load) else 0.0
    ws = result.sleeve_speed(plane)[post]
    bearing = result.model.scene.bearing
    q = float(result.max_ball_load(plane)[post].max()) if len(t) else 0.0
    balls = result.model.I[F_RB] == RB_SM
    return dict(peak_bearing_load_N=peak,
                static_safety_factor=bearing.static_load_rating / peak if peak > 0.0 else None,
                max_ball_load_N=q if balls else None,
                max_contact_pressure_MPa=float(max_contact_pressure(bearing, q)) * 1e-6 if balls else None,
                friction_heat_J=float(friction_heat(result, plane, post)[-1]) if len(t) else 0.0,
                max_sleeve_speed_rpm=float(np.abs(ws).max() * RPM) if len(ws) else 0.0)


def compute_metrics(result: Result) -> dict:
    """The numbers written to metrics.json (SI, with µm and rpm at the edges)."""
    t_fault = result.t_fault if result.t_fault is not None else result.t[-1]
    post = result.t >= t_fault
    t_fc = first_contact_time(result)
    out = dict(scene=result.model.scene.name, t_end=float(result.t[-1]), t_fault_s=result.t_fault,
               first_contact_time_s=t_fc,
               first_contact_after_fault_s=(t_fc - t_fault) if t_fc is not None else None,
               final_rotor_speed_rpm=float(result.rotor_speed[-1] * RPM),
               wall_time_s=result.stats.wall_time_s, compile_time_s=result.stats.compile_time_s,
               rhs_evaluations=result.stats.rhs_evaluations, steps=result.stats.steps,
               rejected_steps=result.stats.rejected_steps, n_state=result.model.n_state, planes={})
    for p in PLANES:
        o = result.orbit(p)[post]
        f = result.contact_force(p)[post]
        disp = np.hypot(o[:, 0], o[:, 1]) if len(o) else np.zeros(1)
        entry = dict(max_displacement_um=float(disp.max() * 1e6),
                     max_y_displacement_um=float(np.abs(o[:, 1]).max() * 1e6) if len(o) else 0.0,
                     peak_contact_force_N=float(f.max()) if len(f) else 0.0,
                     final_sleeve_speed_rpm=float(result.sleeve_speed(p)[-1] * RPM))
        entry.update(retainer_loading(result, p, post))
        entry.update(whirl(result, p, t_fault))
        out["planes"][p] = entry
    out["backward_whirl"] = any(out["planes"][p]["backward_whirl"] for p in PLANES)
    return out


def worst_plane(metrics: dict, key: str) -> float | None:
    """The larger of the two retainer planes' values of a per-plane metric (``metrics["planes"]``
    of :func:`compute_metrics`, e.g. ``"peak_contact_force_N"``); None where the metric is None
    (e.g. the ball loads of a linear retainer mount)."""
    values = [v[key] for v in metrics["planes"].values()]
    return None if any(v is None for v in values) else max(values)
