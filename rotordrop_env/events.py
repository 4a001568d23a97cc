"""The event of an episode with the AMBs on (the ``Recover`` task): one external event per
episode, drawn from stated ranges with the environment's ``np_random`` and written as the scene
keys of the physics effect that simulates it (docs/physics.md):

=============  ==========================================  ====================================
kind           effect (scene keys)                          drawn
=============  ==========================================  ====================================
``shock``      base excitation: a half-sine base            peak [g], duration [s], direction
               acceleration of the housings and AMB          [deg] (physics/ground.py)
               stators (``ground.pulse_*``)
``unbalance``  a sudden unbalance change (blade or          the new unbalance m_u' e' [kg m] and
               fragment loss, ``unbalance_change.*``)        its angle [deg]
               (physics/unbalance_change.py)
``load``       a transient half-sine external force on the  peak [N], duration [s], direction
               rotor at its centre of mass                  [deg] (physics/external_load.py)
               (``external_load.*``)
=============  ==========================================  ====================================

The kind is drawn uniformly among ``kinds``; the event starts ``delay`` after the episode start,
rounded up to the control-step grid (a jump of the unbalance then meets a step boundary). None
of these effects adds a state, so every kind runs in one state layout. :class:`EventRanges` is
the env kwarg ``events`` (a dict of the fields to change), checked: a ValueError names the
field and its allowed range.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, fields, replace
from typing import Any, Mapping

#: the event kinds, in their draw order
EVENT_KINDS = ("shock", "unbalance", "load")
#: each range field's allowed interval and unit
LIMITS: dict[str, tuple[float, float, str]] = {
    "delay": (0.0, 1.0, "s"),
    "shock_peak_g": (0.1, 1000.0, "g"),
    "shock_duration": (1e-4, 0.1, "s"),
    "shock_angle_deg": (-360.0, 360.0, "deg"),
    "unbalance_me": (0.0, 0.1, "kg m"),
    "unbalance_angle_deg": (-360.0, 360.0, "deg"),
    "load_peak": (1.0, 1e6, "N"),
    "load_duration": (1e-4, 1.0, "s"),
    "load_angle_deg": (-360.0, 360.0, "deg"),
}


@dataclass(frozen=True)
class EventRanges:
    """The event distribution of an episode (module doc): the kinds drawn among, and a
    (low, high) uniform range per drawn quantity. The defaults are the ``Recover`` task's."""
    kinds: tuple[str, ...] = EVENT_KINDS
    delay: tuple[float, float] = (0.005, 0.005)
    shock_peak_g: tuple[float, float] = (2.0, 8.0)
    shock_duration: tuple[float, float] = (0.006, 0.018)
    shock_angle_deg: tuple[float, float] = (0.0, 360.0)
    unbalance_me: tuple[float, float] = (3e-3, 12e-3)
    unbalance_angle_deg: tuple[float, float] = (0.0, 360.0)
    load_peak: tuple[float, float] = (1000.0, 4000.0)
    load_duration: tuple[float, float] = (0.005, 0.03)
    load_angle_deg: tuple[float, float] = (0.0, 360.0)

    def __post_init__(self):
        kinds = (self.kinds,) if isinstance(self.kinds, str) else tuple(self.kinds)
        if not kinds or any(k not in EVENT_KINDS for k in kinds) or len(set(kinds)) != len(kinds):
            raise ValueError(f"events['kinds'] = {self.kinds!r} must be a non-empty selection of "
                             + ", ".join(repr(k) for k in EVENT_KINDS) + " (each once)")
        object.__setattr__(self, "kinds", kinds)
        for name, (lo, hi, unit) in LIMITS.items():
            object.__setattr__(self, name, check_range(f"events[{name!r}]", getattr(self, name),
                                                       lo, hi, unit))

    @classmethod
    def of(cls, events: "EventRanges | Mapping[str, Any] | None",
           default: "EventRanges") -> "EventRanges":
        """The env kwarg ``events``: None (the task's), an :class:`EventRanges`, or a dict of
        the fields to change in the task's; ValueError naming an unknown field."""
        if events is None:
            return default
        if isinstance(events, EventRanges):
            return events
        if not isinstance(events, Mapping):
            raise ValueError(f"events = {events!r} must be a dict of event ranges, e.g. "
                             "{'kinds': ('shock',), 'shock_peak_g': (5, 10)}")
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(events) - known)
        if unknown:
            raise ValueError(f"events: unknown field(s) {unknown}; the fields are "
                             + ", ".join(sorted(known)))
        return replace(default, **events)

    def draw(self, rng, t_start: float, dt: float, unbalance_radius: float) -> dict:
        """One event: the scene keys of its effect (the others off), from ``rng`` (a fixed
        number of draws whatever the kind, so that the kind does not shift later draws);
        ``t_start``: the episode start [s, scene time], ``dt``: the control step."""
        u = rng.uniform(size=5)
        kind = self.kinds[min(int(u[0] * len(self.kinds)), len(self.kinds) - 1)]
        start = t_start + math.ceil(_pick(self.delay, u[1]) / dt - 1e-9) * dt
        keys = {f"effects.{e}": False for e in ("base_excitation", "unbalance_change",
                                               "external_load")}
        if kind == "shock":
            keys.update({"effects.base_excitation": True, "ground.pulse_peak": 0.0,
                         "ground.pulse_peak_g": _pick(self.shock_peak_g, u[2]),
                         "ground.pulse_duration": _pick(self.shock_duration, u[3]),
                         "ground.pulse_angle_deg": _pick(self.shock_angle_deg, u[4]),
                         "ground.pulse_start": start})
        elif kind == "unbalance":
            keys.update({"effects.unbalance_change": True, "unbalance_change.time": start,
                         "unbalance_change.radius": unbalance_radius,
                         "unbalance_change.mass": _pick(self.unbalance_me, u[2]) / unbalance_radius,
                         "unbalance_change.angle_deg": _pick(self.unbalance_angle_deg, u[4])})
        else:
            keys.update({"effects.external_load": True, "external_load.profile": "half_sine",
                         "external_load.z": 0.0, "external_load.start": start,
                         "external_load.peak": _pick(self.load_peak, u[2]),
                         "external_load.duration": _pick(self.load_duration, u[3]),
                         "external_load.angle_deg": _pick(self.load_angle_deg, u[4])})
        return {"event": kind, "event_time": start - t_start, "keys": keys}

    def describe(self) -> dict:
        """The distribution as plain data (reports, docs)."""
        return {"kinds": list(self.kinds), **{n: list(getattr(self, n)) for n in LIMITS}}


def _pick(bounds: tuple[float, float], u: float) -> float:
    lo, hi = bounds
    return min(max(lo + u * (hi - lo), lo), hi)


def check_range(what: str, spec, lo: float, hi: float, unit: str) -> tuple[float, float]:
    """``(low, high)`` with lo <= low <= high <= hi, else ValueError naming ``what`` and the
    allowed range."""
    if (not isinstance(spec, (list, tuple)) or len(spec) != 2
            or not all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in spec)):
        raise ValueError(f"{what} = {spec!r} must be (low, high), real numbers within "
                         f"[{lo:g}, {hi:g}] {unit}")
    a, b = float(spec[0]), float(spec[1])
    if not (math.isfinite(a) and math.isfinite(b) and lo <= a <= b <= hi):
        raise ValueError(f"{what} = {spec!r}: need low <= high within [{lo:g}, {hi:g}] {unit}")
    return a, b
