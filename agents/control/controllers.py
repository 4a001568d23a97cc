"""Baseline controllers with the interface of a trained SB3 policy.

Every controller is built from a :class:`~agents.control.plant.Plant` (what the environment tells about
its observations and actions) and answers ``predict(obs, state, episode_start, deterministic)``
with ``(actions, state)`` exactly like ``model.predict`` of Stable-Baselines3, for a single
observation or a batch. Controllers read observations by *name* (``env.unwrapped.obs_names``)
and convert them to SI with ``obs_scale``, so they do not depend on the observation layout.

Baselines (spec §5-6):

``passive``
    No control: the support damping stays at the scene's C_s and the AMBs stay off.
``max-damping``
    Constant maximum support damping C_max in both housings.
``whirl-switch``
    Switching damper: C_max in a housing while the orbit at that plane turns against the spin
    (orbit angular momentum x ẏ − y ẋ opposite to Ω) beyond ``r_on`` × clearance (the signature
    of backward whirl, spec §7), held for ``hold_time`` seconds; otherwise the passive C_s.
``pid-relevitate``
    Re-levitation once power is back (spec §5), ``command="continuous"``: its own PID per AMB
    axis at the control rate (the scene's gains ``amb.kp/ki/kd``, gravity feed-forward,
    anti-windup), with a reference ramped from the landing position to the centre over
    ``amb.liftoff_ramp_time``, currents limited to ±1 (the normalised current limit).
``builtin-relevitate``
    ``command="discrete"``: switches the environment's built-in PID (the same law, evaluated
    continuously inside the integrator, same ramp) on as soon as power is back.
``whirl-brake``
    Continuous currents: PD, gravity feed-forward and terms against backward whirl (class doc).
``whirl-brake-robust``
    ``whirl-brake`` with gains re-tuned on the robust suite's distribution (class doc).
``inner-loop``, ``inner-loop-lift``, ``whirl-brake-sup``
    ``command="supervisor"``: the built-in PID switched on at power return with C_max, alone
    (zero reference offsets), with a constant gain scale and radial offset (lift assist), or
    with whirl-brake's whirl terms as reference offsets.

The PID starts when the ``amb_power`` observation shows the power (from the control step whose
action can first use it); the built-in switch needs no observation and engages in the very step
the power returns.
"""
from __future__ import annotations

import math
from contextlib import contextmanager

import numpy as np

from .plant import ControllerError, Plant, task_flags


class Controller:
    """Base class: ``act(obs)`` maps a batch of raw observations to a batch of actions.

    Subclasses set ``name`` and ``needs`` and return channel values from ``commands(obs)``
    (:mod:`agents.control.plant`). One controller drives many episodes, so ``__init__`` is for
    constants (gains); **per-episode state** (integrators, filters, timers, flags) is (re)set in
    ``reset(n, which)``, which ``predict`` calls at episode starts: for all ``n`` environments
    when ``which`` is None, else where ``which`` is True. Override it, call
    ``super().reset(n, which)`` first and give each state array ``n`` rows. ``predict`` finds
    the starts itself (:meth:`new_episodes`: ``episode_start``, or the ``time`` observation
    going back), so one controller drives episode after episode without the caller's help.
    ``self.t`` (n,) is the time since each episode's start [s]. Errors in a controller, and
    commands of an unknown channel, shape or range, raise
    :class:`~agents.control.plant.ControllerError` naming it.
    """

    name = "controller"
    #: channels the controller sets (a subset of Plant.channels); the rest stay passive
    needs: tuple[str, ...] = ()
    #: reads the sensor observations (``agents.control.plant.SENSORS``), absent with full_state=True
    sensors: bool = True
    #: the action is a function of the present observation alone (no per-episode state, every
    #: damper channel set): a residual policy on it runs under plain SB3 (agents.sb3_policy)
    memoryless: bool = False
    #: the control step it runs at in the benchmark, evaluate, tune and ride-through [s]
    #: (env kwarg ``control_dt``; None: its seat's default, :mod:`agents.control.seats`)
    control_dt: float | None = None
    #: where it runs (:data:`agents.control.seats.SEATS`: ``controller`` or ``supervisor``;
    #: None: from its channels, :func:`agents.control.seats.seat_of`)
    seat: str | None = None
    #: the env ids it is designed for (None: any with its channels), e.g. the recovery laws
    env_ids: tuple[str, ...] | None = None

    def __init__(self, plant: Plant):
        if self.sensors:
            plant.require_sensors(describe(self))
        self.plant = plant
        self.n = 0
        self.seen = np.zeros(0)
        self.t = np.zeros(0)
        self.fresh = np.zeros(0, dtype=bool)
        self.hold = np.zeros((0, 2))

    @classmethod
    def supports(cls, plant: Plant) -> bool:
        return all(c in plant.channels for c in cls.needs) and (
            cls.env_ids is None or plant.env_id in cls.env_ids)

    def reset(self, n: int, which: np.ndarray | None = None) -> None:
        """Start new episodes (all of them, or those flagged in ``which``)."""
        if which is None or self.n != n:
            self.n = n
            self.seen = np.full(n, np.nan)
            self.t = np.zeros(n)
            self.fresh = np.ones(n, dtype=bool)
            self.hold = np.zeros((n, 2))
        else:
            self.t[which] = 0.0
            self.fresh[which] = True

    def commands(self, obs: np.ndarray) -> dict[str, np.ndarray]:
        """Channel name -> value per environment (see :mod:`agents.control.plant`)."""
        return {}

    def act(self, obs: np.ndarray) -> np.ndarray:
        if "damping" in self.plant.channels and self.fresh.any():
            self.hold[self.fresh] = self.plant.damping_level(obs[self.fresh])
        self.fresh[:] = False
        with blame(self, "commands(obs)"):
            commands = self.commands(obs)
        action = self.plant.compose(len(obs), commands, self.hold, describe(self))
        self.t += self.plant.control_dt
        return action

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        """SB3-compatible: ``(actions, state)`` for one observation or a batch."""
        obs = np.asarray(observation, dtype=np.float64)
        single = obs.ndim == 1
        obs = np.atleast_2d(obs)
        t = self.plant.get(obs, "time")                # every env observes it (layout)
        with blame(self, "reset(n, which)"):
            if self.n != len(obs):
                self.reset(len(obs))
            else:
                new = self.new_episodes(t, episode_start)
                if new.any():
                    self.reset(len(obs), new)
        self.seen = t
        if self.n != len(obs) or len(self.t) != len(obs):
            raise ControllerError(f"{describe(self)}: its reset(n, which) must call "
                                  f"super().reset(n, which)")
        action = self.act(obs)
        return (action[0] if single else action), state

    def new_episodes(self, t: np.ndarray, episode_start=None) -> np.ndarray:
        """(n,) rows that start an episode: flagged in ``episode_start`` (SB3), or whose
        ``time`` observation ``t`` [s] went back (below the last one seen, or 0 after this
        episode's first action): the environment was reset without the caller saying so."""
        new = np.zeros(len(t), dtype=bool)
        if episode_start is not None:
            new |= np.asarray(episode_start, dtype=bool).reshape(-1)
        tol = 0.5 * self.plant.control_dt
        return new | (t < self.seen - tol) | ((t < tol) & (self.t > 0.0))

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"


def describe(actor) -> str:
    """How errors name a controller (class or instance) or another actor (a learned policy)."""
    cls = actor if isinstance(actor, type) else type(actor)
    if issubclass(cls, Controller):
        return f"controller {cls.name!r} ({cls.__name__})"
    return f"policy {getattr(actor, 'name', cls.__qualname__)!r}"


@contextmanager
def blame(actor, what: str):
    """Re-raise an error inside as one :class:`ControllerError` line naming ``actor`` and
    ``what`` it was doing (the original exception chained)."""
    try:
        yield
    except ControllerError:
        raise
    except Exception as exc:
        raise ControllerError(f"{describe(actor)}: {what} failed: {type(exc).__name__}: "
                              f"{exc.args[0] if len(exc.args) == 1 else exc}") from exc


class Passive(Controller):
    """No control action: the scene's own support damping, AMBs never switched back on."""

    name = "passive"
    sensors = False
    #: it commands and reads nothing, so no seat is its own: it runs at the supervisor seat's
    #: 1 ms step, so that every score is normalised by the same passive drops as before
    seat = "supervisor"


class MaxDamping(Controller):
    """Constant C_max in both housings."""

    name = "max-damping"
    needs = ("damping",)
    sensors = False
    memoryless = True

    def commands(self, obs):
        return {"damping": np.ones((len(obs), 2))}


class WhirlSwitch(Controller):
    """High damping while the orbit at a plane looks like backward whirl (see module doc).

    Per plane the backward orbit angle (against the spin) travelled beyond ``r_on`` x clearance
    is accumulated with exponential forgetting (time constant ``window``); the damping goes to
    C_max when it exceeds ``angle`` and stays there ``hold_time`` after the last detection.
    Impacts and bounces (radial motion) do not trigger it; an orbit turning backwards does.
    """

    name = "whirl-switch"
    needs = ("damping",)

    def __init__(self, plant: Plant, r_on: float = 0.6, angle: float = np.pi / 4,
                 window: float = 0.01, hold_time: float = 0.02):
        super().__init__(plant)
        self.r_on, self.angle, self.window, self.hold_time = r_on, angle, window, hold_time
        self.decay = np.exp(-plant.control_dt / window)
        self.last = np.zeros((0, 2))
        self.theta = np.zeros((0, 2))
        self.backward = np.zeros((0, 2))

    def reset(self, n, which=None):
        super().reset(n, which)
        if which is None or len(self.last) != n:
            which = np.ones(n, dtype=bool)
            self.last = np.zeros((n, 2))
            self.theta = np.zeros((n, 2))
            self.backward = np.zeros((n, 2))
        self.last[which] = -np.inf
        self.theta[which] = np.nan
        self.backward[which] = 0.0

    def commands(self, obs):
        p = self.plant
        spin = p.spin_sign(obs)[:, None]
        pos = p.positions(obs)
        x, y = pos[:, 0::2], pos[:, 1::2]                       # (n, 2): planes 1, 2
        theta = np.arctan2(y, x)
        dtheta = np.nan_to_num((theta - self.theta + np.pi) % (2 * np.pi) - np.pi)
        far = np.hypot(x, y) > self.r_on * p.clearance
        self.backward = self.decay * self.backward + np.where(far, -spin * dtheta, 0.0)
        self.theta = theta
        t = self.t[:, None]
        self.last = np.where(self.backward > self.angle, t, self.last)
        high = t - self.last <= self.hold_time
        return {"damping": np.where(high, 1.0, self.hold)}


class BuiltinRelevitate(Controller):
    """Switches the environment's built-in PID (ramped lift-off) on as soon as power is back.

    It commands "on" at every step: the environment ignores the command until power returns
    and then engages the controller at once, without reading the ``amb_power`` observation.
    """

    name = "builtin-relevitate"
    needs = ("levitate",)
    sensors = False

    def commands(self, obs):
        return {"levitate": np.ones(len(obs))}


class PidRelevitate(Controller):
    """An own PID per AMB axis on the control currents, with a lift-off reference ramped from
    the landing position to the centre, switched on as soon as power is back (spec §5)."""

    name = "pid-relevitate"
    needs = ("currents",)

    def __init__(self, plant: Plant, ramp: float | None = None):
        super().__init__(plant)
        self.ramp = plant.liftoff_ramp if ramp is None else ramp
        lim = plant.current_limit
        kp, ki, kd = plant.pid               # the scene's AMB PID gains, per A -> normalised
        self.kp, self.ki, self.kd = kp / lim, ki / lim, kd / lim
        self.ff = plant.gravity_currents
        self.on_t = np.zeros(0)
        self.start = np.zeros((0, 4))
        self.integral = np.zeros((0, 4))

    def reset(self, n, which=None):
        super().reset(n, which)
        if which is None or len(self.on_t) != n:
            self.on_t = np.full(n, np.nan)
            self.start = np.zeros((n, 4))
            self.integral = np.zeros((n, 4))
        else:
            self.on_t[which] = np.nan
            self.integral[which] = 0.0

    def commands(self, obs):
        p = self.plant
        powered = p.power_available(obs)
        pos, vel = p.positions(obs), p.velocities(obs)
        new = powered & np.isnan(self.on_t)
        self.on_t[new] = self.t[new]
        self.start[new] = pos[new]
        self.integral[new] = 0.0
        s = np.nan_to_num((self.t - self.on_t) / max(self.ramp, 1e-12), nan=0.0)
        ramping = ((s > 0.0) & (s < 1.0))[:, None]
        s = np.clip(s, 0.0, 1.0)[:, None]
        err = pos - self.start * (1.0 - s)                       # e = d - reference
        derr = vel + np.where(ramping, self.start / max(self.ramp, 1e-12), 0.0)
        raw = self.ff - (self.kp * err + self.ki * self.integral + self.kd * derr)
        windup = ((raw > 1.0) & (err < 0.0)) | ((raw < -1.0) & (err > 0.0))
        self.integral += np.where(powered[:, None] & ~windup, err * p.control_dt, 0.0)
        current = np.where(powered[:, None], np.clip(raw, -1.0, 1.0), 0.0)
        return {"currents": current}



class WhirlBrake(Controller):
    """Re-levitation that brakes a backward whirl first (continuous currents; plus C_max in the
    Full task). Per AMB plane, in normalised current (1 = the current limit) once power is back:

        u = u_g − k_p x/c − k_d v τ/c + k_c s J v τ/c + [|x| > r_on c] (k_t s J x̂ − k_r x̂)

    with x, v the sensed displacement and velocity, c the clearance, τ = 1 ms, s the spin sign,
    J the rotation by +90° (J x̂ points along forward whirl), x̂ = x/|x| and u_g the gravity
    feed-forward. The PD terms centre the rotor without a lift-off ramp; the cross-coupled
    velocity term and the forward tangential push act against the backward orbit, whose
    friction drive the magnets cannot out-pull (about 1 kN of magnet force against 10 kN of
    whirl contact force). The gains were found by cross-entropy search on a tuning set of
    frictions and unbalance phases that the benchmark does not use
    (``rotordrop research tune-whirl-brake``).
    """

    name = "whirl-brake"
    needs = ("currents",)
    memoryless = True
    GAINS = dict(kp=0.86, kd=4.88, kc=2.47, kt=0.44, kr=0.21, ff=1.10, r_on=0.5)

    def __init__(self, plant: Plant, **gains):
        super().__init__(plant)
        unknown = set(gains) - set(self.GAINS)
        if unknown:
            raise TypeError(f"unknown {self.name} gains {sorted(unknown)}; known: {sorted(self.GAINS)}")
        self.g = {**self.GAINS, **gains}

    def commands(self, obs):
        p, g = self.plant, self.g
        pos = p.positions(obs) / p.clearance
        vel = p.velocities(obs) * 1e-3 / p.clearance
        u = (g["ff"] * p.gravity_currents - g["kp"] * pos - g["kd"] * vel
             + whirl_terms(g, pos, vel, p.spin_sign(obs))[0])
        out = {"currents": np.where(p.power_available(obs)[:, None], np.clip(u, -1.0, 1.0), 0.0)}
        if "damping" in p.channels:
            out["damping"] = np.ones((len(obs), 2))
        return out


class WhirlBrakeRobust(WhirlBrake):
    """``whirl-brake`` with its gains re-tuned on the robust distribution with the sensing it
    then had (docs/agents.md "Robust suite": actuator spread, plant variation, and 2 µm sensor
    noise and 1-3 ms latency on the observation alone) by
    ``rotordrop tune --policy whirl-brake --env RotorDrop-Full-v1 --suite robust`` (20
    generations of 24, 25 min on one core). No gains in the searched ranges re-levitate under
    1-3 ms of latency: the tuned law lowers the force and displacement peaks only."""

    name = "whirl-brake-robust"
    GAINS = dict(kp=0.408, kd=3.756, kc=2.431, kt=0.150, kr=0.107, ff=0.798, r_on=0.587)


def whirl_terms(g: dict, pos: np.ndarray, vel: np.ndarray, spin: np.ndarray):
    """whirl-brake's terms against backward whirl, k_c s J v τ/c + [|x| > r_on c](k_t s J x̂ −
    k_r x̂), in normalised current per axis (x1, y1, x2, y2), and the unit radius vectors x̂;
    ``pos`` = x/c, ``vel`` = v τ/c (n, 4), ``spin`` (n,) the spin sign."""
    spin = spin[:, None]
    r = np.repeat(np.hypot(pos[:, 0::2], pos[:, 1::2]), 2, axis=1)
    unit = pos / np.maximum(r, 1e-9)
    u = g["kc"] * spin * _rot90(vel) + np.where(r > g["r_on"], g["kt"] * spin * _rot90(unit)
                                                - g["kr"] * unit, 0.0)
    return u, unit


class InnerLoop(Controller):
    """``command="supervisor"`` with constant commands: the built-in PID switched on as soon as
    power is back, C_max in the Full task, and a constant gain action ``gain`` (PID gains x
    2^(gain x the env's octaves)) and radial reference offset ``offset_r`` (clearances along the
    sensed orbit's radius, on both planes; negative pulls towards the centre), no tangential
    offset. Both are supervisor actions in [-1, 1], read by nothing before the PID is on; the
    law reads no sensor. The class defaults ``GAINS`` (both 0) are ``inner-loop``, the
    "inner loop only" row (the same trajectory as ``builtin-relevitate`` with C_max); other
    values are ``inner-loop-lift`` (:class:`InnerLoopLift`) and the oracle's ``--constant``
    rows (:func:`agents.research.oracle.constant_entry`)."""

    name = "inner-loop"
    needs = ("levitate", "offsets")
    sensors = False
    GAINS = dict(gain=0.0, offset_r=0.0)

    def __init__(self, plant: Plant, gain: float | None = None, offset_r: float | None = None):
        super().__init__(plant)
        self.gain = supervisor_action("gain", self.GAINS["gain"] if gain is None else gain)
        self.offset_r = supervisor_action("offset_r", self.GAINS["offset_r"] if offset_r is None
                                          else offset_r)

    def commands(self, obs):
        n = len(obs)
        offsets = np.zeros((n, 4))                  # radial, tangential of plane 1, then 2
        offsets[:, 0::2] = self.offset_r
        out = {"levitate": np.ones(n), "gain": np.full(n, self.gain), "offsets": offsets}
        if "damping" in self.plant.channels:
            out["damping"] = np.ones((n, 2))
        return out


def supervisor_action(name: str, value: float) -> float:
    """``value`` as a float; ValueError naming ``name`` unless it lies in [-1, 1]."""
    value = float(value)
    if not -1.0 <= value <= 1.0:
        raise ValueError(f"{name} = {value:g} must be in [-1, 1] (a supervisor action)")
    return value


class InnerLoopLift(InnerLoop):
    """``inner-loop`` with a lift assist: gain action 0.5 (PID gains x 2^0.5 = 1.41 at full
    authority) and radial reference offset -0.5 clearance on both planes, constant. The
    negative radial offset shifts the PID's reference towards the centre along the sensed
    radius, which shortens the ramped lift-off (on the robust suite it re-levitates a median
    16 ms after the power return, ``inner-loop`` 63 ms). The two constants were chosen on the robust validation set (seeds 40 000-40 019) among gain
    {0, 0.5, 1} x offset {0, -0.25, -0.5, -0.75, -1} before any test drop was scored with them
    (docs/experiments/2026-11-26-robust-oracle.md)."""

    name = "inner-loop-lift"
    GAINS = dict(gain=0.5, offset_r=-0.5)
    control_dt = 0.005      # the oracle's rollouts' step, at which the constants were chosen


class WhirlBrakeSupervisor(InnerLoop):
    """whirl-brake's whirl terms (:func:`whirl_terms`, its tuned gains) written as supervisor
    commands over the built-in PID: the term's current Δu (1 = the current limit) becomes the
    reference offset δ = Δu i_max / k_p that makes the PID add it (i = −k_p (x − x_ref) + ...),
    split into the sensed orbit's radial and tangential axes; the PID replaces whirl-brake's
    own PD and feed-forward. C_max in the Full task."""

    name = "whirl-brake-sup"
    sensors = True
    GAINS = WhirlBrake.GAINS            # its keyword arguments are whirl-brake's gains

    def __init__(self, plant: Plant, **gains):
        super().__init__(plant, gain=0.0, offset_r=0.0)
        self.g = WhirlBrake(plant, **gains).g
        self.per_offset = plant.current_limit / plant.pid[0] / plant.clearance

    def commands(self, obs):
        p = self.plant
        out = super().commands(obs)
        pos = p.positions(obs) / p.clearance
        vel = p.velocities(obs) * 1e-3 / p.clearance
        spin = p.spin_sign(obs)
        du, unit = whirl_terms(self.g, pos, vel, spin)
        tang = spin[:, None] * _rot90(unit)
        radial = (du * unit).reshape(-1, 2, 2).sum(axis=2)       # per plane
        tangential = (du * tang).reshape(-1, 2, 2).sum(axis=2)
        offsets = np.stack([radial, tangential], axis=2).reshape(-1, 4) * self.per_offset
        out["offsets"] = np.clip(offsets, -1.0, 1.0)
        return out


class ContactWatch:
    """Persistent contact, as a law sees it from its sensors: per environment the fraction of
    time the sensed orbit at either AMB plane lies beyond ``r_contact`` x clearance (the rotor
    at its retainer bearing), low-pass filtered over ``revolutions`` spin revolutions; persistent
    above ``fraction``. ``free``: the time since the orbit was last beyond it [s]."""

    def __init__(self, plant: Plant, r_contact: float, revolutions: float, fraction: float):
        self.plant, self.r_contact, self.revolutions = plant, r_contact, revolutions
        self.fraction = fraction
        self.level = np.zeros(0)
        self.free = np.zeros(0)

    def reset(self, n: int, which: np.ndarray | None) -> None:
        if which is None or len(self.level) != n:
            self.level, self.free = np.zeros(n), np.zeros(n)
        else:
            self.level[which] = self.free[which] = 0.0

    def update(self, obs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(persistent, r / clearance at the larger of the two planes) after this observation."""
        p = self.plant
        pos = p.positions(obs)
        r = np.hypot(pos[:, 0::2], pos[:, 1::2]).max(axis=1) / p.clearance
        touching = r > self.r_contact
        period = 2.0 * np.pi / np.maximum(np.abs(p.get(obs, "rotor_speed")), 1.0)
        gain = np.minimum(p.control_dt / (self.revolutions * period), 1.0)
        self.level += gain * (touching - self.level)
        self.free = np.where(touching, 0.0, self.free + p.control_dt)
        return self.level > self.fraction, r


class PhaseSearch:
    """The state machine of the synchronous laws, per environment: idle until
    :class:`ContactWatch` reports persistent contact; then active, at the phase ``phases[k]``
    (deg, in order), ``dwell`` revolutions each (cycling), until the sensed orbit has stayed
    inside ``r_contact`` for ``release`` revolutions; then idle again, the watch restarted.
    ``step(obs, t)`` -> (active, φ [rad]) per environment."""

    def __init__(self, plant: Plant, g: dict):
        self.plant, self.g = plant, g
        self.phases = np.radians(np.asarray(g["phases"], dtype=np.float64))
        self.watch = ContactWatch(plant, g["r_contact"], g["revolutions"], g["fraction"])
        self.active = np.zeros(0, dtype=bool)
        self.k = np.zeros(0, dtype=np.int64)
        self.since = np.zeros(0)

    def reset(self, n: int, which: np.ndarray | None) -> None:
        self.watch.reset(n, which)
        if which is None or len(self.active) != n:
            self.active, self.k, self.since = np.zeros(n, bool), np.zeros(n, np.int64), np.zeros(n)
        else:
            self.active[which] = False
            self.k[which] = 0

    def step(self, obs: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        g = self.g
        persistent, _ = self.watch.update(obs)
        rev = 2.0 * np.pi / np.maximum(np.abs(self.plant.get(obs, "rotor_speed")), 1.0)
        start = persistent & ~self.active
        self.k[start] = 0
        self.since[start] = t[start]
        self.active |= start
        done = self.active & (self.watch.free >= g["release"] * rev)
        self.active &= ~done
        self.watch.level[done] = 0.0
        turn = self.active & (t - self.since >= g["dwell"] * rev)
        self.k[turn] = (self.k[turn] + 1) % len(self.phases)
        self.since[turn] = t[turn]
        return self.active, self.phases[self.k]


def law_constants(law, gains: dict) -> dict:
    """``law``'s class constants ``GAINS`` updated by ``gains``; TypeError naming unknown ones."""
    unknown = set(gains) - set(law.GAINS)
    if unknown:
        raise TypeError(f"unknown {law.name} constants {sorted(unknown)}; known: "
                        f"{sorted(law.GAINS)}")
    return {**law.GAINS, **gains}


def with_constants(law: type, constants: dict, name: str | None = None) -> type:
    """``law`` as a controller class whose class constants ``GAINS`` are updated by
    ``constants`` (checked: :func:`law_constants`), named ``name`` (default the law's): a
    designed law with tuned or searched constants, run wherever a controller class runs."""
    gains = law_constants(law, constants) if constants else dict(getattr(law, "GAINS", {}))
    return type(law.__name__, (law,), {"GAINS": gains, "name": name or law.name})


#: the tasks the recovery laws are designed for (their contact watch assumes the AMBs on)
RECOVERY_TASKS = ("RotorDrop-Recover-v1",)
#: the synchronous laws' watch and search constants (revolutions, fractions of the clearance).
#: The watch's ``fraction`` and ``revolutions`` were chosen on the ``recover`` suite's
#: validation events (seeds 61 000-61 059) between (0.2, 4) and (0.6, 8) with
#: ``sync-phase-search`` and ``sync-motion-comp``: the eager watch acts on contacts the PID
#: ends by itself and recovers fewer events (0.10 and 0.08 against 0.23 and 0.10)
SEARCH = dict(dwell=4.0, release=6.0, r_contact=0.8, revolutions=8.0, fraction=0.6,
              phases=(180.0, 225.0, 270.0, 315.0, 0.0, 45.0, 90.0, 135.0))


class Searching:
    """Mixin of the synchronous laws: their constants (``GAINS`` updated by the keyword
    arguments) and their :class:`PhaseSearch`, reset with the episodes."""

    def start_search(self, plant: Plant, gains: dict) -> None:
        self.g = law_constants(self, gains)
        self.search = PhaseSearch(plant, self.g)

    def reset(self, n, which=None):
        super().reset(n, which)
        self.search.reset(n, which)


class SyncPhaseSearch(Searching, InnerLoop):
    """Synchronous compensation with a phase search (supervisor seat, over the built-in PID).

    On persistent contact (:class:`ContactWatch`: the sensed orbit beyond ``r_contact`` x
    clearance for more than ``fraction`` of the last ``revolutions`` revolutions) it commands a
    reference offset of amplitude ``amplitude`` x clearance at the angle φ from the sensed
    orbit's radius (along the forward orbit for φ = 90°), on both AMB planes. The offset is
    evaluated continuously inside the physics step in the frame of the sensed orbit, so for a
    synchronous orbit it is a synchronous, spin-locked reference of phase φ relative to the
    displacement, whatever the supervisor's step. The phase is searched over ``phases`` (deg,
    in order), ``dwell`` revolutions each, until the orbit has stayed inside ``r_contact`` for
    ``release`` revolutions; then the offset is removed and the watch starts again
    (:class:`PhaseSearch`). φ = 180° first: a pure pull towards the centre (a stiffer
    synchronous suspension). The watch's constants were chosen on validation events
    (:data:`SEARCH`); the others are set by reasoning and a few trial runs."""

    name = "sync-phase-search"
    sensors = True
    env_ids = RECOVERY_TASKS
    GAINS = dict(SEARCH, amplitude=0.25)

    def __init__(self, plant: Plant, **gains):
        super().__init__(plant, gain=0.0, offset_r=0.0)
        self.start_search(plant, gains)
        supervisor_action("amplitude", self.g.get("amplitude", 0.0))

    def commands(self, obs):
        out = super().commands(obs)
        active, phi = self.search.step(obs, self.t)
        out["offsets"] = self.offsets(obs, active, phi)
        return out

    def offsets(self, obs, active: np.ndarray, phi: np.ndarray) -> np.ndarray:
        """(n, 4) offsets of amplitude A at angle ``phi`` from the orbit radius where
        ``active`` (radial, tangential of plane 1, then 2)."""
        a = np.where(active, self.g["amplitude"], 0.0)
        per_plane = np.stack([a * np.cos(phi), a * np.sin(phi)], axis=1)
        return np.tile(per_plane, 2)


class SyncCurrentSearch(Searching, PidRelevitate):
    """Synchronous current compensation with a phase search (controller seat, raw currents):
    the own PID of ``pid-relevitate`` plus, on persistent contact (:class:`PhaseSearch`), a
    current of ``amplitude`` x the current limit on each AMB plane along the sensed
    displacement turned by φ (φ = 180°: towards the centre; 90°: along the forward orbit).
    Sampled at the controller's 0.1-0.2 ms step it is a spin-locked synchronous force of phase
    φ relative to the displacement of a synchronous orbit, which the magnets apply whatever
    their PID's saturation. The watch's constants are the supervisor laws' (:data:`SEARCH`);
    ``amplitude`` and the phases are set by reasoning and a few trial runs (untuned)."""

    name = "sync-current-search"
    env_ids = RECOVERY_TASKS
    GAINS = dict(SEARCH, amplitude=0.6)

    def __init__(self, plant: Plant, **gains):
        super().__init__(plant)
        self.start_search(plant, gains)

    def commands(self, obs):
        out = super().commands(obs)
        active, phi = self.search.step(obs, self.t)
        pos = self.plant.positions(obs)
        r = np.repeat(np.hypot(pos[:, 0::2], pos[:, 1::2]), 2, axis=1)
        unit = pos / np.maximum(r, 1e-12)
        c, s = np.cos(phi)[:, None], np.sin(phi)[:, None]
        spin = self.plant.spin_sign(obs)[:, None]
        turned = c * unit + s * spin * _rot90(unit)
        extra = np.where(active[:, None], self.g["amplitude"] * turned, 0.0)
        out["currents"] = np.clip(out["currents"] + extra, -1.0, 1.0)
        return out


class SyncMotionCompensation(SyncPhaseSearch):
    """Synchronous motion compensation (supervisor seat, over the built-in PID): on persistent
    contact (as ``sync-phase-search``) a reference offset against the sensed synchronous orbit
    on each AMB plane, proportional to it: radial offset −``gain`` x r / clearance (clipped to
    the supervisor's range), so that the PID's synchronous force grows with the orbit it has to
    pull back into the clearance, plus the tangential offset ``lead`` x that (its phase lead
    against the contact's friction drive). It is removed once the orbit has stayed inside
    ``r_contact`` for ``release`` revolutions. The watch's ``fraction`` and ``revolutions`` as
    chosen on validation events (:data:`SEARCH`); ``gain`` and ``r_contact`` set by reasoning."""

    name = "sync-motion-comp"
    GAINS = dict(SEARCH, gain=0.3, r_contact=0.7, lead=0.0, phases=(180.0,))

    def offsets(self, obs, active, phi):
        p = self.plant
        pos = p.positions(obs) / p.clearance
        r = np.hypot(pos[:, 0::2], pos[:, 1::2])                # (n, 2) per plane
        radial = np.clip(-self.g["gain"] * r, -1.0, 0.0)
        tang = np.clip(-self.g["lead"] * radial, -1.0, 1.0)
        out = np.stack([radial, tang], axis=2).reshape(-1, 4)
        return np.where(active[:, None], out, 0.0)


_ROT90 = np.array([-1.0, 1.0, -1.0, 1.0])


def _rot90(v: np.ndarray) -> np.ndarray:
    """(x1, y1, x2, y2) rows rotated by +90° in each plane."""
    return v[:, [1, 0, 3, 2]] * _ROT90


BASELINES: dict[str, type[Controller]] = {c.name: c for c in (
    Passive, MaxDamping, WhirlSwitch, PidRelevitate, BuiltinRelevitate, WhirlBrake, InnerLoop,
    InnerLoopLift, WhirlBrakeSupervisor, WhirlBrakeRobust, SyncPhaseSearch,
    SyncMotionCompensation, SyncCurrentSearch)}


def command_for(cls: type[Controller]) -> str | None:
    """The re-levitation command (env kwarg ``command``) a controller's channels need:
    ``continuous`` for ``currents``, ``supervisor`` for ``gain`` or ``offsets``, ``discrete``
    for ``levitate``, None otherwise."""
    if "currents" in cls.needs:
        return "continuous"
    if {"gain", "offsets"} & set(cls.needs):
        return "supervisor"
    return "discrete" if "levitate" in cls.needs else None


def controller_env_kwargs(cls, env_id: str) -> dict:
    """The env kwargs a controller class needs in ``env_id``: the re-levitation command of its
    channels (``controllers.command_for``) in the re-levitation environments (the passive
    reference keeps the AMBs off), and the control step of its seat
    (:func:`agents.control.seats.seat_of`: its own ``control_dt``, checked against the seat's
    range, else the seat's default)."""
    from .seats import seat_of
    command = command_for(cls)
    kw = {"command": command} if command and task_flags(env_id)[1] else {}
    kw.update(seat_of(cls).env_kwargs(getattr(cls, "control_dt", None)))
    return kw


def is_controller_spec(spec: str) -> bool:
    """``module:Class`` or ``file.py:Class`` (a user's controller), not a path on disk."""
    from pathlib import Path
    return ":" in spec and not Path(spec).exists()


def load_controller(spec: str) -> type[Controller]:
    """A user's controller class from ``package.module:Class`` (importable, or in the current
    directory) or ``path/to/file.py:Class``.

    It must subclass :class:`Controller` (set ``name`` and ``needs``, return channel values
    from ``commands(obs)``); the benchmark, ``evaluate`` and ``ride-through`` then treat it
    like a baseline."""
    import importlib
    import importlib.util
    import sys
    from pathlib import Path
    target, _, attr = spec.rpartition(":")
    if not target or not attr.isidentifier():
        raise ValueError(f"controller {spec!r}: expected package.module:Class or file.py:Class")
    try:
        if target.endswith(".py"):
            path = Path(target)
            if not path.is_file():
                raise FileNotFoundError(f"controller {spec!r}: no file {path}")
            folder = str(path.resolve().parent)  # its sibling modules import, as `python file.py`
            if folder not in sys.path:
                sys.path.insert(0, folder)
            module_spec = importlib.util.spec_from_file_location(f"rotordrop_user_{path.stem}", path)
            module = importlib.util.module_from_spec(module_spec)
            sys.modules[module_spec.name] = module      # as an import would (dataclasses need it)
            try:
                module_spec.loader.exec_module(module)
            except BaseException:
                del sys.modules[module_spec.name]
                raise
        else:
            cwd = str(Path.cwd())               # modules next to the user, as python -m finds them
            sys.path.insert(0, cwd)
            try:
                module = importlib.import_module(target)
            finally:
                sys.path.remove(cwd)
    except (ImportError, SyntaxError) as exc:
        raise ValueError(f"controller {spec!r}: cannot import {target!r} "
                         f"({type(exc).__name__}: {exc})") from None
    if not hasattr(module, attr):
        raise ValueError(f"controller {spec!r}: {target} has no {attr!r}")
    cls = getattr(module, attr)
    if not (isinstance(cls, type) and issubclass(cls, Controller)):
        raise ValueError(f"controller {spec!r}: {attr!r} in {target} is not a subclass of "
                         f"agents.control.controllers.Controller")
    if cls.name in BASELINES:
        raise ValueError(f"controller {spec!r}: its name {cls.name!r} is a baseline's; give it its own")
    return cls


def controller_class(spec: str) -> type[Controller] | None:
    """The controller class of a baseline name or a ``module:Class`` spec; None for anything
    else (a learned policy)."""
    if spec in BASELINES:
        return BASELINES[spec]
    return load_controller(spec) if is_controller_spec(spec) else None


def make_controller(cls: type[Controller], plant: Plant) -> Controller:
    """``cls(plant)`` after checking that the environment has the channels it needs; an error
    in the constructor (say an argument without default) is a :class:`ControllerError`."""
    if not cls.supports(plant):
        where = "" if cls.env_ids is None else f" in {', '.join(cls.env_ids)}"
        raise ValueError(f"controller {cls.name!r} needs action channels {cls.needs}{where}, "
                         f"which {plant.env_id} does not have (it has "
                         f"{', '.join(plant.channels)})")
    with blame(cls, f"{cls.__name__}(plant)"):
        return cls(plant)


def check_controller(actor, plant: Plant, obs: np.ndarray) -> None:
    """Fail fast before long work: ``actor.predict`` (a controller or a learned policy) on one
    raw observation ``obs`` of the plant's environment, alone and as a batch of two new
    episodes; anything wrong raises :class:`ControllerError` naming the actor."""
    obs = np.asarray(obs)
    if obs.shape != (len(plant.obs_names),):
        raise ValueError(f"check_controller: obs has shape {obs.shape}, {plant.env_id} "
                         f"observes ({len(plant.obs_names)},)")
    shape = () if plant.discrete else (len(plant.action_names),)
    for batch in (obs, np.stack([obs, obs])):
        n = 1 if batch.ndim == 1 else len(batch)
        with blame(actor, "predict(obs)"):
            action, _ = actor.predict(batch, episode_start=np.ones(n, dtype=bool))
        want = shape if batch.ndim == 1 else (n, *shape)
        if np.shape(action) != want:
            raise ControllerError(f"{describe(actor)}: predict returned actions of shape "
                                  f"{np.shape(action)} for {plant.env_id}, expected {want}")


def baseline_name(spec) -> str:
    """The law of a baseline ``spec``: a baseline's name, or ``{"law": name, "gains": {...}}``
    (that law with those constants, e.g. the ones tuned on a suite: what a residual policy
    corrects when it names them). ValueError naming the allowed forms otherwise."""
    if isinstance(spec, dict):
        if set(spec) != {"law", "gains"} or not isinstance(spec["gains"], dict):
            raise ValueError(f"a baseline with constants is {{'law': NAME, 'gains': {{...}}}}, "
                             f"got {spec!r}")
        name = spec["law"]
    else:
        name = spec
    if name not in BASELINES:
        raise ValueError(f"unknown baseline controller {name!r}; known: {', '.join(BASELINES)}")
    return name


def make_baseline(spec, plant: Plant) -> Controller:
    """The baseline ``spec`` (:func:`baseline_name`) on ``plant``: a name with its class
    constants, or a law with the given ones (each named by the class and finite)."""
    cls = BASELINES[baseline_name(spec)]
    if not isinstance(spec, dict):
        return make_controller(cls, plant)
    for k, v in spec["gains"].items():
        if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
            raise ValueError(f"{cls.name} constant {k} must be a finite number, got {v!r}")
    try:
        law = with_constants(cls, spec["gains"])
    except (TypeError, AttributeError) as exc:          # unknown constants, or a law without
        raise ValueError(f"{cls.name}: {exc}") from None
    return make_controller(law, plant)
