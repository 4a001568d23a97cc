"""Episode scenarios: randomisation ranges, sampling from ``np_random``, and the cached state at
the fault (so that no episode re-simulates the levitated phase before the drop)."""
from __future__ import annotations

import math
from collections import OrderedDict
from typing import Any, Mapping

import numpy as np

from physics.equilibrium import levitated_state
from physics.model import AMB_NONE, F_AMB, Model, build_model
from physics.scene import Scene, SceneError
from physics.simulate import Integrator, run_segments

POWER_RETURN = "power_return_time"

#: Default randomisation ranges (spec §2 study ranges): key -> (law, low, high).
#: ``uniform`` or ``log_uniform``; ``power_return_time`` [s after the fault] applies to the
#: re-levitation environments only.
DEFAULT_RANGES: dict[str, tuple[str, float, float]] = {
    "contact.friction": ("uniform", 0.1, 0.5),
    "unbalance.mass": ("uniform", 0.5e-3, 2e-3),
    "support.stiffness": ("log_uniform", 5e6, 5e8),
    "support.damping": ("log_uniform", 2790.0, 27900.0),
    "rotor.speed_rpm": ("uniform", 8000.0, 12000.0),
    POWER_RETURN: ("uniform", 0.02, 0.1),
}


def resolve_ranges(custom: Mapping[str, Any] | None, relevitate: bool, base: Scene) -> dict:
    """Merge user ranges into the defaults. A value is ``(low, high)`` (uniform),
    ``(law, low, high)``, or ``None`` to keep that parameter fixed."""
    ranges = dict(DEFAULT_RANGES)
    for key, spec in (custom or {}).items():
        if spec is None:
            ranges.pop(key, None)
            continue
        if key != POWER_RETURN:
            base.get(key)                                   # unknown keys raise SceneError
        spec = tuple(spec)
        if len(spec) == 2:
            spec = ("uniform",) + spec
        if len(spec) != 3 or spec[0] not in ("uniform", "log_uniform"):
            raise ValueError(f"randomization[{key!r}] = {spec!r}: give (low, high) or "
                             "('uniform' | 'log_uniform', low, high)")
        law, lo, hi = spec[0], float(spec[1]), float(spec[2])
        if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
            raise ValueError(f"randomization[{key!r}]: need finite low <= high, got ({lo}, {hi})")
        if law == "log_uniform" and lo <= 0.0:
            raise ValueError(f"randomization[{key!r}]: log_uniform needs low > 0, got {lo}")
        ranges[key] = (law, lo, hi)
    if not relevitate:
        ranges.pop(POWER_RETURN, None)
    return ranges


def sample(ranges: Mapping[str, tuple[str, float, float]], rng: np.random.Generator) -> dict:
    """One draw per key, in sorted key order (reproducible for a seeded ``rng``)."""
    out = {}
    for key in sorted(ranges):
        law, lo, hi = ranges[key]
        u = rng.uniform()
        v = lo + u * (hi - lo) if law == "uniform" else math.exp(
            math.log(lo) + u * (math.log(hi) - math.log(lo)))
        out[key] = min(max(v, lo), hi)          # no round-off outside the range
    return out


class FaultState:
    """A scene compiled, its state at the instant of the fault, and the integrator (its
    settings and its step size there) that the episode continues with."""

    def __init__(self, scene: Scene):
        self.scene = scene
        self.model: Model = build_model(scene)
        self.y = levitated_state(self.model)
        self.integrator = Integrator(self.model)
        t_off = scene.amb.off_time
        if self.model.I[F_AMB] == AMB_NONE or t_off <= 0.0:
            self.t_fault = 0.0                  # no AMBs: the drop starts at t = 0
        else:
            self.t_fault = t_off
            run_segments(self.integrator, self.y, t_off)     # as physics.simulate: bit-identical


_CACHE: "OrderedDict[Scene, FaultState]" = OrderedDict()
CACHE_SIZE = 32


def fault_state(scene: Scene) -> FaultState:
    """The (cached) fault state of a scene."""
    fs = _CACHE.get(scene)
    if fs is None:
        fs = FaultState(scene)
        _CACHE[scene] = fs
        if len(_CACHE) > CACHE_SIZE:
            _CACHE.popitem(last=False)
    else:
        _CACHE.move_to_end(scene)
    return fs


def scenario_scene(base: Scene, values: Mapping[str, Any]) -> Scene:
    """The base scene with the scene keys of a scenario applied (clear SceneError otherwise)."""
    keys = {k: v for k, v in values.items() if k != POWER_RETURN}
    if not keys:
        return base
    try:
        return base.with_overrides(keys)
    except SceneError as exc:
        raise SceneError(f"scenario {keys}: {exc}") from None
