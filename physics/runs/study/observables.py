"""Numbers of a drop that the paper's statements are about, beyond the standard metrics.

:func:`drop_observables` runs inside the sweep workers (it is the ``evaluate`` hook of
:func:`physics.runs.sweep.run_sweep`), so only these small dicts travel back. All times are measured
from the fault; forces in N, displacements in µm, speeds in rpm.
"""
from __future__ import annotations

import numpy as np

from ...metrics import RPM, after, first_contact_time, per_plane
from ...model import PLANES
from ...results import Result

WINDOW_S = 0.01            # window of the contact-force fluctuation used for settling
SETTLE_FRACTION = 0.25     # settled: window mean and std within this fraction of the late mean
BOUNCE_WINDOW_S = 0.05     # "just after the drop": separations counted in this window


def drop_observables(result: Result) -> dict:
    """Per-plane and worst-plane observables of one drop (see module docstring)."""
    t = result.t
    t_f = result.t_fault if result.t_fault is not None else 0.0
    post = after(result, t_f)               # the samples t >= t_f, a suffix (as slices)
    t_fc = first_contact_time(result)
    late = after(result, t_f + 0.5 * (t[-1] - t_f))
    t_post = t[post]

    def plane(p: str) -> dict:
        o = result.orbit_after(p, t_f)
        r = result.radius_after(p, t_f)
        f = result.contact_force(p)
        v = (np.gradient(result.radius_after(p, t_f, relative=True), t_post) if t_post.size > 2
             else np.zeros(1))
        ws = result.sleeve_speed(p)
        spun = post.start + np.flatnonzero(ws[post] >= 0.5 * result.rotor_speed[post])
        late_force = float(f[late].mean())
        return dict(
            max_x_um=float(np.abs(o[:, 0]).max() * 1e6) if r.size else 0.0,
            t_max_response_s=float(t_post[np.argmax(r)] - t_f) if r.size else None,
            mean_late_force_N=late_force,
            force_settling_s=_settling(t, f, t_f, late_force),
            separations=_separations(f[post]),
            bounces_after_drop=(_separations(f[(t >= t_fc) & (t <= t_fc + BOUNCE_WINDOW_S)])
                                if t_fc is not None else 0),
            radial_speed_rms_mm_s=float(np.sqrt(np.mean(v[t_post >= t_f + 0.1] ** 2)) * 1e3)
            if v.size > 1 else 0.0,
            sleeve_spin_up_s=float(t[spun[0]] - t_f) if spun.size else None,
            sleeve_speed_at_0p1s_rpm=float(np.interp(t_f + 0.1, t, ws) * RPM),
        )
    out: dict = {"planes": per_plane(result, plane)}
    pl = out["planes"]
    out["t_max_response_s"] = max((pl[p]["t_max_response_s"] for p in PLANES),
                                  key=lambda x: -1 if x is None else x)
    out["max_x_um"] = max(pl[p]["max_x_um"] for p in PLANES)
    out["mean_late_force_N"] = max(pl[p]["mean_late_force_N"] for p in PLANES)
    out["force_settling_s"] = max(pl[p]["force_settling_s"] for p in PLANES)
    out["separations"] = max(pl[p]["separations"] for p in PLANES)
    out["radial_speed_rms_mm_s"] = max(pl[p]["radial_speed_rms_mm_s"] for p in PLANES)
    spin = [pl[p]["sleeve_spin_up_s"] for p in PLANES if pl[p]["sleeve_spin_up_s"] is not None]
    out["sleeve_spin_up_s"] = min(spin) if spin else None
    return out


def _separations(f: np.ndarray) -> int:
    """Contact losses: samples where the force drops from positive to zero."""
    on = f > 0.0
    return int(np.count_nonzero(on[:-1] & ~on[1:]))


def _settling(t: np.ndarray, f: np.ndarray, t_f: float, level: float) -> float:
    """Time after the fault after which the contact force stays settled: in every WINDOW_S
    window its mean is within SETTLE_FRACTION of the late mean and its standard deviation below
    SETTLE_FRACTION of it (1 N at least). A force that keeps growing never settles."""
    dt = t[1] - t[0]
    n = max(2, int(round(WINDOW_S / dt)))
    sel = np.flatnonzero(t >= t_f)
    m = sel.size // n
    if m == 0:
        return 0.0
    w = f[sel[: m * n]].reshape(m, n)
    band = SETTLE_FRACTION * max(level, 1.0)
    loud = np.flatnonzero((w.std(axis=1) > band) | (np.abs(w.mean(axis=1) - level) > band))
    return float((loud[-1] + 1) * n * dt) if loud.size else 0.0
