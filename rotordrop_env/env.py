"""Gymnasium environments of the AMB rotor drop (spec §5-6): passive, semi-active support
damping, AMB re-levitation, and both together. See docs/environments.md for the full tables."""
from __future__ import annotations

import math
import numbers
from os import PathLike
from typing import Mapping

import gymnasium as gym
import numpy as np

from physics.amb import static_weight_share
from physics.metrics import WHIRL_MIN_REVOLUTIONS, WHIRL_RADIUS_FRACTION
from physics.ball_bearing import max_contact_pressure
from physics.scene import Scene, SceneError, load_scene
from physics.simulate import IntegrationError, explain_status
from physics.validity import validity_bound

from . import kernels as K
from .buffers import Buffers
from .info import MISSING, REWARD_TERMS, info_dict, kpi_keys  # noqa: F401 (REWARD_TERMS re-exported)
from .layout import COMMANDS, action_layout, observation_layout
from .reward import REWARDS, check_kpi_weights, kpi_step
from .scenario import (POWER_RETURN, POWER_RETURN_LIMITS, fault_state, layout_base, resolve_ranges,
                       sample, scenario_scene)
from .sensors import Sensing, check_delay, check_latency, check_noise

#: the kernel's re-levitation mode of each ``command``
LEV_CODES = {"discrete": K.LEV_DISCRETE, "continuous": K.LEV_CONTINUOUS,
             "supervisor": K.LEV_SUPERVISOR}
#: the kernel's map of each ``damping_action`` (damper action -> commanded damping)
DAMPING_ACTIONS = {"linear": K.DAMP_LINEAR, "from_max": K.DAMP_FROM_MAX}
#: command="supervisor": |offset| <= SUPERVISOR_OFFSET x clearance; gain scale in
#: [2^-SUPERVISOR_OCTAVES, 2^SUPERVISOR_OCTAVES]
SUPERVISOR_OFFSET = 1.0
SUPERVISOR_OCTAVES = 1.0
DEFAULT_POWER_RETURN = 0.05
#: reward weight -> its slot in the kernel configuration: settable at any time, used from the
#: next step on (``env.w_whirl = 5``, ``vec_env.set_attr("w_whirl", 5)``)
WEIGHT_SLOTS = {"w_whirl": K.C_W_WHIRL, "w_contact": K.C_W_CONTACT, "w_displacement": K.C_W_DISP,
                "w_effort": K.C_W_EFFORT, "w_success": K.C_W_SUCCESS, "w_failure": K.C_W_FAILURE}
#: settings fixed at construction: assigning one raises (it would silently change nothing)
FIXED_SETTINGS = frozenset(("control_dt", "dt", "episode_time", "n_steps", "randomize",
                            "randomization", "ranges", "fixed_keys", "full_state", "command",
                            "power_return_time", "samples_per_step", "relevitation_hold",
                            "terminate_on_failure", "render_mode", "base_scene", "overrides",
                            "obs_names", "obs_scale", "action_names", "weights",
                            "sensor_noise", "sensor_delay", "obs_latency_steps", "supervisor_authority",
                            "damping_action", "reward", "reward_kwargs"))


def _sensing_scene(base: Scene, noise: float, delay: float) -> tuple[Scene, float, float]:
    """The scene with the sensing kwargs in its ``sensor`` group (the one sensing model of
    physics/sensor.py), and the noise and delay in effect: a kwarg, else the scene's value; a
    kwarg that contradicts the scene's non-zero value is refused."""
    values = {}
    for key, given in (("sensor.noise", noise), ("sensor.delay", delay)):
        scene_value = base.get(key)
        kwarg = "sensor_" + key.split(".")[1]
        if given > 0.0 and scene_value > 0.0 and given != scene_value:
            raise ValueError(f"{kwarg} = {given:g} contradicts the scene's {key} = "
                             f"{scene_value:g}; give one of them")
        values[key] = given or scene_value
    if any(values[k] != base.get(k) for k in values):
        base = base.with_overrides(values)
    return base, values["sensor.noise"], values["sensor.delay"]


def _weight(name: str, doc: str) -> property:
    """A reward weight attribute: validated, written to the kernel, used from the next step."""
    return property(lambda self: self.weights[name], lambda self, v: self._set_weight(name, v),
                    doc=f"{doc} (settable: used from the next step)")


class RotorDropEnv(gym.Env):
    """Base class of the rotor-drop environments (one readable class, MuJoCo-v5 style).

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
    randomize                   False       draw a scenario at every reset (ranges below); keys
                                            fixed by the user (``overrides``, the
                                            ``power_return_time`` kwarg, a None range) keep
                                            their value
    randomization               None        {key: (low, high) | (law, low, high) | None};
                                            needs randomize=True, no range for a fixed key
    full_state                  False       observe the whole state vector (research)
    sensor_noise                0.0         std of the displacement sensors' Gaussian noise [m],
                                            one sample per control step, seen by the built-in
                                            PID, the supervisor and the observations
                                            (velocities: sqrt(2) x that / 1 ms), see
                                            :mod:`rotordrop_env.sensors`
    sensor_delay                0.0         delay of the displacement sensors [s], inside the
                                            physics: the built-in PID, the supervisor and the
                                            observations see it
    obs_latency_steps           0           k or (low, high): the agent sees the measurement of
                                            k control steps ago, k drawn per episode
    command                     "discrete"  re-levitation envs: "discrete", "continuous" or
                                            "supervisor"
    supervisor_authority        1.0         command="supervisor": a in (0, 1] scales the offset
                                            range (a x clearance) and the gain-scale range
                                            (2^-a ... 2^a); 1 is the full range
    damping_action              "linear"    damping envs: map of the damper action a to the
                                            damping, "linear" (-1 C_min, 0 mid-range, +1 C_max)
                                            or "from_max" (a >= 0 C_max, linear to C_min at -1:
                                            the zero action is full damping)
    power_return_time           0.05        re-levitation envs: power returns [s after fault]
    samples_per_step            5           monitor samples per control step (dense output)
    relevitation_hold           0.02        re-levitated after this long in the success region [s]
    terminate_on_failure        True        end at the stator, at a bearing overload or when
                                            a contact leaves its law's validity bound
    reward                      "default"   "default" (the terms below) or "kpi" (the KPI
                                            reward of :mod:`rotordrop_env.reward`)
    reward_kwargs               None        reward="kpi": its weights (``KPI_WEIGHTS``)
    w_whirl, w_contact,         10, 0.1,    reward weights (see Reward)
    w_displacement, w_effort,   0.1, 0.01,
    w_success, w_failure        10, 10
    render_mode                 None        "rgb_array" or "human"
    ==========================  ==========  ====================================================

    Reward (sum of named terms, each in ``info["reward_<term>"]``)
    -------------------------------------------------------------
    =============  ========================================================================
    term           value per control step
    =============  ========================================================================
    whirl          -w_whirl x backward orbit revolutions in the step (rotor relative to the
                   sleeve, counted beyond half the clearance; mean of the two planes)
    contact        -w_contact x peak contact force in the step / static weight share [N/N]
    displacement   -w_displacement x peak radial displacement at the retainer planes / clearance
    effort         -w_effort x mean squared normalised command (damper (C-C_min)/(C_max-C_min),
                   AMB control currents / current limit)
    success        +w_success once, when re-levitation is achieved (re-levitation envs)
    failure        -w_failure x remaining control steps, on termination (failing never pays:
                   10 per step is above the per-step cost of riding out a whirl, about 3)
    =============  ========================================================================

    ``info`` (see :mod:`rotordrop_env.info`): the same keys at reset and at every step, numpy
    values, no NaN; the reward terms, ``cost`` (Safety-Gymnasium convention) and its
    components, and the episode's ``kpi_*`` so far. The scenario of the episode is
    ``env.unwrapped.scenario``.

    Episode end: ``terminated`` when the rotor reaches the AMB stator (radial displacement
    ``amb.air_gap`` = 600 µm at an AMB plane), a contact force exceeds the retainer bearing's
    static load rating C_0 or a penetration passes its contact law's validity bound
    (:func:`physics.validity.validity_bound`; ``info["beyond_validity"]``, latched, at reset and
    every step); ``truncated`` only at the time limit.
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 30}
    fixed_settings = FIXED_SETTINGS
    _damping = False
    _relevitate = False

    def __init__(self, scene: str | Scene = "paper", overrides: dict | None = None,
                 control_dt: float = 1e-3, episode_time: float = 0.3, randomize: bool = False,
                 randomization: dict | None = None, full_state: bool = False,
                 command: str | None = None, power_return_time: float | None = None,
                 samples_per_step: int = 5, relevitation_hold: float = 0.02,
                 terminate_on_failure: bool = True, sensor_noise: float = 0.0,
                 obs_latency_steps: int | tuple[int, int] = 0, sensor_delay: float = 0.0,
                 w_whirl: float = 10.0,
                 w_contact: float = 0.1, w_displacement: float = 0.1, w_effort: float = 0.01,
                 w_success: float = 10.0, w_failure: float = 10.0, render_mode: str | None = None,
                 supervisor_authority: float = 1.0, damping_action: str = "linear",
                 reward: str = "default", reward_kwargs: dict | None = None):
        self._check_options(command, power_return_time, render_mode)
        if reward not in REWARDS:
            raise ValueError(f"reward = {reward!r} is not a reward; the rewards are "
                             + ", ".join(repr(r) for r in REWARDS))
        if reward_kwargs and reward != "kpi":
            raise ValueError("reward_kwargs are the weights of reward='kpi'; pass reward='kpi' "
                             "or leave them out")
        if reward_kwargs is not None and not isinstance(reward_kwargs, Mapping):
            raise ValueError(f"reward_kwargs = {reward_kwargs!r} must be a dict")
        self.reward = reward
        self.reward_kwargs = dict(reward_kwargs or {})
        self._kpi_weights = check_kpi_weights(reward_kwargs) if reward == "kpi" else None
        self.supervisor_authority = _check_authority(supervisor_authority, command)
        self.damping_action = self._check_damping_action(damping_action)
        _positive("control_dt", control_dt, 1e-6, 0.1)
        _positive("episode_time", episode_time, control_dt, 100.0)
        _positive("relevitation_hold", relevitation_hold, 0.0, 100.0)
        _positive("samples_per_step", samples_per_step, 1, 1000)
        if not float(samples_per_step).is_integer():
            raise ValueError(f"samples_per_step = {samples_per_step!r} must be an integer in [1, 1000]")
        if overrides is not None and not isinstance(overrides, Mapping):
            raise ValueError(f"overrides = {overrides!r} must be a dict of dotted scene keys, "
                             "e.g. {'contact.friction': 0.3}")
        weights = dict(w_whirl=w_whirl, w_contact=w_contact, w_displacement=w_displacement,
                       w_effort=w_effort, w_success=w_success, w_failure=w_failure)
        for k, v in weights.items():
            _positive(k, v, 0.0, 1e9)
        self.command = (command or "discrete") if self._relevitate else None
        self.power_return_time = (DEFAULT_POWER_RETURN if power_return_time is None
                                  else float(power_return_time)) if self._relevitate else None
        self.control_dt = self.dt = float(control_dt)
        self.n_steps = int(math.ceil(episode_time / control_dt - 1e-9))
        self.episode_time = self.n_steps * self.dt
        self.randomize = _flag("randomize", randomize)
        self.full_state = _flag("full_state", full_state)
        self.render_mode = render_mode
        self.weights = weights
        noise, delay = check_noise(sensor_noise), check_delay(sensor_delay)
        self.obs_latency_steps = check_latency(obs_latency_steps)
        base = self._make_scene(scene, overrides)
        base, self.sensor_noise, self.sensor_delay = _sensing_scene(base, noise, delay)
        self.ranges, fixed = resolve_ranges(randomization, self._relevitate, type(self).__name__)
        _check_unused_ranges(randomization, self.randomize, overrides, power_return_time)
        self.base_scene = layout_base(base, self.ranges, fixed) if self.randomize else base
        #: keys the user fixed: never randomised (still drawn, so the others' draws stay put)
        self.fixed_keys = fixed | frozenset(overrides or {}) | frozenset(
            [POWER_RETURN] if power_return_time is not None else [])
        self.scene = self.base_scene
        fs = fault_state(self.base_scene)
        self.model = model = fs.model

        self.obs_names, self.obs_scale = observation_layout(
            model, self._damping, self._relevitate, self.full_state, self.episode_time,
            self.command)
        self.action_space, self.action_names = action_layout(self._damping, self._relevitate,
                                                             self.command)
        n_obs = len(self.obs_names)
        self.observation_space = gym.spaces.Box(-np.inf, np.inf, shape=(n_obs,), dtype=np.float32)
        self._discrete = isinstance(self.action_space, gym.spaces.Discrete)
        self._act_shape = () if self._discrete else self.action_space.shape
        n_act = 1 if self._discrete else self.action_space.shape[0]
        self._sensing = Sensing(self.sensor_noise, self.obs_latency_steps, self.obs_names,
                                self.obs_scale, self.base_scene.contact.clearance,
                                model.control_index("sensor.noise"))
        self._bind(Buffers(model.n_state, n_obs, n_act, int(samples_per_step), model.sizes))
        self._configure_static(relevitation_hold, _flag("terminate_on_failure", terminate_on_failure))
        self._renderer = None
        self._values = np.zeros(K.N_V)          # the info numbers (rotordrop_env.info)
        self._scenario: dict = {}
        self._needs_reset = True
        self._closed = False
        self._ended = False                 # the episode has ended (until the next reset)
        self._warned = False                # a step after the end was warned about
        self._made = True                   # from here on FIXED_SETTINGS cannot be assigned

    # ------------------------------------------------------------ attributes and weights --
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
        _positive(name, value, 0.0, 1e9)
        self.weights[name] = float(value)
        self._b.C[WEIGHT_SLOTS[name]] = value

    w_whirl = _weight("w_whirl", "reward weight per backward orbit revolution")
    w_contact = _weight("w_contact", "reward weight of the normalised contact force")
    w_displacement = _weight("w_displacement", "reward weight of the normalised displacement")
    w_effort = _weight("w_effort", "reward weight of the control effort")
    w_success = _weight("w_success", "re-levitation bonus")
    w_failure = _weight("w_failure", "penalty per remaining control step on termination")

    # ------------------------------------------------------------------------- set-up --
    def _check_options(self, command, power_return_time, render_mode):
        name = type(self).__name__
        if not self._relevitate:
            if command is not None:
                raise ValueError(f"command= applies to the re-levitation environments only, not {name}")
            if power_return_time is not None:
                raise ValueError(f"power_return_time= applies to the re-levitation environments "
                                 f"only, not {name}")
        if command is not None and command not in COMMANDS:
            raise ValueError(f"command = {command!r} is not a command mode; the modes are "
                             + ", ".join(repr(c) for c in COMMANDS))
        if power_return_time is not None:
            _positive(POWER_RETURN, power_return_time, *POWER_RETURN_LIMITS)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode = {render_mode!r} must be None or one of "
                             f"{self.metadata['render_modes']}")

    def _check_damping_action(self, value) -> str:
        """``damping_action``: one of ``DAMPING_ACTIONS``, other than "linear" only in an
        environment with damper commands (elsewhere it would silently change nothing)."""
        if value not in DAMPING_ACTIONS:
            raise ValueError(f"damping_action = {value!r} is not a damper map; the maps are "
                             + ", ".join(repr(m) for m in DAMPING_ACTIONS))
        if value != "linear" and not self._damping:
            raise ValueError(f"damping_action = {value!r} applies to the environments with "
                             f"damper commands (Damping, Full) only, not {type(self).__name__}")
        return value

    def _make_scene(self, scene, overrides) -> Scene:
        if isinstance(scene, Mapping):          # Scene.to_dict / to_json form (a JSON env spec)
            scene = Scene.from_dict(scene)
        if isinstance(scene, Scene):
            base = scene.with_overrides(overrides) if overrides else scene
        elif isinstance(scene, (str, PathLike)):
            base = load_scene(scene, overrides)
        else:
            raise ValueError(f"scene = {scene!r} must be a preset name, a TOML path, a "
                             "physics.Scene or its dict (Scene.to_dict(), as in a JSON env spec)")
        forced = {}
        if self._damping:
            forced["effects.semi_active_damper"] = True
        if self._relevitate:
            forced["effects.amb"] = "actuator"
        for key, value in forced.items():
            given = (overrides or {}).get(key)
            if given is not None and str(given).lower() != str(value).lower():
                raise SceneError(f"{type(self).__name__} needs {key} = {value}, got {given!r}")
        base = base.with_overrides(forced) if forced else base
        if self._damping and not base.effects.housing:
            raise SceneError("the damping environments need effects.housing = true")
        return base

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

    def _configure_static(self, hold: float, terminate: bool) -> None:
        b = self._b
        C = b.C
        C[K.C_DT] = self.dt
        C[K.C_DAMP] = DAMPING_ACTIONS[self.damping_action] if self._damping else K.DAMP_NONE
        C[K.C_LEV] = LEV_CODES[self.command] if self._relevitate else K.LEV_NONE
        C[K.C_SUP_OFFSET], C[K.C_SUP_OCTAVES] = supervisor_scales(self.base_scene,
                                                                  self.supervisor_authority)
        C[K.C_WHIRL_RADIUS], C[K.C_WHIRL_REVS] = WHIRL_RADIUS_FRACTION, WHIRL_MIN_REVOLUTIONS
        w = self.weights
        C[K.C_W_WHIRL], C[K.C_W_CONTACT], C[K.C_W_DISP] = w["w_whirl"], w["w_contact"], w["w_displacement"]
        C[K.C_W_EFFORT], C[K.C_W_SUCCESS], C[K.C_W_FAILURE] = w["w_effort"], w["w_success"], w["w_failure"]
        C[K.C_HOLD] = hold
        C[K.C_TERMINATE] = 1.0 if terminate else 0.0
        C[K.C_FULL] = 1.0 if self.full_state else 0.0
        b.scale[:] = self.obs_scale

    def _configure_episode(self, fs, power_return: float | None) -> None:
        """Episode constants of the kernel; the solver settings are the fault state's
        integrator's, so the episode continues exactly as ``rotordrop drop`` would."""
        b, scene, integ = self._b, fs.scene, fs.integrator
        C = b.C
        t_fault = fs.t_fault
        C[K.C_T_FAULT] = t_fault
        C[K.C_T_END] = t_fault + self.n_steps * self.dt
        if power_return is None:
            C[K.C_T_POWER] = math.inf
        else:                                   # on the control-step grid (documented)
            C[K.C_T_POWER] = t_fault + math.ceil(power_return / self.dt - 1e-9) * self.dt
        C[K.C_RTOL], C[K.C_HMAX], C[K.C_HMIN] = integ.rtol, integ.h_max, integ.h_min
        C[K.C_FIXED] = 1.0 if integ.fixed else 0.0
        C[K.C_MAXSTEPS] = integ.max_steps
        b.atol[:] = integ.atol
        C[K.C_F_REF] = static_weight_share(scene)
        C[K.C_GAP] = scene.amb.air_gap
        C[K.C_LOAD_RATING] = scene.bearing.static_load_rating
        C[K.C_CS_MIN], C[K.C_CS_MAX] = scene.support.damping_min, scene.support.damping_max
        C[K.C_ILIM] = scene.amb.current_limit
        C[K.C_RELEV_RADIUS] = 0.5 * scene.contact.clearance
        C[K.C_PEN_BOUND] = validity_bound(scene, "retainer").penetration
        C[K.C_STATOR_BOUND] = (validity_bound(scene, "stator").penetration
                               if scene.effects.stator_contact else math.inf)
        C[K.C_P_COEF] = pressure_coef(fs.model, scene)

    # ------------------------------------------------------------------------ episode --
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        self._check_open("reset")
        super().reset(seed=seed)
        values = sample(self.ranges, self.np_random, self.fixed_keys) if self.randomize else {}
        fixed = (options or {}).get("scenario") or {}
        unknown = set(options or {}) - {"scenario"}
        if unknown or not isinstance(fixed, Mapping):
            what = f"unknown reset option(s) {sorted(unknown)}" if unknown else \
                f"reset option scenario = {fixed!r} is not a dict"
            raise ValueError(f"{what}; use options="
                             "{'scenario': {dotted_key: value, 'power_return_time': s}}")
        values.update(fixed)
        if POWER_RETURN in values and not self._relevitate:
            raise ValueError(f"{POWER_RETURN} applies to the re-levitation environments only")
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
            _positive(POWER_RETURN, pr, *POWER_RETURN_LIMITS)
        self._configure_episode(fs, pr)
        b.y[:] = fs.y
        b.P[:] = fs.model.P
        b.I[:] = fs.model.I
        b.U[:] = fs.model.controls(False)
        b.M[:] = 0.0
        b.M[K.M_T] = fs.t_fault
        b.M[K.M_H] = fs.integrator.h
        b.M[K.M_OK_START] = -1.0
        b.M[K.M_RELEV_T] = math.nan
        b.out[:] = 0.0                              # the reset info: nothing has happened yet
        K.observe_now(b.y, b.P, b.I, b.U, b.C, b.M, b.work, b.aux, b.cur, b.scale, b.obs)
        self._scenario = self._scenario_report(values, pr is not None)
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

    @property
    def scenario(self) -> dict:
        """The machine of the current episode (a copy): every randomisation key's value (drawn,
        fixed by the user, or the scene's without ``randomize``), every key fixed by ``reset``
        options, and ``power_return_time`` as applied (re-levitation environments)."""
        return dict(self._scenario)

    def _scenario_report(self, values: dict, power: bool) -> dict:
        """The machine of this episode: the value of every randomisation key (drawn, fixed by
        the user, or the scene's without ``randomize``) and of every key fixed by ``reset``
        options; the power return as applied (on the control-step grid)."""
        keys = sorted((set(self.ranges) | set(values)) - {POWER_RETURN})
        out = {k: self.scene.get(k) for k in keys}
        if power:                               # without the subtraction's round-off
            out[POWER_RETURN] = round(float(self._b.C[K.C_T_POWER] - self._b.C[K.C_T_FAULT]), 12)
        return out

    def step(self, action):
        if self._needs_reset or self._ended:
            self._check_steppable()
        b = self._b
        self._load_action(action, b.act)
        K.step_one(*self._args)
        return self._finish(action)

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

    def _load_action(self, action, act: np.ndarray) -> None:
        a = real_action(action, self.action_space, self.action_names)
        if self._discrete:
            if a.size != 1:
                raise ValueError(f"action {action!r} is not in {self.action_space}: give 0 or 1")
            act[0] = a.item()
            return
        if a.shape != self._act_shape:
            raise ValueError(f"action {action!r} has shape {a.shape}; "
                             f"{self.action_space} needs {self._act_shape} ({', '.join(self.action_names)})")
        act[:] = a

    def _finish(self, action):
        """Turn the kernel's outputs into Gymnasium's (obs, reward, terminated, truncated, info)."""
        b = self._b
        out = b.out
        if out[K.O_ERR]:
            self._action_error(out[K.O_ERR], action)
        if out[K.O_STATUS]:
            raise IntegrationError(explain_status(int(out[K.O_STATUS]), b.M[K.M_T], b.M[K.M_H], self.model))
        terminated = bool(out[K.O_TERM])
        truncated = bool(out[K.O_TRUNC])
        self._ended |= terminated or truncated
        if self._kpi_weights is None:
            reward = float(out[K.O_REWARD])
        else:
            reward = float(kpi_step(out, b.M, b.C, self._kpi_weights, self._relevitate))
        info = self._info()
        self._show_step()
        return self.observed(), reward, terminated, truncated, info

    def observed(self) -> np.ndarray:
        """The float32 observation the agent gets after the step just taken: the kernel's, or
        with ``sensor_noise`` / ``obs_latency_steps`` the sensed one (:mod:`.sensors`; call
        once per step, it takes the measurement)."""
        if not self._sensing.active:
            return self._b.obs.astype(np.float32)
        return self._sensing.step(self._b.obs, self.np_random, self._b.U)

    def _action_error(self, err: int, action) -> None:
        """Raise the ValueError of a refused action (``err``: the kernel's ERR_* code)."""
        what = "non-finite" if err == K.ERR_NAN else "out-of-range"
        if self._discrete:
            raise ValueError(f"{what} action {action!r}: the {self.action_space} action "
                             "(levitate) must be 0 (stay off) or 1 (switch on)")
        raise ValueError(f"{what} action {action!r}: {self.action_space} entries must be finite "
                         f"and in [-1, 1] ({', '.join(self.action_names)})")

    def _show_step(self) -> None:
        """Record the step for the episode view (and redraw it in "human" mode)."""
        if self._renderer is not None:
            self._record()
            if self.render_mode == "human":
                self.render()

    def _info(self) -> dict:
        """The ``info`` of the reset or step just taken (:mod:`rotordrop_env.info`)."""
        b = self._b
        K.info_values(b.out, b.M, b.C, self._values)
        return info_dict(self._values, self._sensing.k, self._relevitate)

    def kpis(self) -> dict:
        """Episode KPIs so far (numpy scalars; every step's ``info`` carries them, the final
        step's are the episode's)."""
        return kpi_keys(self._info())

    # ---------------------------------------------------------------------- rendering --
    def _record(self, step: bool = True) -> None:
        """One row of the episode view (``rotordrop_env.render.COLUMNS``) and the orbits at the
        step's monitor samples (at reset: the present state only): the rotor axis at the
        retainer planes, a flexible rotor's elastic deflection included."""
        b = self._b
        y, M, model = b.y, b.M, self.model
        damping = ((y[model.state_index("RB1.Cs")], y[model.state_index("RB2.Cs")])
                   if model.has_state("RB1.Cs") else (math.nan, math.nan))
        amb = (M[K.M_POWER], M[K.M_CTRL_ON]) if self._relevitate else (math.nan, math.nan)
        states = b.Y_sub if step else y[None]
        orbit = np.empty((len(states), 4))              # the axis at RB1, RB2 (elastic included)
        K.retainer_orbits(states, b.P, b.I, orbit)
        self._renderer.add((self.time, b.out[K.O_FORCE], y[model.state_index("Omega")],
                            M[K.M_REV1], M[K.M_REV2],
                            M[K.M_WHIRL], *damping, *amb), orbit)

    def render(self):
        self._check_open("render")
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode='rgb_array' "
                            "or 'human' to gym.make")
            return None
        return self._ensure_renderer().draw()

    def _ensure_renderer(self):
        if self._renderer is None:
            from .render import Renderer
            title = f"{self.spec.id if self.spec is not None else type(self).__name__}  ·  " \
                    f"{self.base_scene.name} scene"
            self._renderer = Renderer(self.render_mode, title, self.episode_time, self.n_steps,
                                      self._b.dims[3], self._damping, self._relevitate)
            self._reset_view()
        return self._renderer

    def _reset_view(self) -> None:
        s = self.scene
        self._ensure_renderer().reset(s.contact.friction, s.contact.clearance, s.amb.air_gap)

    def close(self):
        """Release the view; afterwards reset(), step() and render() raise
        ``gymnasium.error.ClosedEnvironmentError`` (closing twice is fine)."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        self._closed = self._needs_reset = True

    # ---------------------------------------------------------------------- helpers --
    @property
    def time(self) -> float:
        """Time since the fault [s]."""
        return float(self._b.M[K.M_T] - self._b.C[K.C_T_FAULT])

    @property
    def state(self) -> np.ndarray:
        """A copy of the physical state vector (names: ``env.unwrapped.model.names``)."""
        return self._b.y.copy()


def pressure_coef(model, scene) -> float:
    """c of the worst ball's Hertz contact pressure c x cbrt(ball load) [Pa]
    (:func:`physics.ball_bearing.max_contact_pressure`); ``MISSING`` without Sopanen-Mikkola
    balls (then the ball KPIs are ``MISSING``)."""
    if not model.has_ball_bearing:
        return MISSING
    return float(max_contact_pressure(scene.bearing, 1.0))


def real_action(action, space: gym.Space, names) -> np.ndarray:
    """``action`` as an array of real numbers; a bool, complex, string or object action raises
    ValueError naming the action space (numpy would cast it silently)."""
    a = np.asarray(action)
    if a.dtype.kind not in "fiu":
        raise ValueError(f"action {action!r} ({a.dtype} values) is not in {space}: give real "
                         f"numbers ({', '.join(names)})")
    return a


def supervisor_scales(scene: Scene, authority: float = 1.0) -> tuple[float, float]:
    """(largest reference offset [m], gain-scale octaves) of ``command="supervisor"`` with the
    ``supervisor_authority`` ``authority`` (1: the full ranges)."""
    return authority * SUPERVISOR_OFFSET * scene.contact.clearance, authority * SUPERVISOR_OCTAVES


def _check_authority(value, command) -> float:
    """``supervisor_authority``: a real number in (0, 1], other than 1 only with the supervisor
    command (elsewhere it would silently change nothing)."""
    _positive("supervisor_authority", value, 0.0, 1.0, low_open=True)
    if value != 1.0 and command != "supervisor":
        raise ValueError(f"supervisor_authority = {value!r} applies to command='supervisor' only, "
                         f"not command={command!r}")
    return float(value)


def _positive(name: str, value, lo: float, hi: float, low_open: bool = False) -> None:
    """ValueError naming ``name`` and the range unless ``value`` is a real number in [lo, hi]
    (``low_open``: in (lo, hi])."""
    interval = f"{'(' if low_open else '['}{lo:g}, {hi:g}]"
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name} = {value!r} must be a real number in {interval}, "
                         f"not a {type(value).__name__}")
    if not (math.isfinite(value) and lo <= value <= hi) or (low_open and value == lo):
        raise ValueError(f"{name} = {value!r} must be in {interval}")


def _check_unused_ranges(randomization, randomize: bool, overrides, power_return_time) -> None:
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


def _flag(name: str, value) -> bool:
    """A bool kwarg (bool or numpy bool; strings and numbers are refused)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} = {value!r} must be a bool (True or False), "
                         f"not a {type(value).__name__}")
    return bool(value)


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
    _damping = True


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
    _relevitate = True


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
    _damping = True
    _relevitate = True
