"""Gymnasium environments of the AMB rotor drop (spec §5-6): :class:`RotorDropEnv`, one class
that runs any task (:mod:`rotordrop_env.tasks`), and the shipped tasks' classes: passive,
semi-active support damping, AMB re-levitation, and both together. See docs/environments.md for
the full tables.

The pieces an environment is made of, each in its module: the task declaration
(:mod:`.tasks`), the command interfaces and their settings (:mod:`.commands`), the observation
and action layout (:mod:`.layout`) and sensing (:mod:`.sensors`), the reward
(:mod:`.reward`), the episode constraints (:mod:`.constraints`), the scenario draw
(:mod:`.scenario`), the ``info`` and KPIs (:mod:`.info`), the kwarg checks (:mod:`.settings`),
the episode view (:mod:`.view`) and the step kernels (:mod:`.kernels`).
"""
from __future__ import annotations

import math
from typing import Callable, NamedTuple

import gymnasium as gym
import numpy as np

from physics.amb import static_weight_share
from physics.ball_bearing import max_contact_pressure
from physics.jit import bound
from physics.metrics import WHIRL_MIN_REVOLUTIONS, WHIRL_RADIUS_FRACTION
from physics.scene import Scene, SceneError
from physics.simulate import IntegrationError, explain_status

from . import constraints as constraints_
from . import kernels as K
from .buffers import Buffers
from .commands import (DAMPING_ACTIONS, DEFAULT_POWER_RETURN, LEV_CODES,  # noqa: F401 (re-exported)
                       SUPERVISOR_OCTAVES, SUPERVISOR_OFFSET, Commands, action_error, load_action,
                       real_action, supervisor_scales)
from .info import MISSING, REWARD_TERMS, StepInfo, kpi_keys  # noqa: F401 (REWARD_TERMS re-exported)
from .layout import observation_layout
from .reward import Reward, make_reward
from .scenario import (POWER_RETURN, POWER_RETURN_LIMITS, fault_state, layout_base, reset_options,
                       resolve_ranges, sample, scenario_report, scenario_scene)
from .sensors import Sensing, check_delay, check_latency, check_noise, check_sample_rate
from .settings import (FIXED_SETTINGS, WEIGHT_SLOTS, SettingsGuard, check_choice,  # noqa: F401
                       check_flag, check_real, check_steps, check_unused_ranges, check_weights,
                       make_scene, sensing_scene)
from .events import EventRanges
from .tasks import DAMPING, FULL, PASSIVE, RECOVER, RELEVITATE, Task, resolve_task
from .view import EpisodeView


class RotorDropEnv(SettingsGuard, EpisodeView, gym.Env):
    """The rotor-drop environment of a task (MuJoCo-v5 style): the class of a shipped task
    (:class:`PassiveEnv`...), or ``RotorDropEnv(task=Task(...))`` for any other
    (:mod:`rotordrop_env.tasks`).

    An episode starts at the AMB fault from the cached levitated state of the scene and runs
    ``episode_time`` seconds in control steps of ``control_dt``. The physics is the full drop
    model of :mod:`physics` (adaptive Dormand-Prince between control steps).

    Constructor keyword arguments (all pass through ``gym.make(id, **kwargs)``)
    --------------------------------------------------------------------------
    ==========================  ==========  ====================================================
    kwarg                       default     meaning
    ==========================  ==========  ====================================================
    scene                       "paper"     preset name, TOML path or :class:`physics.Scene`
    overrides                   None        dict of dotted scene keys, e.g. {"contact.friction": 0.4}
    control_dt                  1e-3        control step [s] (``env.dt``)
    episode_time                0.3         episode length after the fault [s] (time limit)
    randomize                   False       draw a scenario at every reset (the task's ranges);
                                            keys fixed by the user (``overrides``, the
                                            ``power_return_time`` kwarg, a None range) keep
                                            their value
    randomization               None        {key: (low, high) | (law, low, high) | None};
                                            needs randomize=True, no range for a fixed key
    full_state                  False       observe the whole state vector (research)
    sensor_noise                0.0         std of the displacement sensors' Gaussian noise [m]
                                            per sensor sample (:mod:`rotordrop_env.sensors`)
    sensor_sample_rate          None        the sensors' sample rate [Hz] in [1e3, 1e5]: one
                                            noise sample per axis at t = k / rate, held until
                                            the next (None: the scene's sensor.sample_rate,
                                            10 kHz by default)
    sensor_delay                0.0         delay of the displacement sensors [s] (in the physics:
                                            the PID, the supervisor and the observations see it)
    obs_latency_steps           0           k or (low, high): the agent sees the measurement of
                                            k control steps ago, k drawn per episode
    command                     task's      AMB tasks: "discrete", "continuous" or "supervisor"
    supervisor_authority        1.0         command="supervisor": a in (0, 1] scales the offset
                                            range (a x clearance) and the gain scale (2^-a...2^a)
    damping_action              "linear"    damper tasks: map of the damper action a to the
                                            damping, "linear" (-1 C_min, 0 mid-range, +1 C_max)
                                            or "from_max" (a >= 0 C_max, linear to C_min at -1:
                                            the zero action is full damping)
    power_return_time           task's      AMB tasks: power returns [s after fault] (0.05)
    samples_per_step            5           monitor samples per control step (dense output)
    relevitation_hold           task's      re-levitated (recovered) after this long in the
                                            success region [s] (0.02; Recover: 0.05)
    events                      task's      Recover: the event distribution, a dict of the
                                            :class:`rotordrop_env.events.EventRanges` fields
                                            to change (e.g. {"kinds": ("shock",)})
    constraints                 task's      the episode constraints that end an episode (names
                                            or objects of :mod:`rotordrop_env.constraints`; all
                                            three by default)
    terminate_on_failure        True        False: no constraint ends an episode
    reward                      task's      "default" (the terms below), "kpi" (the KPI reward
                                            of :mod:`rotordrop_env.reward`) or a ``Reward``
    reward_kwargs               None        reward="kpi": its weights (``KPI_WEIGHTS``)
    w_whirl, w_contact,         10, 0.1,    weights of the reward terms (``TermReward``)
    w_displacement, w_effort,   0.1, 0.01,
    w_success, w_failure        10, 10
    render_mode                 None        "rgb_array" or "human"
    task                        the class'  the :class:`Task` to run (``RotorDropEnv``: passive)
    ==========================  ==========  ====================================================

    ``info`` (see :mod:`rotordrop_env.info`): the same keys at reset and at every step, numpy
    values, no NaN; the reward terms, ``cost`` (Safety-Gymnasium convention) and its
    components, and the episode's ``kpi_*`` so far. The scenario of the episode is
    ``env.unwrapped.scenario``.

    The reward terms: :class:`rotordrop_env.reward.TermReward`. Episode end: ``terminated``
    when one of the episode's ``constraints`` is violated (:mod:`rotordrop_env.constraints`),
    ``truncated`` only at the time limit.
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 30}
    fixed_settings = FIXED_SETTINGS
    task: Task | None = None                # a shipped task's class names its task

    def __init__(self, scene: str | Scene = "paper", overrides: dict | None = None,
                 control_dt: float = 1e-3, episode_time: float = 0.3, randomize: bool = False,
                 randomization: dict | None = None, full_state: bool = False,
                 command: str | None = None, power_return_time: float | None = None,
                 samples_per_step: int = 5, relevitation_hold: float | None = None,
                 terminate_on_failure: bool = True, sensor_noise: float = 0.0,
                 obs_latency_steps: int | tuple[int, int] = 0, sensor_delay: float = 0.0,
                 sensor_sample_rate: float | None = None,
                 w_whirl: float = 10.0,
                 w_contact: float = 0.1, w_displacement: float = 0.1, w_effort: float = 0.01,
                 w_success: float = 10.0, w_failure: float = 10.0, render_mode: str | None = None,
                 supervisor_authority: float = 1.0, damping_action: str = "linear",
                 reward: str | Reward | None = None, reward_kwargs: dict | None = None,
                 constraints=None, task: Task | None = None, events: dict | None = None):
        self.task = task = resolve_task(type(self), task)
        name = type(self).__name__ if self.task is type(self).task else f"{task.name} task"
        self.events = check_events(task, name, events, power_return_time)
        if relevitation_hold is None:
            relevitation_hold = task.relevitation_hold
        self.commands = Commands.of(task.commands, name, command, damping_action,
                                    supervisor_authority, power_return_time, task.command,
                                    task.power_return_time)
        self.render_mode = check_choice("render_mode", render_mode, self.metadata["render_modes"])
        self.reward_function = make_reward(task.reward if reward is None else reward, reward_kwargs)
        self.reward, self.reward_kwargs = self.reward_function.name, dict(reward_kwargs or {})
        terminate = check_flag("terminate_on_failure", terminate_on_failure)
        self.constraints = constraints_.resolve_constraints(constraints, terminate, task.constraints)
        check_steps(control_dt, episode_time, relevitation_hold, samples_per_step)
        self.weights = check_weights(dict(
            w_whirl=w_whirl, w_contact=w_contact, w_displacement=w_displacement,
            w_effort=w_effort, w_success=w_success, w_failure=w_failure))
        self._damping, self._relevitate = self.commands.damper, self.commands.amb
        c = self.commands
        self.command, self.power_return_time = c.command, c.power_return_time
        self.supervisor_authority, self.damping_action = c.supervisor_authority, c.damping_action
        self.control_dt = self.dt = float(control_dt)
        self.n_steps = int(math.ceil(episode_time / control_dt - 1e-9))
        self.episode_time = self.n_steps * self.dt
        self.randomize = check_flag("randomize", randomize)
        self.full_state = check_flag("full_state", full_state)
        noise, delay = check_noise(sensor_noise), check_delay(sensor_delay)
        rate = check_sample_rate(sensor_sample_rate)
        self.obs_latency_steps = check_latency(obs_latency_steps)
        self._make_scenes(name, scene, overrides, (noise, delay, rate), randomization,
                          power_return_time)
        self._make_spaces()
        self._bind(Buffers(self.model.n_state, len(self.obs_names), self._n_act,
                           int(samples_per_step), self.model.sizes,
                           n_noise=self._sensing.n_noise))
        self._configure_static(relevitation_hold)
        self._values = np.zeros(K.N_V)          # the info numbers (rotordrop_env.info)
        self._step_info = StepInfo(self._relevitate)
        self._scenario: dict = {}
        self._needs_reset = True
        self._closed = self._warned = False     # _warned: a step after the end was warned about
        self._ended = False                 # the episode has ended (until the next reset)
        self._made = True                   # from here on FIXED_SETTINGS cannot be assigned

    # ------------------------------------------------------------------------- set-up --
    def _make_scenes(self, name, scene, overrides, sensing, randomization, power_return_time):
        """The base scene (the task's and its interfaces' keys, the ``sensing`` kwargs (noise,
        delay, sample rate)), the scenario ranges and the keys the user fixed, and the model of
        the fault state."""
        base = self.commands.scene(make_scene(scene, overrides), overrides, name, self.task.scene)
        base, self.sensor_noise, self.sensor_delay, self.sensor_sample_rate = \
            sensing_scene(base, *sensing)
        self.ranges, fixed = resolve_ranges(randomization, self._relevitate, name,
                                            self.task.randomization)
        check_unused_ranges(randomization, self.randomize, overrides, power_return_time)
        self.base_scene = layout_base(base, self.ranges, fixed) if self.randomize else base
        #: keys the user fixed: never randomised (still drawn, so the others' draws stay put)
        self.fixed_keys = fixed | frozenset(overrides or {}) | frozenset(
            [POWER_RETURN] if power_return_time is not None else [])
        self.scene = self.base_scene
        self.model = fault_state(self.base_scene).model

    def _make_spaces(self) -> None:
        """Observation (names, scales, Box) and action (space, names) of the task."""
        self.obs_names, self.obs_scale = observation_layout(
            self.model, self._damping, self._relevitate, self.full_state, self.episode_time,
            self.command)
        self.action_space, self.action_names = self.commands.action_layout()
        self.observation_space = gym.spaces.Box(-np.inf, np.inf, shape=(len(self.obs_names),),
                                                dtype=np.float32)
        self._discrete = isinstance(self.action_space, gym.spaces.Discrete)
        self._n_act = 1 if self._discrete else self.action_space.shape[0]
        self._sensing = Sensing(self.sensor_noise, self.obs_latency_steps, self.obs_names,
                                self.obs_scale, self.base_scene.contact.clearance,
                                self.model.control_index("sensor.noise"),
                                self.sensor_sample_rate, self.dt)

    def _bind(self, buffers: Buffers) -> None:
        """Use these arrays (own ones, or a row of a batched VecEnv's stack) from the next reset."""
        old = getattr(self, "_b", None)
        if old is not None:
            for name in ("C", "scale"):
                getattr(buffers, name)[...] = getattr(old, name)
        self._use(buffers)
        self._needs_reset = True

    def _use(self, buffers: Buffers) -> None:
        """Step on these arrays as they are (a copied batch re-attaching its rows)."""
        self._b = buffers
        self._args = buffers.args()
        self._calls = None                  # the compiled calls bound to them, at first use

    def _bind_calls(self) -> "_Calls":
        """The compiled calls of a step, bound to this environment's arrays
        (:func:`physics.jit.bound`: no per-call dispatch; made again after a copy or a rebind)."""
        b = self._b
        self._calls = _Calls(bound(K.step_one, *self._args), bound(K.check_action, b.act, b.C),
                             bound(K.info_values, b.out, b.M, b.C, self._values),
                             self._sensing.measurer(b.obs, b.Z, b.U),
                             self._sensing.drawer(b.M, b.Z))
        return self._calls

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        state["_calls"] = None              # bound machine code does not pickle: bound again
        return state

    def _configure_static(self, hold: float) -> None:
        """The kernel configuration fixed at construction: command modes, weights, monitors."""
        b = self._b
        C = b.C
        C[K.C_DT] = self.dt
        self.commands.configure(C, self.base_scene)
        C[K.C_WHIRL_RADIUS], C[K.C_WHIRL_REVS] = WHIRL_RADIUS_FRACTION, WHIRL_MIN_REVOLUTIONS
        for name, slot in WEIGHT_SLOTS.items():
            C[slot] = self.weights[name]
        C[K.C_HOLD] = hold
        C[K.C_UNLATCHED] = 0.0 if self.task.latched else 1.0
        C[K.C_FULL] = 1.0 if self.full_state else 0.0
        b.scale[:] = self.obs_scale

    # ------------------------------------------------------------------------ episode --
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        self._check_open("reset")
        super().reset(seed=seed)
        values = sample(self.ranges, self.np_random, self.fixed_keys) if self.randomize else {}
        event = self._draw_event(values)
        values.update(reset_options(options, self._relevitate))
        scene = scenario_scene(self.base_scene, values)
        fs = fault_state(scene)
        b = self._b
        if fs.model.n_state != b.y.shape[-1]:
            raise SceneError(f"scenario {values} changes the state layout ({fs.model.n_state} "
                             f"states instead of {b.y.shape[-1]}): keep effect-switching values "
                             "(e.g. unbalance.mass = 0) out of the randomisation ranges")
        self.scene, self.model = scene, fs.model
        pr = values.get(POWER_RETURN, self.power_return_time)
        if pr is not None:
            check_real(POWER_RETURN, pr, *POWER_RETURN_LIMITS)
        start_episode(b, fs, self.n_steps, self.dt, pr, self.constraints, self.task.amb_on,
                      self.task.success_radius)
        self._scenario = scenario_report(self.ranges, values, scene, b.C[K.C_T_POWER]
                                         - b.C[K.C_T_FAULT] if pr is not None else None)
        self._scenario.update(event)
        self._needs_reset = False
        self._ended = self._warned = False
        if self.render_mode is not None:            # record from the first step of the episode
            self._reset_view()
            self._record(step=False)
        if self._sensing.active:
            obs = self._sensing.reset(b.obs, self.np_random, b.U)
        else:
            obs = b.obs.astype(np.float32)
        return obs, self._info()

    def _draw_event(self, values: dict) -> dict:
        """The task's event (:mod:`rotordrop_env.events`), its scene keys added to ``values``;
        the report's ``event`` and ``event_time`` (after the episode start) [s]. Drawn after the
        machine, so that the machine's draws do not depend on the event's."""
        if self.events is None:
            return {}
        radius = scenario_scene(self.base_scene, values).unbalance.radius
        ev = self.events.draw(self.np_random, fault_state(self.base_scene).t_fault, self.dt,
                              radius)
        values.update(ev.pop("keys"))
        return ev

    @property
    def scenario(self) -> dict:
        """The machine of the current episode (a copy): every randomisation key's value (drawn,
        fixed by the user, or the scene's without ``randomize``), every key fixed by ``reset``
        options, and ``power_return_time`` as applied (re-levitation environments)."""
        return dict(self._scenario)

    def step(self, action):
        if self._needs_reset or self._ended:
            self._check_steppable()
        calls = self._calls or self._bind_calls()
        load_action(action, self._b.act, self.action_space, self.action_names)
        if calls.draw is not None:              # the sensor noise (rotordrop_env.sensors)
            err = calls.check()                 # a refused action draws none (as in a batch)
            if err:
                self._action_error(err, action)
            calls.draw(self.np_random)
        calls.step()
        return self._finish(action)

    def draw_noise(self) -> None:
        """Before a kernel step (its action checked): the sensor noise samples inside it and
        the measurement's after it (:meth:`rotordrop_env.sensors.Sensing.draw_step`)."""
        if self._sensing.noise > 0.0:
            (self._calls or self._bind_calls()).draw(self.np_random)

    def _check_open(self, what: str) -> None:
        if self._closed:
            raise gym.error.ClosedEnvironmentError(f"{what}() on a closed environment: make a "
                                                   "new one (gym.make)")

    def _check_steppable(self) -> None:
        """Before a step that needs a look: closed (raise), not reset (raise), or after the
        episode's end (warn once, as Gymnasium's own environments do; the step then runs)."""
        self._check_open("step")
        if self._needs_reset:
            raise gym.error.ResetNeeded("call reset() before step() (and after a batched VecEnv "
                                        "took over this environment's arrays)")
        if not self._warned:
            gym.logger.warn("You are calling 'step()' even though this environment has already "
                            "returned terminated = True or truncated = True. You should always "
                            "call 'reset()' once you receive 'terminated = True' or 'truncated = "
                            "True' -- any further steps are undefined behavior.")
            self._warned = True

    def _finish(self, action):
        """Turn the kernel's outputs into Gymnasium's (obs, reward, terminated, truncated, info)."""
        b = self._b
        out = b.out.tolist()                # Python floats: one conversion for every flag
        if out[K.O_ERR]:
            self._action_error(int(out[K.O_ERR]), action)
        if out[K.O_STATUS]:
            raise IntegrationError(explain_status(int(out[K.O_STATUS]), b.M[K.M_T], b.M[K.M_H], self.model))
        terminated = bool(out[K.O_TERM])
        truncated = bool(out[K.O_TRUNC])
        if terminated or truncated:         # (assigned only then: attributes go through
            self._ended = True              # SettingsGuard's checks)
        reward = self.reward_function.one(b.out, b.M, b.C, self._relevitate)
        info = self._info()
        self._show_step()
        return self.observed(), reward, terminated, truncated, info

    def observed(self) -> np.ndarray:
        """The float32 observation the agent gets after the step just taken: the kernel's, or
        with ``sensor_noise`` / ``obs_latency_steps`` the sensed one (:mod:`.sensors`; call
        once per step, it takes the measurement)."""
        if not self._sensing.active:
            return self._b.obs.astype(np.float32)
        measure = (self._calls or self._bind_calls()).measure
        if measure is None:                     # the supervisor's orbit entries
            return self._sensing.step(self._b.obs, self.np_random, self._b.U)
        return measure(self.np_random)

    def _action_error(self, err: int, action) -> None:
        """Raise the ValueError of a refused action (``err``: the kernel's ERR_* code)."""
        raise action_error(err, action, self.action_space, self.action_names)

    def _info(self) -> dict:
        """The ``info`` of the reset or step just taken (:mod:`rotordrop_env.info`)."""
        (self._calls or self._bind_calls()).info()
        return self._step_info(self._values, self._sensing.k)

    def kpis(self) -> dict:
        """Episode KPIs so far (numpy scalars; every step's ``info`` carries them, the final
        step's are the episode's)."""
        return kpi_keys(self._info())

    def close(self):
        """Release the view; afterwards reset(), step() and render() raise
        ``gymnasium.error.ClosedEnvironmentError`` (closing twice is fine)."""
        self._close_view()
        self._closed = self._needs_reset = True

    @property
    def time(self) -> float:
        """Time since the fault [s]."""
        return float(self._b.M[K.M_T] - self._b.C[K.C_T_FAULT])

    @property
    def state(self) -> np.ndarray:
        """A copy of the physical state vector (names: ``env.unwrapped.model.names``)."""
        return self._b.y.copy()


class _Calls(NamedTuple):
    """The compiled calls of one environment's step on its arrays (:meth:`RotorDropEnv._bind_calls`):
    the kernel step, the action check, the info numbers, the measurement (None: the Python one)
    and the noise draws before a step (None without noise)."""
    step: Callable[[], None]
    check: Callable[[], int]
    info: Callable[[], None]
    measure: Callable[[np.random.Generator], np.ndarray] | None
    draw: Callable[[np.random.Generator], None] | None


def start_episode(b: Buffers, fs, n_steps: int, dt: float, power_return: float | None,
                  constraints: tuple, amb_on: bool = False, success_radius: float = 0.5) -> None:
    """The kernel arrays ``b`` at the fault of the fault state ``fs``: the episode's constants
    (the solver settings are the fault state's integrator's, so the episode continues exactly
    as ``rotordrop drop`` would; the ``constraints`` that end it), its state, controls and
    monitor, and the reset observation. ``amb_on``: no fault, the AMBs stay powered and the
    built-in PID keeps levitating (its states and reference continue from the levitated run);
    ``success_radius``: the success region's radius / clearance."""
    scene, integ = fs.scene, fs.integrator
    C = b.C
    t_fault = fs.t_fault
    C[K.C_T_FAULT] = t_fault
    C[K.C_T_END] = t_fault + n_steps * dt
    if power_return is None:
        C[K.C_T_POWER] = math.inf
    else:                                   # on the control-step grid (documented)
        C[K.C_T_POWER] = t_fault + math.ceil(power_return / dt - 1e-9) * dt
    C[K.C_RTOL], C[K.C_HMAX], C[K.C_HMIN] = integ.rtol, integ.h_max, integ.h_min
    C[K.C_FIXED] = 1.0 if integ.fixed else 0.0
    C[K.C_MAXSTEPS] = integ.max_steps
    b.atol[:] = integ.atol
    C[K.C_F_REF] = static_weight_share(scene)
    C[K.C_CS_MIN], C[K.C_CS_MAX] = scene.support.damping_min, scene.support.damping_max
    C[K.C_ILIM] = scene.amb.current_limit
    C[K.C_RELEV_RADIUS] = success_radius * scene.contact.clearance
    C[K.C_P_COEF] = pressure_coef(fs.model, scene)
    constraints_.configure(C, scene, constraints)
    b.y[:] = fs.y
    b.P[:] = fs.model.P
    b.I[:] = fs.model.I
    b.U[:] = fs.model.controls(amb_on)
    b.M[:] = 0.0
    if amb_on:
        b.M[K.M_POWER] = b.M[K.M_CTRL_ON] = 1.0
    b.M[K.M_T] = fs.t_fault
    b.M[K.M_H] = fs.integrator.h
    b.M[K.M_OK_START] = -1.0
    b.M[K.M_RELEV_T] = math.nan
    b.out[:] = 0.0                              # the reset info: nothing has happened yet
    K.observe_now(b.y, b.P, b.I, b.U, b.C, b.M, b.work, b.aux, b.cur, b.scale, b.obs)


def check_events(task: Task, name: str, events, power_return_time) -> EventRanges | None:
    """The env kwarg ``events`` of a task with events (:class:`EventRanges`); ValueError for
    ``events`` on a task without, and for ``power_return_time`` on a task whose AMBs stay on."""
    if task.amb_on and power_return_time is not None:
        raise ValueError(f"power_return_time = {power_return_time!r} does not apply to the "
                         f"{name}: its AMBs stay powered from the start")
    if task.events is None:
        if events is not None:
            raise ValueError(f"events = {events!r} applies to the tasks with an event (Recover), "
                             f"not {name}")
        return None
    return EventRanges.of(events, task.events)


def pressure_coef(model, scene) -> float:
    """c of the worst ball's Hertz contact pressure c x cbrt(ball load) [Pa]
    (:func:`physics.ball_bearing.max_contact_pressure`); ``MISSING`` without Sopanen-Mikkola
    balls (then the ball KPIs are ``MISSING``)."""
    if not model.has_ball_bearing:
        return MISSING
    return float(max_contact_pressure(scene.bearing, 1.0))


class PassiveEnv(RotorDropEnv):
    """``RotorDrop-Passive-v1``: the paper's passive drop (the action does nothing).

    One episode reproduces ``rotordrop drop`` for the same scene from the fault on.

    Action space: ``Box(-1, 1, (1,), float32)``, ignored (checked for finiteness and range).

    Observation (``obs_names``; physical value = obs x ``obs_scale``, SI)
    --------------------------------------------------------------------
    =====  =============  =============================================  ==================
    index  name           meaning                                        scale
    =====  =============  =============================================  ==================
    0-3    x1 y1 vx1 vy1  rotor displacement / velocity at sensor 1      clearance, 0.1 m/s
                          (= AMB1 plane), relative to the stator centre
    4-7    x2 y2 vx2 vy2  same at sensor 2 (AMB2 plane)                  clearance, 0.1 m/s
    8      rotor_speed    rotor spin speed Omega [rad/s]                 initial speed
    9-10   sleeve_speed1  sleeve (inner ring) spin speed of RB1, RB2     initial speed
           sleeve_speed2
    11     time           time since the fault [s]                       episode_time
    =====  =============  =============================================  ==================

    With ``full_state=True`` the observation is the whole state vector (``model.names``, scaled
    by ``model.obs_scale``) followed by ``time``.

    Version history: v0 (initial release).
    """
    task = PASSIVE


class DampingEnv(RotorDropEnv):
    """``RotorDrop-Damping-v1``: semi-active support damping (spec §6).

    Action space: ``Box(-1, 1, (2,), float32)``: ``damping1``, ``damping2``, the command of each
    housing's support damping, -1 -> C_min (``support.damping_min``, 2790 N s/m), +1 -> C_max
    (``support.damping_max``, 27900 N s/m), linear in between (``damping_action="from_max"``:
    every a >= 0 -> C_max, linear from C_min at -1 to C_max at 0). The damping follows its command
    with a first-order lag (``support.damper_time_constant``, 10 ms); it starts at
    ``support.damping``.

    Observation: the passive table (indices 0-10), then

    =====  ========  ======================================  =======
    11-12  damping1  current support damping C_s of housing  C_max
           damping2  1 and 2 [N s/m] (the damper state)
    13     time      time since the fault [s]                episode_time
    =====  ========  ======================================  =======

    Version history: v0 (initial release).
    """
    task = DAMPING


class RelevitateEnv(RotorDropEnv):
    """``RotorDrop-Relevitate-v1``: AMB reactivation (spec §5, ``effects.amb = "actuator"``).

    The AMBs (differential electromagnets, bias current, current limit, force capacity, optional
    coil lag, PID with filtered derivative) switch off at the fault; power returns
    ``power_return_time`` after it (rounded up to the control-step grid). From then on the agent
    commands the AMBs; before, its action has no effect.

    Action space, ``command="discrete"`` (default): ``Discrete(2)``, ``levitate``: 0 = stay off,
    1 = switch the built-in levitation controller on (reference ramped from the landing position
    to the centre in ``amb.liftoff_ramp_time``, integrators reset). Once on it stays on.

    Action space, ``command="continuous"``: ``Box(-1, 1, (4,), float32)``: control currents of
    AMB1 x, AMB1 y, AMB2 x, AMB2 y, normalised by ``amb.current_limit``; the bias current is on
    whenever power is.

    Action space, ``command="supervisor"``: ``Box(-1, 1, (6,), float32)``: ``levitate`` (> 0
    switches the built-in PID on, as in discrete mode), ``gain`` (PID gains x 2^a),
    ``offset_r1``, ``offset_t1``, ``offset_r2``, ``offset_t2`` (reference shift of AMB plane 1, 2
    by a x clearance along the radius and along a forward orbit of the sensed orbit, applied
    inside the physics step). The observation gains ``orbit_radius1/2`` (scale: clearance) and
    ``orbit_rate1/2`` (rad/s along the spin; scale: initial speed). See docs/environments.md.

    Observation: the passive table (indices 0-11), then

    =====  ===============  ================================================  =============
    12     amb_power        1 once power has returned                          1
    13     controller_on    1 when the AMBs are under control (the built-in    1
                            controller engaged, or direct currents applied)
    14-17  i1x i1y i2x i2y  applied control currents of the 4 AMB axes [A]     current limit
    =====  ===============  ================================================  =============

    Re-levitation succeeds when both contact forces stay zero and the rotor stays within half the
    clearance of the centre at both retainer planes for ``relevitation_hold`` (reward
    ``success`` once; ``info["relevitated"]``; KPI time = start of that period after the fault).

    Version history: v0 (initial release).
    """
    task = RELEVITATE


class FullEnv(RotorDropEnv):
    """``RotorDrop-Full-v1``: semi-active damping and AMB reactivation together.

    Action space: ``Box(-1, 1, float32)``: ``damping1``, ``damping2`` (as in Damping), then
    with ``command="discrete"`` one entry ``levitate`` (> 0 switches the built-in controller on;
    it stays on), with ``command="continuous"`` the 4 normalised control currents, or with
    ``command="supervisor"`` the 6 supervisor entries (see Relevitate).

    Observation: passive indices 0-10, ``damping1``, ``damping2``, ``time``, then the
    re-levitation entries ``amb_power``, ``controller_on``, ``i1x``, ``i1y``, ``i2x``, ``i2y``.

    Version history: v0 (initial release).
    """
    task = FULL
