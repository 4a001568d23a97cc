"""Checks of the environments' constructor kwargs: each bad value raises a ValueError (a
SceneError for scene keys) naming the kwarg and what it allows, before anything is built."""
from __future__ import annotations

import math
import numbers
from os import PathLike
from typing import Mapping

import numpy as np

from physics.scene import Scene, load_scene

from . import slots as S
from .scenario import POWER_RETURN


def check_real(name: str, value, lo: float, hi: float, low_open: bool = False) -> None:
    """ValueError naming ``name`` and the range unless ``value`` is a real number in [lo, hi]
    (``low_open``: in (lo, hi])."""
    interval = f"{'(' if low_open else '['}{lo:g}, {hi:g}]"
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name} = {value!r} must be a real number in {interval}, "
                         f"not a {type(value).__name__}")
    if not (math.isfinite(value) and lo <= value <= hi) or (low_open and value == lo):
        raise ValueError(f"{name} = {value!r} must be in {interval}")


def check_flag(name: str, value) -> bool:
    """A bool kwarg (bool or numpy bool; strings and numbers are refused)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} = {value!r} must be a bool (True or False), "
                         f"not a {type(value).__name__}")
    return bool(value)


def check_choice(name: str, value, allowed):
    """``value`` if it is None or one of ``allowed``, else ValueError naming them."""
    if value is not None and value not in allowed:
        raise ValueError(f"{name} = {value!r} must be None or one of {allowed}")
    return value


def check_steps(control_dt, episode_time, relevitation_hold, samples_per_step) -> None:
    """The time grid of an episode: control step, length, re-levitation hold, monitor samples."""
    check_real("control_dt", control_dt, 1e-6, 0.1)
    check_real("episode_time", episode_time, control_dt, 100.0)
    check_real("relevitation_hold", relevitation_hold, 0.0, 100.0)
    check_real("samples_per_step", samples_per_step, 1, 1000)
    if not float(samples_per_step).is_integer():
        raise ValueError(f"samples_per_step = {samples_per_step!r} must be an integer in [1, 1000]")


def check_weights(weights: Mapping[str, float]) -> dict[str, float]:
    """The reward weights ``w_*``: each a real number in [0, 1e9]."""
    for k, v in weights.items():
        check_real(k, v, 0.0, 1e9)
    return dict(weights)


def make_scene(scene, overrides) -> Scene:
    """The ``scene`` kwarg (preset name, TOML path, :class:`physics.Scene` or its dict) with the
    ``overrides`` applied."""
    if overrides is not None and not isinstance(overrides, Mapping):
        raise ValueError(f"overrides = {overrides!r} must be a dict of dotted scene keys, "
                         "e.g. {'contact.friction': 0.3}")
    if isinstance(scene, Mapping):          # Scene.to_dict / to_json form (a JSON env spec)
        scene = Scene.from_dict(scene)
    if isinstance(scene, Scene):
        return scene.with_overrides(overrides) if overrides else scene
    if isinstance(scene, (str, PathLike)):
        return load_scene(scene, overrides)
    raise ValueError(f"scene = {scene!r} must be a preset name, a TOML path, a "
                     "physics.Scene or its dict (Scene.to_dict(), as in a JSON env spec)")


def sensing_scene(base: Scene, noise: float, delay: float,
                  rate: float | None = None) -> tuple[Scene, float, float, float]:
    """The scene with the sensing kwargs in its ``sensor`` group (the one sensing model of
    physics/sensor.py), and the noise, delay and sample rate in effect: a kwarg, else the
    scene's value; a kwarg that contradicts the scene's own (non-zero, or for the sample rate
    non-default) value is refused."""
    default_rate = Scene().sensor.sample_rate
    values = {}
    # (key, kwarg value (0 or None: not given), the scene's value when it sets none)
    for key, given, neutral in (("sensor.noise", noise, 0.0), ("sensor.delay", delay, 0.0),
                                ("sensor.sample_rate", rate, default_rate)):
        scene_value = base.get(key)
        kwarg = "sensor_" + key.split(".", 1)[1]
        if not given:
            values[key] = scene_value
            continue
        if scene_value != neutral and given != scene_value:
            raise ValueError(f"{kwarg} = {given:g} contradicts the scene's {key} = "
                             f"{scene_value:g}; give one of them")
        values[key] = given
    if any(values[k] != base.get(k) for k in values):
        base = base.with_overrides(values)
    return base, values["sensor.noise"], values["sensor.delay"], values["sensor.sample_rate"]


def check_unused_ranges(randomization, randomize: bool, overrides, power_return_time) -> None:
    """Refuse randomisation ranges that would be silently dropped: all of them without
    ``randomize``, and a range for a key that ``overrides`` or the ``power_return_time`` kwarg
    fixes (a None range, "keep the key fixed", agrees with them)."""
    if randomization and not randomize:
        raise ValueError(f"randomization = {randomization!r} has no effect without randomize=True: "
                         "pass randomize=True, or leave randomization out")
    fixed_by = {key: f"overrides[{key!r}]" for key in overrides or {}}
    if power_return_time is not None:
        fixed_by[POWER_RETURN] = f"the power_return_time = {power_return_time!r} kwarg"
    for key, spec in (randomization or {}).items():
        if spec is not None and key in fixed_by:
            raise ValueError(f"randomization[{key!r}] = {spec!r} is a range for a key that "
                             f"{fixed_by[key]} fixes; give only one of the two (or None as its range)")


#: reward weight -> its slot in the kernel configuration: settable at any time, used from the
#: next step on (``env.w_whirl = 5``, ``vec_env.set_attr("w_whirl", 5)``)
WEIGHT_SLOTS = {"w_whirl": S.C_W_WHIRL, "w_contact": S.C_W_CONTACT, "w_displacement": S.C_W_DISP,
                "w_effort": S.C_W_EFFORT, "w_success": S.C_W_SUCCESS, "w_failure": S.C_W_FAILURE}
#: settings fixed at construction: assigning one raises (it would silently change nothing)
FIXED_SETTINGS = frozenset(("control_dt", "dt", "episode_time", "n_steps", "randomize",
                            "randomization", "ranges", "fixed_keys", "full_state", "command",
                            "power_return_time", "samples_per_step", "relevitation_hold",
                            "terminate_on_failure", "render_mode", "base_scene", "overrides",
                            "obs_names", "obs_scale", "action_names", "weights",
                            "sensor_noise", "sensor_delay", "sensor_sample_rate", "obs_latency_steps", "supervisor_authority",
                            "damping_action", "reward", "reward_kwargs", "reward_function",
                            "constraints", "task", "commands", "events"))


def _weight(name: str, doc: str) -> property:
    """A reward weight attribute: validated, written to the kernel, used from the next step."""
    return property(lambda self: self.weights[name], lambda self, v: self._set_weight(name, v),
                    doc=f"{doc} (settable: used from the next step)")


class SettingsGuard:
    """The attributes of an environment: reward weights settable at any time (checked, written
    to the kernel configuration ``_b.C``, used from the next step), the construction settings
    (:data:`FIXED_SETTINGS`) fixed once it is made, misspelt ``w_*`` names refused."""

    def __setattr__(self, name: str, value) -> None:
        if name in FIXED_SETTINGS and self.__dict__.get("_made"):
            raise AttributeError(f"{name} is fixed when the environment is made; make a new one "
                                 f"(gym.make(id, {name}=...)). Settable at any time: "
                                 f"{', '.join(WEIGHT_SLOTS)}")
        if name.startswith("w_") and name not in WEIGHT_SLOTS:
            raise AttributeError(f"{name!r} is not a reward weight; the weights are "
                                 f"{', '.join(WEIGHT_SLOTS)}")
        super().__setattr__(name, value)

    def set_wrapper_attr(self, name: str, value, *, force: bool = True) -> bool:
        """Gymnasium's way to set an attribute through ``gym.make``'s wrappers
        (``env.set_wrapper_attr("w_whirl", 5.0)``): a reward weight, a construction setting or a
        misspelt ``w_*`` name always reaches the environment, to be validated or refused there
        (never left on a wrapper, where the environment would not see it)."""
        if name in FIXED_SETTINGS or name.startswith("w_"):
            setattr(self, name, value)
            return True
        return super().set_wrapper_attr(name, value, force=force)

    def _set_weight(self, name: str, value) -> None:
        check_real(name, value, 0.0, 1e9)
        self.weights[name] = float(value)
        self._b.C[WEIGHT_SLOTS[name]] = value

    w_whirl = _weight("w_whirl", "reward weight per backward orbit revolution")
    w_contact = _weight("w_contact", "reward weight of the normalised contact force")
    w_displacement = _weight("w_displacement", "reward weight of the normalised displacement")
    w_effort = _weight("w_effort", "reward weight of the control effort")
    w_success = _weight("w_success", "re-levitation bonus")
    w_failure = _weight("w_failure", "penalty per remaining control step on termination")
