"""What a controller needs to know about the environment it drives, read from the env itself.

``Plant.from_env(env)`` reads ``obs_names`` / ``obs_scale`` / ``action_names`` / the action space
and the scene of a rotor-drop environment (a ``gym.make`` env, its unwrapped env or a batched
VecEnv). Controllers address observations by name and build actions by *channel*:

============  =========================================================================
channel       meaning of the value a controller gives (per environment)
============  =========================================================================
``damping``   (n, 2) damper commands in [-1, 1] (-1 = C_min, +1 = C_max) of housing 1, 2
``levitate``  (n,) or (n, 1) 1 = switch the built-in levitation controller on, 0 = stay off
              (``command="discrete"``)
``currents``  (n, 4) control currents / current limit, AMB1 x, AMB1 y, AMB2 x, AMB2 y
              (``command="continuous"``)
``gain``      (n,) or (n, 1) PID gain scale 2^value (``command="supervisor"``; 0 = the
              scene's gains)
``offsets``   (n, 4) reference offsets / clearance: radial and tangential (along a forward
              orbit) of AMB plane 1, then plane 2 (``command="supervisor"``)
============  =========================================================================

Channels a controller does not set (or sets to None) stay passive (damping held at its value at
the episode start, AMBs off). :meth:`Plant.compose` rejects, with a :class:`ControllerError`, a
channel the environment does not have, a value of another shape and a value outside [-1, 1]
(beyond round-off ``ROUND_OFF``) or NaN: it never clips or broadcasts a controller's mistake.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from difflib import get_close_matches
from functools import cached_property

import numpy as np

from rotordrop_env.layout import CURRENT_ACTIONS as CURRENT_NAMES
from rotordrop_env.layout import SUPERVISOR_ACTIONS

SENSORS = ("x1", "y1", "vx1", "vy1", "x2", "y2", "vx2", "vy2", "rotor_speed")
#: the damper values of housing 1, 2: sensor observations, else those of the full state
DAMPING_OBS = (("damping1", "damping2"), ("RB1.Cs", "RB2.Cs"))
POSITIONS = ("x1", "y1", "x2", "y2")
VELOCITIES = ("vx1", "vy1", "vx2", "vy2")
#: columns per environment of each channel, and what its normalised value means
CHANNEL_WIDTH = {"damping": 2, "levitate": 1, "currents": 4, "gain": 1, "offsets": 4}
CHANNEL_UNITS = {"damping": "-1 = C_min, +1 = C_max, not N s/m",
                 "levitate": "1 = on, 0 = off",
                 "currents": "current / current limit, not A",
                 "gain": "log2 of the PID gain scale",
                 "offsets": "reference offset / clearance, not m"}
#: action columns of each channel (continuous action spaces)
CHANNEL_ACTIONS = {"damping": ("damping1", "damping2"), "levitate": ("levitate",),
                   "currents": CURRENT_NAMES, "gain": SUPERVISOR_ACTIONS[1:2],
                   "offsets": SUPERVISOR_ACTIONS[2:]}
ROUND_OFF = 1e-6        # tolerated excess over |value| = 1 (clipped away)


class ControllerError(ValueError):
    """A controller's bug or bad command, named with the controller (one line in the CLIs)."""


def task_flags(env_id: str) -> tuple[bool, bool]:
    """(damping, relevitate): what the environment of ``env_id`` lets a controller command, as
    its task declares it (the damper and AMB command interfaces of
    :class:`rotordrop_env.tasks.Task`). (False, False) for an id that is not a rotor-drop task."""
    from rotordrop_env.tasks import TASKS
    task = TASKS.get(env_id)
    return (task.damper, task.amb) if task is not None else (False, False)


def make_env(env_id: str, **kwargs):
    """``gym.make`` of a rotor-drop environment (registers the ids first)."""
    import gymnasium as gym
    import rotordrop_env  # noqa: F401
    return gym.make(env_id, **kwargs)


def plant_of(env_id: str, **kwargs) -> "Plant":
    """The :class:`Plant` of ``gym.make(env_id, **kwargs)`` (the env is closed again)."""
    env = make_env(env_id, **kwargs)
    try:
        return Plant.from_env(env)
    finally:
        env.close()


@dataclass(frozen=True)
class Plant:
    env_id: str
    obs_names: tuple[str, ...]
    obs_scale: np.ndarray
    action_names: tuple[str, ...]
    discrete: bool
    control_dt: float
    clearance: float
    damping_range: tuple[float, float]     # C_min, C_max [N s/m]
    current_limit: float                   # [A]
    pid: tuple[float, float, float]        # built-in PID gains kp [A/m], ki [A/(m s)], kd [A s/m]
    feedforward: tuple[float, float]       # gravity currents of AMB1, AMB2 (y axes) [A]
    liftoff_ramp: float                    # [s]
    damping_action: str = "linear"         # the env's damper map (``damping_action``)

    @classmethod
    def from_env(cls, env) -> "Plant":
        u = env.unwrapped if hasattr(env, "unwrapped") else env
        while hasattr(u, "venv") and not hasattr(u, "envs"):      # SB3 VecEnv wrappers
            u = u.venv
        if hasattr(u, "envs") and not hasattr(u, "obs_names"):     # batched or DummyVecEnv
            u = u.envs[0].unwrapped
        elif hasattr(u, "get_attr") and not hasattr(u, "obs_names"):   # SubprocVecEnv
            spec = u.get_attr("spec", [0])[0]
            return plant_of(spec.id, **spec.kwargs)
        s = u.base_scene
        m = u.model                # gravity feed-forward currents: 0 without actuator AMBs
        return cls(env_id=u.spec.id if u.spec is not None else type(u).__name__,
                   obs_names=tuple(u.obs_names), obs_scale=np.asarray(u.obs_scale, dtype=np.float64),
                   action_names=tuple(u.action_names), discrete=bool(u._discrete),
                   control_dt=float(u.dt), clearance=s.contact.clearance,
                   damping_range=(s.support.damping_min, s.support.damping_max),
                   current_limit=s.amb.current_limit, pid=(s.amb.kp, s.amb.ki, s.amb.kd),
                   feedforward=(m.param("amb1.feedforward_current"), m.param("amb2.feedforward_current")),
                   liftoff_ramp=s.amb.liftoff_ramp_time,
                   damping_action=getattr(u, "damping_action", "linear"))

    # ------------------------------------------------------------------ observations --
    def require_sensors(self, who: str) -> None:
        """:class:`ControllerError` naming ``who`` unless the environment observes the sensor
        signals ``SENSORS`` (a ``full_state=True`` environment observes the state vector)."""
        missing = [n for n in SENSORS if n not in self.obs_names]
        if missing:
            raise ControllerError(f"{who} needs the sensor observations {', '.join(missing)}; "
                                  f"create the environment without full_state=True")

    @cached_property
    def _columns(self) -> dict[str, int]:
        return {n: j for j, n in enumerate(self.obs_names)}

    def index(self, name: str) -> int:
        try:
            return self._columns[name]
        except KeyError:
            raise KeyError(f"{self.env_id} has no observation {name!r} "
                           f"(it has {', '.join(self.obs_names)})") from None

    def get(self, obs: np.ndarray, name: str) -> np.ndarray:
        """Physical (SI) value of observation ``name`` for each row of ``obs``."""
        j = self.index(name)
        return obs[:, j] * self.obs_scale[j]

    def _block_columns(self, names: tuple[str, ...]) -> tuple[list[int], np.ndarray]:
        j = [self.index(n) for n in names]
        return j, self.obs_scale[j]

    @cached_property
    def _positions(self):
        return self._block_columns(POSITIONS)

    @cached_property
    def _velocities(self):
        return self._block_columns(VELOCITIES)

    def positions(self, obs: np.ndarray) -> np.ndarray:
        """(n, 4) sensed displacements x1, y1, x2, y2 [m]."""
        j, scale = self._positions
        return obs[:, j] * scale

    def velocities(self, obs: np.ndarray) -> np.ndarray:
        """(n, 4) sensed velocities vx1, vy1, vx2, vy2 [m/s]."""
        j, scale = self._velocities
        return obs[:, j] * scale

    def spin_sign(self, obs: np.ndarray) -> np.ndarray:
        """(n,) sign of the rotor speed (+1 at standstill)."""
        return np.where(self.get(obs, "rotor_speed") < 0.0, -1.0, 1.0)

    @cached_property
    def gravity_currents(self) -> np.ndarray:
        """(4,) gravity feed-forward per AMB axis (x1, y1, x2, y2) / current limit."""
        return np.array([0.0, self.feedforward[0], 0.0, self.feedforward[1]]) / self.current_limit

    @cached_property
    def _damping(self):
        return self._block_columns(next((d for d in DAMPING_OBS if set(d) <= set(self.obs_names)),
                                        DAMPING_OBS[0]))

    def damping_level(self, obs: np.ndarray) -> np.ndarray:
        """(n, 2) current damper values as commands in [-1, 1]."""
        lo, hi = self.damping_range
        j, scale = self._damping
        return np.clip(2.0 * (obs[:, j] * scale - lo) / (hi - lo) - 1.0, -1.0, 1.0)

    def damper_action(self, command: np.ndarray) -> np.ndarray:
        """The env's damper action for damper commands in [-1, 1] (-1 C_min, +1 C_max, linear):
        the command itself, or with ``damping_action="from_max"`` (where the action 0 is
        already C_max) the action (command - 1) / 2 in [-1, 0] that gives the same damping."""
        return command if self.damping_action == "linear" else 0.5 * (command - 1.0)

    def power_available(self, obs: np.ndarray) -> np.ndarray:
        if "amb_power" not in self.obs_names:
            return np.zeros(len(obs), dtype=bool)
        return self.get(obs, "amb_power") > 0.5

    # --------------------------------------------------------------------- actions --
    @cached_property
    def channels(self) -> tuple[str, ...]:
        return tuple(ch for ch, names in CHANNEL_ACTIONS.items() if names[0] in self.action_names)

    @cached_property
    def _action_columns(self) -> dict[str, list[int]]:
        """Action columns of each channel (continuous action spaces)."""
        names = self.action_names
        return {ch: [names.index(n) for n in CHANNEL_ACTIONS[ch]] for ch in self.channels}

    def checked(self, commands, n: int, who: str = "controller") -> dict[str, np.ndarray]:
        """``commands`` (channel -> value) as (n, width) float arrays, None values dropped;
        a :class:`ControllerError` naming ``who`` for anything else (module docstring)."""
        if not isinstance(commands, Mapping):
            raise ControllerError(f"{who}: commands() returned {type(commands).__name__}, expected "
                                  f"a dict channel -> array (channels of {self.env_id}: "
                                  f"{', '.join(self.channels) or 'none'})")
        return {ch: self._checked_channel(ch, v, n, who)
                for ch, v in commands.items() if v is not None}

    def _checked_channel(self, channel, value, n: int, who: str) -> np.ndarray:
        if channel not in self.channels:
            raise ControllerError(f"{who}: {self._channel_problem(channel)}; {self.env_id} has "
                                  f"the channels {', '.join(self.channels) or 'none'}")
        try:
            v = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ControllerError(f"{who}: channel {channel!r} is not numeric ({exc})") from exc
        width = CHANNEL_WIDTH[channel]
        shapes = [(n, width)] + ([(n,)] if width == 1 else [])
        if v.shape not in shapes:
            raise ControllerError(f"{who}: channel {channel!r} has shape {v.shape}, expected "
                                  f"{' or '.join(map(str, shapes))} (one row per observation; "
                                  f"e.g. np.full({shapes[0]}, value))")
        bad = ~(np.abs(v) <= 1.0 + ROUND_OFF)                       # NaN is bad too
        if bad.any():
            raise ControllerError(f"{who}: channel {channel!r} value {v[bad][0]:g} is outside the "
                                  f"allowed range [-1, 1] ({CHANNEL_UNITS[channel]})")
        return v.reshape(n, width)

    def _channel_problem(self, channel) -> str:
        if channel in CHANNEL_WIDTH:
            return (f"channel {channel!r} is not an action of this environment (set it only "
                    f"if {channel!r} in self.plant.channels)")
        close = get_close_matches(str(channel), list(CHANNEL_WIDTH), n=1)
        return f"unknown channel {channel!r}" + (f" (did you mean {close[0]!r}?)" if close else "")

    def compose(self, n: int, commands: dict, hold_damping: np.ndarray | None = None,
                who: str = "controller") -> np.ndarray:
        """The env action for each of n environments from channel commands (module docstring),
        checked with :meth:`checked` (``who`` names the controller in errors).

        ``hold_damping`` (n, 2) is the passive damper command used when ``damping`` is not given.
        """
        c = self.checked(commands, n, who)
        lev = c["levitate"][:, 0] if "levitate" in c else None
        if self.discrete:
            return np.zeros(n, dtype=np.int64) if lev is None else (lev > 0.5).astype(np.int64)
        a = np.zeros((n, len(self.action_names)), dtype=np.float32)
        cols = self._action_columns
        if "damping" in cols:
            d = c.get("damping", hold_damping)
            if d is not None:
                a[:, cols["damping"]] = self.damper_action(d)
        if "levitate" in cols:
            a[:, cols["levitate"][0]] = -1.0 if lev is None else np.where(lev > 0.5, 1.0, -1.0)
        for ch in ("currents", "gain", "offsets"):
            if ch in c:
                a[:, cols[ch]] = c[ch]
        return np.clip(a, -1.0, 1.0)                  # round-off within ROUND_OFF only
