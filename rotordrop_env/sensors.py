"""Imperfect sensing: displacement noise and delay, one sensing model for every controller, and
the agent's own observation latency (kwargs ``sensor_noise``, ``sensor_delay`` and
``obs_latency_steps``; docs/environments.md "Sensor noise, delay and latency").

The noise and the delay are the position sensors' (physics/sensor.py, the scene group
``sensor``): the built-in AMB controller (PID or linear law), the supervisor's orbit frame and
the observations all see the same sensed displacement; the KPIs and rewards are those of the
true motion.

* **Delay** τ = ``sensor_delay`` [s]: inside the physics (a Padé approximant per AMB axis); the
  kernel's observations x1 ... vy2 and orbit entries are the delayed ones.
* **Noise**: the four displacements x1, y1, x2, y2 get independent Gaussian noise of standard
  deviation σ = ``sensor_noise`` [m], one sample per axis at each sensor sample instant
  t_k = k / f_s (f_s = ``sensor_sample_rate``, the scene's ``sensor.sample_rate``), held until
  the next, whatever the control step: :meth:`Sensing.draw_step` draws the samples strictly
  inside a step before it (the kernel holds them in turn, the U entries ``sensor.noise``), the
  measurement after the step draws the one at its end, if an instant falls there, and carries
  the sample current then; the built-in PID and the supervisor's orbit frame read the same
  samples. The four velocities, which a real machine estimates by differencing the displacement
  signal, get independent noise of σ_v = √2 σ / ``VELOCITY_ESTIMATE_DT`` per observation (the
  noise of a difference of two samples 1 ms apart, the same for every control step;
  observations only). With ``command="supervisor"`` the orbit radius and rate are
  computed from the noisy values (the same formula as the kernel's). Spin speeds, damper states
  and coil currents are not noised.
* **Latency**: the observation returned after control step n is the (noisy) measurement taken
  after step n − k; k is drawn once per episode, uniformly from the integers of
  ``obs_latency_steps = (low, high)``. Every entry is delayed except ``time``, the controller's
  own clock. Before the episode has k measurements, the first one is repeated.

All draws come from the environment's ``np_random``; with σ = 0 and k = 0 nothing is drawn and
the observations are bit-identical to an environment without these kwargs. At f_s = 1 /
control_dt the draws are those of a noise held per control step.
"""
from __future__ import annotations

import math
import numbers
from functools import partial

import numpy as np

from physics.jit import bound, njit
from physics.sensor import on_sample, samples_inside

from .kernels import M_T, SUP_MIN_RADIUS
from .layout import SUPERVISOR_OBS

#: interval of the velocity estimate that the velocity noise stands for [s]
VELOCITY_ESTIMATE_DT = 1e-3
NOISE_LIMITS = (0.0, 1e-4)          # sensor_noise [m] (the scene's sensor.noise range)
DELAY_LIMITS = (0.0, 2e-3)          # sensor_delay [s] (the scene's sensor.delay range)
RATE_LIMITS = (1e3, 1e5)            # sensor_sample_rate [Hz] (the scene's sensor.sample_rate range)
LATENCY_LIMITS = (0, 100)           # obs_latency_steps [control steps]
POSITIONS = ("x1", "y1", "x2", "y2")
VELOCITIES = ("vx1", "vy1", "vx2", "vy2")


def _check_real(name: str, value, limits: tuple[float, float], what: str, example: str) -> float:
    """``value`` as a float in ``limits`` (one-line ValueError naming ``name`` otherwise)."""
    lo, hi = limits
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real) \
            or not (math.isfinite(value) and lo <= value <= hi):
        raise ValueError(f"{name} = {value!r} must be {what} in [{lo:g}, {hi:g}] ({example})")
    return float(value)


def check_noise(value) -> float:
    """``sensor_noise`` as a float in ``NOISE_LIMITS``."""
    return _check_real("sensor_noise", value, NOISE_LIMITS, "a standard deviation in metres",
                       "e.g. 2e-6 for 2 µm")


def check_delay(value) -> float:
    """``sensor_delay`` as a float in ``DELAY_LIMITS``."""
    return _check_real("sensor_delay", value, DELAY_LIMITS, "a delay in seconds",
                       "e.g. 1e-4 for 0.1 ms")


def check_sample_rate(value) -> float | None:
    """``sensor_sample_rate`` as a float in ``RATE_LIMITS`` (None: the scene's)."""
    if value is None:
        return None
    return _check_real("sensor_sample_rate", value, RATE_LIMITS, "a sample rate in hertz",
                       "e.g. 2e4 for 20 kHz")


def check_latency(value) -> tuple[int, int]:
    """``obs_latency_steps`` (an integer k, or (low, high)) as (low, high) integers in
    ``LATENCY_LIMITS`` (one-line ValueError otherwise)."""
    lo_lim, hi_lim = LATENCY_LIMITS
    pair = tuple(value) if isinstance(value, (list, tuple)) else (value, value)
    ok = len(pair) == 2 and all(isinstance(v, numbers.Integral) and not isinstance(v, (bool, np.bool_))
                                for v in pair)
    if not ok or not lo_lim <= pair[0] <= pair[1] <= hi_lim:
        raise ValueError(f"obs_latency_steps = {value!r} must be an integer or a pair (low, high) "
                         f"of integers with {lo_lim} <= low <= high <= {hi_lim} [control steps]")
    return int(pair[0]), int(pair[1])


class Sensing:
    """The noisy, delayed observation of one environment (module doc).

    ``obs_names``/``obs_scale``: the environment's layout (normalised obs x scale = SI);
    ``clearance`` [m] for the orbit's dead zone.

    A step's standard normals are drawn in one call (:meth:`draw_step`, before the kernel
    step): the samples strictly inside the step, then the measurement's after it (4 of a new
    displacement sample at a sample instant, then 4 of the velocity estimates), the very
    numbers, in the very order, of one draw per sample and one per measurement."""

    def __init__(self, noise: float, latency: tuple[int, int], obs_names, obs_scale,
                 clearance: float, noise_control: int, sample_rate: float = 1e4,
                 control_dt: float = 1e-3):
        names = list(obs_names)
        self.noise, self.latency = noise, latency
        self.rate, self.dt = sample_rate, control_dt
        self.z = np.zeros(4)                    # standard normals of the held noise sample
        #: measurements taken this episode, latency k, the first row of the coming
        #: measurement's normals (draw_step's; -1: not drawn), a sample instant at it (1/0),
        #: samples inside the last step (draw_step)
        self.state = np.array([0, 0, -1, 1, 0], dtype=np.int64)
        self.noise_control = noise_control      # first of the 4 noise controls in U
        self.active = noise > 0.0 or latency[1] > 0
        self.time_col = names.index("time")
        if noise > 0.0:
            missing = [n for n in POSITIONS + VELOCITIES if n not in names]
            if missing:
                raise ValueError("sensor_noise applies to the sensor observations (x1 ... vy2), "
                                 "which a full_state=True environment does not have")
            self.cols = np.array([names.index(n) for n in POSITIONS + VELOCITIES])
            sigma = np.array([noise] * 4 + [math.sqrt(2.0) * noise / VELOCITY_ESTIMATE_DT] * 4)
            self.sigma = sigma / np.asarray(obs_scale)[self.cols]       # in obs units
            self.scale = np.asarray(obs_scale, dtype=np.float64)
            self.orbit = [names.index(n) for n in SUPERVISOR_OBS] if SUPERVISOR_OBS[0] in names else None
            self.speed_col = names.index("rotor_speed")
            self.r_min = SUP_MIN_RADIUS * clearance
        self.buffer = np.zeros((latency[1] + 1, len(names)))
        self._cols = self.cols if noise > 0.0 else np.zeros(0, dtype=np.int64)   # for _sense
        self._sigma = self.sigma if noise > 0.0 else np.zeros(0)
        self._own = np.zeros((2, 4))            # the measurement's normals drawn by itself
        self._Z, self._rows = None, {}          # draw_step's Z and its flat views by rows

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()            # the views of Z are made again (copies break
        state["_Z"], state["_rows"] = None, {}  # them)
        return state

    #: the episode's observation latency [control steps]
    k = property(lambda self: int(self.state[1]))
    #: measurements taken this episode
    n = property(lambda self: int(self.state[0]))
    #: a sensor sample instant falls on the coming measurement
    fresh = property(lambda self: bool(self.state[3]))
    #: sensor samples strictly inside the last step (:meth:`draw_step`)
    last_drawn = property(lambda self: int(self.state[4]))

    @property
    def compiled(self) -> bool:
        """Every measurement is the compiled one (the supervisor's orbit entries with noise
        take the Python path)."""
        return self.noise == 0.0 or self.orbit is None

    @property
    def n_noise(self) -> int:
        """Rows of the kernel's ``Z``: the most sensor samples strictly inside one control step,
        then the 2 rows of the measurement after it (:meth:`draw_step`); 0 without noise."""
        return math.ceil(self.dt * self.rate) + 3 if self.noise > 0.0 else 0

    def reset(self, true_obs: np.ndarray, rng: np.random.Generator,
              U: np.ndarray | None = None) -> np.ndarray:
        """Start an episode: draw its latency k, take the first measurement (with a fresh
        noise sample: the sensor's sample current at the episode's start)."""
        lo, hi = self.latency
        self.state[:] = (0, int(rng.integers(lo, hi + 1)) if hi > lo else lo, -1, 1, 0)
        return self.step(true_obs, rng, U)

    def draw_step(self, t0: float, Z: np.ndarray, rng: np.random.Generator) -> int:
        """Before a control step from ``t0``: the standard normals of the noise samples at the
        sensor's sample instants strictly inside the step into ``Z``'s first rows (the kernel
        holds them in turn, :func:`physics.integrate.integrate_sensed`), and in the rows after
        them the normals of the measurement after the step (a sample at the step's end is its
        new displacement sample), in one draw. Returns the number of samples inside (0,
        nothing drawn, without noise)."""
        if self.noise == 0.0:
            return 0
        rows = plan_step(t0, self.dt, self.rate, Z, self.z, self.state)
        if Z is not self._Z:
            self._Z, self._rows = Z, {}
        flat = self._rows.get(rows)
        if flat is None:
            flat = self._rows[rows] = _flat(Z[:rows])
        rng.standard_normal(out=flat)
        return self.last_drawn

    def drawer(self, M: np.ndarray, Z: np.ndarray):
        """:meth:`draw_step` on an environment's arrays (``M``: its monitor, the step's start
        at ``M[M_T]``), its plan bound to them (:func:`physics.jit.bound`): a callable of the
        environment's generator; None without noise."""
        if self.noise == 0.0:
            return None
        counts = np.zeros(1, dtype=np.int64)
        plan = bound(plan_rows, np.zeros(1, dtype=np.int64), M[None], self.dt, self.rate, Z[None],
                     self.z[None], self.state[None], counts)
        return partial(self._drawn, plan, counts, Z, {})

    def _drawn(self, plan, counts: np.ndarray, Z: np.ndarray, views: dict,
               rng: np.random.Generator) -> None:
        """The bound :meth:`draw_step` (:meth:`drawer`): ``plan`` fills ``counts``, the rows of
        ``Z`` to draw (their flat views kept in ``views``)."""
        plan()
        rows = counts.item()
        flat = views.get(rows)
        if flat is None:
            flat = views[rows] = _flat(Z[:rows])
        rng.standard_normal(out=flat)
        if Z is not self._Z:                    # where the Python measurement reads them
            self._Z, self._rows = Z, {}

    def _normals(self, rng: np.random.Generator) -> np.ndarray:
        """The rows holding the coming measurement's normals from row ``state[2]`` on: the
        ``Z`` of :meth:`draw_step`, else its own rows, drawn now (row 0)."""
        if self.state[2] >= 0:
            return self._Z
        self.state[2] = 0
        if self.noise > 0.0:
            rng.standard_normal(out=_flat(self._own[:1 + self.state[3]]))
        return self._own

    def step(self, true_obs: np.ndarray, rng: np.random.Generator,
             U: np.ndarray | None = None) -> np.ndarray:
        """Measure ``true_obs`` (normalised, as the kernel wrote it) and return the float32
        observation the agent sees now; the displacement noise sample goes to the controls ``U``
        (the physics' sensed displacement until the next measurement) when given."""
        if U is not None and self.compiled:
            # one compiled call, the same numbers as step_python (the supervisor's orbit
            # entries take the Python path)
            out = np.empty(true_obs.shape[0], dtype=np.float32)
            _sense(true_obs, self._normals(rng), self.z, self._sigma, self._cols, U,
                   self.noise_control, self.noise, self.buffer, self.state, self.time_col, out)
            return out
        return self.step_python(true_obs, rng, U)

    def measurer(self, true_obs: np.ndarray, Z: np.ndarray, U: np.ndarray):
        """:meth:`step` on an environment's arrays after each :meth:`draw_step` into ``Z`` (or
        without noise), bound to them (:func:`physics.jit.bound`): a callable returning the
        observation (given the environment's random generator); None with the supervisor's
        orbit entries (they take :meth:`step`)."""
        if not self.compiled:
            return None
        out = np.empty(true_obs.shape[0], dtype=np.float32)
        call = bound(_sense, true_obs, Z, self.z, self._sigma, self._cols, U, self.noise_control,
                     self.noise, self.buffer, self.state, self.time_col, out)
        return partial(self._measured, call, out, true_obs, U)

    def _measured(self, call, out: np.ndarray, true_obs: np.ndarray, U: np.ndarray,
                  rng: np.random.Generator) -> np.ndarray:
        """The bound measurement ``call`` (:meth:`measurer`): a fresh copy of its observation
        ``out``; :meth:`step` when no :meth:`draw_step` drew its normals."""
        if self.noise > 0.0 and self.state[2] < 0:
            return self.step(true_obs, rng, U)
        call()
        return out.copy()

    def step_python(self, true_obs: np.ndarray, rng: np.random.Generator,
                    U: np.ndarray | None = None) -> np.ndarray:
        """:meth:`step` in numpy (any settings; the reference of its compiled path)."""
        m = self._measure(true_obs, rng, U)
        L = len(self.buffer)
        n = self.n
        self.buffer[n % L] = m
        if n == 0:
            self.buffer[:] = m
        out = self.buffer[(n - min(self.k, n)) % L].astype(np.float32)
        out[self.time_col] = true_obs[self.time_col]
        self.state[0] += 1
        self.state[2] = -1
        return out

    def _draw(self, rng: np.random.Generator) -> np.ndarray:
        """The measurement's standard normals: 4 of the displacement noise (a fresh sample at a
        sample instant, else the one held: the last inside the step, if any), then 4 of the
        velocity estimates'."""
        rows, r = self._normals(rng), int(self.state[2])
        if self.fresh:
            self.z[:] = rows[r]
            r += 1
        elif r > 0:
            self.z[:] = rows[r - 1]
        return np.concatenate((self.z, rows[r]))

    def _measure(self, true_obs: np.ndarray, rng: np.random.Generator,
                 U: np.ndarray | None) -> np.ndarray:
        m = np.array(true_obs, dtype=np.float64)
        if self.noise > 0.0:
            z = self._draw(rng)
            m[self.cols] += self.sigma * z
            if U is not None:                   # x1, y1, x2, y2: the AMB axes' order
                U[self.noise_control:self.noise_control + 4] = self.noise * z[:4]
            if self.orbit is not None:
                self._orbit(m)
        return m

    def _orbit(self, m: np.ndarray) -> None:
        """Orbit radius and rate (supervisor entries) from the noisy displacements and
        velocities, as :func:`rotordrop_env.kernels.orbit_frame` computes them from the state."""
        phys = m[self.cols] * self.scale[self.cols]
        spin = 1.0 if m[self.speed_col] >= 0.0 else -1.0
        for k in range(2):
            px, py = phys[2 * k], phys[2 * k + 1]
            vx, vy = phys[4 + 2 * k], phys[5 + 2 * k]
            r = math.hypot(px, py)
            rate = spin * (px * vy - py * vx) / (r * r) if r > self.r_min else 0.0
            m[self.orbit[k]] = r / self.scale[self.orbit[k]]
            m[self.orbit[2 + k]] = rate / self.scale[self.orbit[2 + k]]


def _flat(rows: np.ndarray) -> np.ndarray:
    """``rows`` (contiguous) as one flat view (never a copy: the draws must land in them)."""
    flat = rows.view()
    flat.shape = (rows.size,)
    return flat


@njit
def plan_step(t0, dt, rate, Z, held, state):
    """The draws of a control step from ``t0`` (:meth:`Sensing.draw_step`): its n sensor sample
    instants strictly inside (:func:`physics.sensor.samples_inside`; t1 = t0 + dt, as the
    kernel computes it) and whether one falls at its end, recorded in ``state`` (the
    measurement's first row n, at its end, n); a step whose draws were not measured first
    leaves its last sample inside ``held``. Returns the rows of ``Z`` to draw: n, then the
    measurement's 1 (velocity) or, at a sample instant, 2 (a new displacement sample first)."""
    if state[2] >= 0 and state[4] > 0:
        for j in range(4):
            held[j] = Z[state[4] - 1, j]
    t1 = t0 + dt
    n = samples_inside(t0, t1, rate)[1]
    at_end = 1 if on_sample(t1, rate) else 0
    state[2] = n
    state[3] = at_end
    state[4] = n
    return n + at_end + 1


@njit
def plan_rows(rows, M, dt, rate, Z, HELD, STATE, counts):
    """:func:`plan_step` of the environments ``rows`` of a batch (``M``: their monitors, the
    step's start ``M[e, M_T]``): ``counts[i]``, the rows of ``Z[rows[i]]`` to draw."""
    for i in range(rows.shape[0]):
        e = rows[i]
        counts[i] = plan_step(M[e, M_T], dt, rate, Z[e], HELD[e], STATE[e])


@njit
def sense_rows(rows, OBS, Z, HELD, sigma, cols, U, noise_control, noise, BUFFER, STATE,
               time_col, OUT):
    """:func:`_sense` of the environments ``rows`` of a batch, their observations into
    ``OUT``."""
    for i in range(rows.shape[0]):
        e = rows[i]
        _sense(OBS[e], Z[e], HELD[e], sigma, cols, U[e], noise_control, noise, BUFFER[e],
               STATE[e], time_col, OUT[e])


@njit
def _sense(true_obs, Z, held, sigma, cols, U, noise_control, noise, buffer, state, time_col, out):
    """:meth:`Sensing.step` without the supervisor's orbit entries, compiled: the measurement
    (``true_obs`` + ``sigma`` z at ``cols``; the noise ``noise`` z of the 4 displacements into
    ``U``) into the latency ring ``buffer`` (all of it at the episode's first measurement,
    ``state[0]`` = 0) and the float32 observation of k = ``state[1]`` measurements ago (its
    ``time`` the present) into ``out``. z: the 4 displacement normals ``held`` (at a sample
    instant, ``state[3]``, the new ones of row r = ``state[2]`` of ``Z``; else the last sample
    inside the step, row r - 1, if any), then the 4 velocity normals of the next row; ``held``
    keeps the displacement's; ``state[0]`` += 1, ``state[2]`` = -1."""
    L = buffer.shape[0]
    n = state[0]
    k = state[1]
    row = n % L
    for i in range(true_obs.shape[0]):
        buffer[row, i] = true_obs[i]
    if cols.shape[0] > 0:
        r = state[2]
        if state[3]:
            for j in range(4):
                held[j] = Z[r, j]
            r += 1
        elif r > 0:
            for j in range(4):
                held[j] = Z[r - 1, j]
        for j in range(4):                  # x1, y1, x2, y2: the AMB axes' order
            buffer[row, cols[j]] += sigma[j] * held[j]
            buffer[row, cols[4 + j]] += sigma[4 + j] * Z[r, j]
            U[noise_control + j] = noise * held[j]
    if n == 0:
        for q in range(L):
            if q != row:
                for i in range(true_obs.shape[0]):
                    buffer[q, i] = buffer[row, i]
    src = (n - min(k, n)) % L
    for i in range(true_obs.shape[0]):
        out[i] = buffer[src, i]
    out[time_col] = true_obs[time_col]
    state[0] = n + 1
    state[2] = -1


class SensingRows:
    """The sensing of a batch's environments (one id and settings, compiled measurements:
    :attr:`Sensing.compiled`) on stacked arrays: each environment's :class:`Sensing` keeps views
    of its rows (its own numbers: its reset, latency and measurement work on them as a single
    environment's), and the batch plans and measures a step of every row in one compiled call
    each (:func:`plan_rows`, :func:`sense_rows`), with the draws from each environment's own
    generator between them: the numbers of each environment stepped alone."""

    def __init__(self, sensings: list[Sensing], stack):
        self.sensings = sensings
        first = sensings[0]
        self.noise = first.noise
        self.z = np.stack([s.z for s in sensings])
        self.state = np.stack([s.state for s in sensings])
        self.buffer = np.stack([s.buffer for s in sensings])
        self.rows = np.arange(len(sensings))
        self.counts = np.zeros(len(sensings), dtype=np.int64)
        self.out = np.zeros(stack.obs.shape, dtype=np.float32)
        self.attach(stack)

    def attach(self, stack) -> None:
        """Give each environment's sensing the views of its rows, and take the batch's
        ``stack`` (:class:`rotordrop_env.buffers.Buffers`): again after a copy."""
        for e, s in enumerate(self.sensings):
            s.z, s.state, s.buffer = self.z[e], self.state[e], self.buffer[e]
        self.stack = stack
        self._views: list[dict] = [{} for _ in self.sensings]     # flat views of Z's rows
        self._plan = self._sense = None                           # bound at first use

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        state["_views"], state["_plan"], state["_sense"] = [], None, None
        return state

    def draw(self, rngs: list, rows: np.ndarray | None = None) -> None:
        """Before a batch step: each environment's draws (:meth:`Sensing.draw_step`) from its
        generator in ``rngs``, for all rows or the rows ``rows``."""
        if self.noise == 0.0:
            return
        st, first = self.stack, self.sensings[0]
        if rows is None:
            if self._plan is None:
                self._plan = bound(plan_rows, self.rows, st.M, first.dt, first.rate, st.Z, self.z,
                                   self.state, self.counts)
            self._plan()
            rows = self.rows
        else:
            plan_rows(rows, st.M, first.dt, first.rate, st.Z, self.z, self.state, self.counts)
        for e, count in zip(rows.tolist(), self.counts.tolist()):
            flat = self._views[e].get(count)
            if flat is None:
                flat = self._views[e][count] = _flat(st.Z[e, :count])
            rngs[e].standard_normal(out=flat)

    def measure(self, rows: np.ndarray | None = None) -> np.ndarray:
        """After a batch step: every row's measurement (or the rows ``rows``'), its float32
        observation in the rows of :attr:`out` (overwritten by the next step)."""
        st, first = self.stack, self.sensings[0]
        args = (st.obs, st.Z, self.z, first._sigma, first._cols, st.U, first.noise_control,
                first.noise, self.buffer, self.state, first.time_col, self.out)
        if rows is not None:
            sense_rows(rows, *args)
        else:
            if self._sense is None:
                self._sense = bound(sense_rows, self.rows, *args)
            self._sense()
        return self.out
