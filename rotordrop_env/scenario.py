"""Episode scenarios: randomisation ranges, sampling from ``np_random``, and the cached state at
the fault (so that no episode re-simulates the levitated phase before the drop)."""
from __future__ import annotations

import math
import numbers
from collections import OrderedDict
from typing import Any, Mapping

import numpy as np

from physics.equilibrium import levitated_state
from physics.model import Model, build_model
from physics.scene import Scene, SceneError, param_meta
from physics.simulate import Integrator, run_segments

POWER_RETURN = "power_return_time"
#: Allowed power return [s after the fault] (the ``power_return_time`` kwarg's range too).
POWER_RETURN_LIMITS = (0.0, 100.0)
LAWS = ("uniform", "log_uniform")

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


def resolve_ranges(custom: Mapping[str, Any] | None, relevitate: bool,
                   env_name: str, task_ranges: Mapping[str, Any] | None = None
                   ) -> tuple[dict, frozenset]:
    """The defaults, updated by a task's ``task_ranges`` (its scenario draw: a range, or None
    to leave a default key out) and by the user's ``randomization``: (ranges drawn at every
    reset, keys it fixes). A value is ``(low, high)`` (uniform), ``(law, low, high)``, or
    ``None``: fix the key at the scene's value (it is still drawn, see :func:`sample`)."""
    if custom is None:
        custom = {}
    if not isinstance(custom, Mapping):
        raise ValueError(f"randomization = {custom!r} must be a dict {{key: (low, high) | "
                         "(law, low, high) | None}")
    if POWER_RETURN in custom and not relevitate:
        raise ValueError(f"randomization[{POWER_RETURN!r}] applies to the re-levitation "
                         f"environments only, not {env_name}")
    ranges = {k: v for k, v in DEFAULT_RANGES.items() if relevitate or k != POWER_RETURN}
    for key, spec in (task_ranges or {}).items():
        if spec is None:
            ranges.pop(key, None)
        else:
            ranges[key] = parse_range(key, spec)
    fixed = set()
    for key, spec in custom.items():
        if spec is None:
            _bounds(key, real=False)                    # unknown keys raise
            fixed.add(key)
        else:
            ranges[key] = parse_range(key, spec)
    return ranges, frozenset(fixed)


def parse_range(key: str, spec: Any) -> tuple[str, float, float]:
    """``(low, high)`` or ``(law, low, high)`` -> (law, low, high), checked against the key's
    allowed range (the scene's parameter table; [0, 100] s for ``power_return_time``)."""
    what = f"randomization[{key!r}] = {spec!r}"
    if not isinstance(spec, (list, tuple)) or len(spec) not in (2, 3):
        raise ValueError(f"{what}: give (low, high), ('uniform' | 'log_uniform', low, high), "
                         "or None to keep the key fixed")
    law, lo, hi = ("uniform", *spec) if len(spec) == 2 else spec
    if law not in LAWS:
        raise ValueError(f"{what}: the law must be one of {', '.join(LAWS)}, got {law!r}")
    if not all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in (lo, hi)):
        raise ValueError(f"{what}: low and high must be real numbers")
    lo, hi = float(lo), float(hi)
    b_lo, b_hi, unit = _bounds(key)
    if not (math.isfinite(lo) and math.isfinite(hi) and b_lo <= lo <= hi <= b_hi):
        raise ValueError(f"{what}: need finite low <= high inside the allowed range of {key}, "
                         f"[{b_lo:g}, {b_hi:g}] {unit}")
    if law == "log_uniform" and lo <= 0.0:
        raise ValueError(f"{what}: log_uniform needs low > 0")
    return law, lo, hi


def _bounds(key: str, real: bool = True) -> tuple[float, float, str]:
    """(low, high, unit) a key may take; SceneError for an unknown key and, with ``real``, a
    key that is not a real-valued scene parameter."""
    if key == POWER_RETURN:
        return (*POWER_RETURN_LIMITS, "s")
    try:
        meta = param_meta(key)
    except SceneError as exc:
        raise SceneError(f"randomization: {exc} (or {POWER_RETURN!r})") from None
    if real and meta["type"] is not float:
        raise SceneError(f"randomization[{key!r}]: {key} is a {meta['type'].__name__} parameter; "
                         "only real-valued parameters can be randomised")
    return meta["lo"], meta["hi"], meta["unit"]


def sample(ranges: Mapping[str, tuple[str, float, float]], rng: np.random.Generator,
           fixed: frozenset = frozenset()) -> dict:
    """One draw per key, in sorted key order (reproducible for a seeded ``rng``). The ``fixed``
    keys are drawn too and then left out, so that fixing a key does not change the other keys'
    values for the same seed."""
    out = {}
    for key in sorted(ranges):
        law, lo, hi = ranges[key]
        u = rng.uniform()
        v = lo + u * (hi - lo) if law == "uniform" else math.exp(
            math.log(lo) + u * (math.log(hi) - math.log(lo)))
        if key not in fixed:
            out[key] = min(max(v, lo), hi)      # no round-off outside the range
    return out


def draw(randomization: Mapping[str, Any] | None, seed: int, relevitate: bool = True,
         env_name: str = "FullEnv") -> tuple[dict, np.random.Generator]:
    """The scenario an environment (class ``env_name``, re-levitating or not) made with
    ``randomization`` draws at ``reset(seed=seed)``, without making one; and the generator after
    the draw, for what a caller draws beyond the scene (sensing, latency)."""
    ranges, fixed = resolve_ranges(randomization, relevitate, env_name)
    rng = np.random.default_rng(seed)
    return sample(ranges, rng, fixed), rng


class FaultState:
    """A scene compiled, its state at the instant of the fault, and the integrator (its
    settings and its step size there) that the episode continues with."""

    def __init__(self, scene: Scene):
        self.scene = scene
        self.model: Model = build_model(scene)
        self.y = levitated_state(self.model)
        self.integrator = Integrator(self.model)
        t_off = scene.amb.off_time
        if not self.model.has_ambs or t_off <= 0.0:
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


def layout_base(base: Scene, ranges: Mapping[str, tuple[str, float, float]],
                fixed: frozenset = frozenset()) -> Scene:
    """``base``, or with the low end of each range that would switch a state on in every draw
    (``amb.coil_time_constant`` 0 in the scene, a range above 0: the coil-lag states), so that
    the state layout is the same at every reset. A range that crosses the switch (low 0, high
    > 0) raises SceneError."""
    switch = {}
    n_base = build_model(base).n_state
    for key, (_, lo, hi) in sorted(ranges.items()):
        if key == POWER_RETURN or key in fixed:
            continue
        n_lo = build_model(base.with_overrides({key: lo})).n_state
        n_hi = build_model(base.with_overrides({key: hi})).n_state if hi != lo else n_lo
        if n_lo != n_hi:
            raise SceneError(f"randomization[{key!r}] = ({lo:g}, {hi:g}) changes the state layout "
                             "within its range: keep it on one side of the switch (e.g. low > 0)")
        if n_lo != n_base:
            switch[key] = lo
    return base.with_overrides(switch) if switch else base


def reset_options(options: Mapping | None, relevitate: bool) -> dict:
    """The scenario keys that ``reset(options={"scenario": {...}})`` fixes for one episode."""
    fixed = (options or {}).get("scenario") or {}
    unknown = set(options or {}) - {"scenario"}
    if unknown or not isinstance(fixed, Mapping):
        what = f"unknown reset option(s) {sorted(unknown)}" if unknown else \
            f"reset option scenario = {fixed!r} is not a dict"
        raise ValueError(f"{what}; use options="
                         "{'scenario': {dotted_key: value, 'power_return_time': s}}")
    if POWER_RETURN in fixed and not relevitate:
        raise ValueError(f"{POWER_RETURN} applies to the re-levitation environments only")
    return dict(fixed)


def scenario_report(ranges: Mapping, values: Mapping, scene: Scene,
                    power_return: float | None) -> dict:
    """The machine of an episode: the value of every randomisation key (drawn, fixed by the
    user, or the scene's without ``randomize``) and of every key fixed by ``reset`` options;
    the power return as applied (``power_return``: on the control-step grid, None without)."""
    keys = sorted((set(ranges) | set(values)) - {POWER_RETURN})
    out = {k: scene.get(k) for k in keys}
    if power_return is not None:             # without the subtraction's round-off
        out[POWER_RETURN] = round(float(power_return), 12)
    return out
