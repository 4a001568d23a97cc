"""The command interfaces of the environments: what an agent's action commands.

A task names its interfaces (:class:`rotordrop_env.tasks.Task` ``commands``); the action is
their entries in the order of :data:`INTERFACES`, and the step kernel maps each interface's
entries onto the physics' controls (:func:`rotordrop_env.kernels.apply_action`).

==========  ==================================================================  ================
interface   action entries                                                      scene it needs
==========  ==================================================================  ================
damper      ``damping1``, ``damping2``: each housing's support damping command   ``effects.semi_active_damper``,
            (``damping_action``: "linear" or "from_max")                         ``effects.housing``
amb         after the power return (``power_return_time``), by ``command``:      ``effects.amb = "actuator"``
            "discrete" (``levitate``: switch the built-in PID on), "continuous"
            (the 4 normalised control currents) or "supervisor" (``levitate``,
            ``gain``, 4 reference offsets; ``supervisor_authority``)
==========  ==================================================================  ================

:class:`Commands` is one environment's interfaces with their settings (the env kwargs
``command``, ``damping_action``, ``supervisor_authority``, ``power_return_time``), checked: a
setting for an interface the task does not have is refused (it would silently change nothing).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np
from gymnasium import spaces

from physics.scene import Scene, SceneError

from . import slots as S
from .layout import COMMANDS, action_layout
from .scenario import POWER_RETURN, POWER_RETURN_LIMITS
from .settings import check_real
from .tasks import AMB, DAMPER, DEFAULT_POWER_RETURN, INTERFACES  # noqa: F401 (re-exported)

#: the kernel's re-levitation mode of each ``command``
LEV_CODES = {"discrete": S.LEV_DISCRETE, "continuous": S.LEV_CONTINUOUS,
             "supervisor": S.LEV_SUPERVISOR}
#: the kernel's map of each ``damping_action`` (damper action -> commanded damping)
DAMPING_ACTIONS = {"linear": S.DAMP_LINEAR, "from_max": S.DAMP_FROM_MAX}
#: command="supervisor": |offset| <= SUPERVISOR_OFFSET x clearance; gain scale in
#: [2^-SUPERVISOR_OCTAVES, 2^SUPERVISOR_OCTAVES]
SUPERVISOR_OFFSET = 1.0
SUPERVISOR_OCTAVES = 1.0


def supervisor_scales(scene: Scene, authority: float = 1.0) -> tuple[float, float]:
    """(largest reference offset [m], gain-scale octaves) of ``command="supervisor"`` with the
    ``supervisor_authority`` ``authority`` (1: the full ranges)."""
    return authority * SUPERVISOR_OFFSET * scene.contact.clearance, authority * SUPERVISOR_OCTAVES


@dataclass(frozen=True)
class Commands:
    """One environment's command interfaces and their settings (see the module docstring)."""
    damper: bool
    amb: bool
    command: str | None = None                 # amb: "discrete", "continuous" or "supervisor"
    damping_action: str = "linear"             # damper: "linear" or "from_max"
    supervisor_authority: float = 1.0          # amb, command="supervisor": a in (0, 1]
    power_return_time: float | None = None     # amb: power returns [s after the fault]

    @classmethod
    def of(cls, interfaces, env_name: str, command=None, damping_action="linear",
           supervisor_authority=1.0, power_return_time=None, default_command="discrete",
           default_power_return=DEFAULT_POWER_RETURN) -> "Commands":
        """The checked settings of an environment (class ``env_name``) with ``interfaces``;
        ValueError naming the kwarg and what it allows."""
        damper, amb = DAMPER in interfaces, AMB in interfaces
        if not amb:
            for kwarg, value in (("command", command), (POWER_RETURN, power_return_time)):
                if value is not None:
                    raise ValueError(f"{kwarg}= applies to the re-levitation environments only, "
                                     f"not {env_name}")
        if command is not None and command not in COMMANDS:
            raise ValueError(f"command = {command!r} is not a command mode; the modes are "
                             + ", ".join(repr(c) for c in COMMANDS))
        if power_return_time is not None:
            check_real(POWER_RETURN, power_return_time, *POWER_RETURN_LIMITS)
        check_real("supervisor_authority", supervisor_authority, 0.0, 1.0, low_open=True)
        if supervisor_authority != 1.0 and command != "supervisor":
            raise ValueError(f"supervisor_authority = {supervisor_authority!r} applies to "
                             f"command='supervisor' only, not command={command!r}")
        if damping_action not in DAMPING_ACTIONS:
            raise ValueError(f"damping_action = {damping_action!r} is not a damper map; the maps "
                             "are " + ", ".join(repr(m) for m in DAMPING_ACTIONS))
        if damping_action != "linear" and not damper:
            raise ValueError(f"damping_action = {damping_action!r} applies to the environments "
                             f"with damper commands (Damping, Full) only, not {env_name}")
        return cls(damper, amb, (command or default_command) if amb else None, damping_action,
                   float(supervisor_authority),
                   (default_power_return if power_return_time is None
                    else float(power_return_time)) if amb else None)

    @property
    def interfaces(self) -> tuple[str, ...]:
        return tuple(n for n, on in ((DAMPER, self.damper), (AMB, self.amb)) if on)

    def scene(self, base: Scene, overrides: Mapping | None, env_name: str,
              task_keys: Mapping | None = None) -> Scene:
        """``base`` with the scene keys the interfaces need and the task's ``task_keys``;
        SceneError when ``overrides`` asks for another value of one of them, or when the
        damper has no elastic housing to act on."""
        forced = {k: v for n in self.interfaces for k, v in INTERFACES[n].items()}
        forced.update(task_keys or {})
        for key, value in forced.items():
            given = (overrides or {}).get(key)
            if given is not None and str(given).lower() != str(value).lower():
                raise SceneError(f"{env_name} needs {key} = {value}, got {given!r}")
        base = base.with_overrides(forced) if forced else base
        if self.damper and not base.effects.housing:
            raise SceneError("the damping environments need effects.housing = true")
        return base

    def action_layout(self):
        """(space, names) of the action (:func:`rotordrop_env.layout.action_layout`)."""
        return action_layout(self.damper, self.amb, self.command)

    def configure(self, C, scene: Scene) -> None:
        """The interfaces' modes and ranges in the kernel configuration ``C``."""
        C[S.C_DAMP] = DAMPING_ACTIONS[self.damping_action] if self.damper else S.DAMP_NONE
        C[S.C_LEV] = LEV_CODES[self.command] if self.amb else S.LEV_NONE
        C[S.C_SUP_OFFSET], C[S.C_SUP_OCTAVES] = supervisor_scales(scene, self.supervisor_authority)


# ------------------------------------------------------------------------ the action --
def real_action(action, space: spaces.Space, names) -> np.ndarray:
    """``action`` as an array of real numbers; a bool, complex, string or object action raises
    ValueError naming the action space (numpy would cast it silently)."""
    a = np.asarray(action)
    if a.dtype.kind not in "fiu":
        raise ValueError(f"action {action!r} ({a.dtype} values) is not in {space}: give real "
                         f"numbers ({', '.join(names)})")
    return a


def load_action(action, act: np.ndarray, space: spaces.Space, names) -> None:
    """Write one environment's ``action`` into its kernel action array ``act``; ValueError
    naming the action space for a wrong type or shape (the kernel checks the values)."""
    if type(action) is np.ndarray and action.dtype.kind == "f" and action.shape == act.shape \
            and not isinstance(space, spaces.Discrete):
        act[:] = action                     # the common case, checked at once
        return
    a = real_action(action, space, names)
    if isinstance(space, spaces.Discrete):
        if a.size != 1:
            raise ValueError(f"action {action!r} is not in {space}: give 0 or 1")
        act[0] = a.item()
        return
    if a.shape != space.shape:
        raise ValueError(f"action {action!r} has shape {a.shape}; "
                         f"{space} needs {space.shape} ({', '.join(names)})")
    act[:] = a


def action_error(err: int, action, space: spaces.Space, names) -> ValueError:
    """The ValueError of an action the kernel refused (``err``: its ERR_* code)."""
    what = "non-finite" if err == S.ERR_NAN else "out-of-range"
    if isinstance(space, spaces.Discrete):
        return ValueError(f"{what} action {action!r}: the {space} action "
                          "(levitate) must be 0 (stay off) or 1 (switch on)")
    return ValueError(f"{what} action {action!r}: {space} entries must be finite "
                      f"and in [-1, 1] ({', '.join(names)})")
