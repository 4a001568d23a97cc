"""Observation and action layouts: names, SI scales and spaces (one place, used by every env).

The kernel :func:`rotordrop_env.kernels.observe` writes the entries in exactly this order;
``physical value = obs * obs_scale`` (SI units).
"""
from __future__ import annotations

import math

import numpy as np
from gymnasium import spaces

from physics.model import VELOCITY, Model

SENSOR_NAMES = ("x1", "y1", "vx1", "vy1", "x2", "y2", "vx2", "vy2")
LEV_NAMES = ("amb_power", "controller_on", "i1x", "i1y", "i2x", "i2y")
CURRENT_ACTIONS = ("current_amb1_x", "current_amb1_y", "current_amb2_x", "current_amb2_y")
#: command="supervisor": switch, PID gain scale, reference offsets (radial, tangential) per plane
SUPERVISOR_ACTIONS = ("levitate", "gain", "offset_r1", "offset_t1", "offset_r2", "offset_t2")
SUPERVISOR_OBS = ("orbit_radius1", "orbit_radius2", "orbit_rate1", "orbit_rate2")
COMMANDS = ("discrete", "continuous", "supervisor")


def observation_layout(model: Model, damping: bool, relevitate: bool, full_state: bool,
                       episode_time: float, command: str | None = None
                       ) -> tuple[list[str], np.ndarray]:
    """Names and SI scales of the observation entries."""
    s = model.scene
    c = s.contact.clearance
    omega0 = max(s.rotor.speed_rpm * math.pi / 30.0, 100.0)
    names: list[str] = []
    scale: list[float] = []
    if full_state:
        names += list(model.names)
        scale += list(model.obs_scale)
    else:
        for n in SENSOR_NAMES:
            names.append(n)
            scale.append(c if n[0] in "xy" else VELOCITY)
        names += ["rotor_speed", "sleeve_speed1", "sleeve_speed2"]
        scale += [omega0] * 3
        if damping:
            names += ["damping1", "damping2"]
            scale += [s.support.damping_max] * 2
    names.append("time")
    scale.append(episode_time)
    if relevitate:
        names += list(LEV_NAMES)
        scale += [1.0, 1.0] + [max(s.amb.current_limit, 1e-9)] * 4
        if command == "supervisor":
            names += list(SUPERVISOR_OBS)
            scale += [c, c, omega0, omega0]
    return names, np.asarray(scale, dtype=np.float64)


def action_layout(damping: bool, relevitate: bool, command: str | None):
    """(space, names) of the action. Box in [-1, 1], or Discrete(2) for the bare switch."""
    names: list[str] = []
    if damping:
        names += ["damping1", "damping2"]
    if relevitate:
        if command == "discrete":
            if not damping:
                return spaces.Discrete(2), ["levitate"]
            names.append("levitate")
        elif command == "supervisor":
            names += list(SUPERVISOR_ACTIONS)
        else:
            names += list(CURRENT_ACTIONS)
    if not names:
        names = ["none"]
    n = len(names)
    return spaces.Box(-1.0, 1.0, shape=(n,), dtype=np.float32), names
