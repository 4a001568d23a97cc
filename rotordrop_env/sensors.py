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

import numpy as np

from physics.jit import njit
from physics.sensor import on_sample, samples_inside

from .kernels import SUP_MIN_RADIUS
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
    ``clearance`` [m] for the orbit's dead zone."""

    def __init__(self, noise: float, latency: tuple[int, int], obs_names, obs_scale,
                 clearance: float, noise_control: int, sample_rate: float = 1e4,
                 control_dt: float = 1e-3):
        names = list(obs_names)
        self.noise, self.latency = noise, latency
        self.rate, self.dt = sample_rate, control_dt
        self.z = np.zeros(4)                    # standard normals of the held noise sample
        self.fresh = True                       # a sample instant at the coming measurement
        self.last_drawn = 0                     # samples inside the last step (draw_step)
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
        self.k = 0
        self.n = 0                      # measurements taken this episode

    @property
    def n_noise(self) -> int:
        """The most sensor samples strictly inside one control step (rows of the kernel's
        ``Z``); 0 without noise."""
        return math.ceil(self.dt * self.rate) + 1 if self.noise > 0.0 else 0

    def reset(self, true_obs: np.ndarray, rng: np.random.Generator,
              U: np.ndarray | None = None) -> np.ndarray:
        """Start an episode: draw its latency k, take the first measurement (with a fresh
        noise sample: the sensor's sample current at the episode's start)."""
        lo, hi = self.latency
        self.k = int(rng.integers(lo, hi + 1)) if hi > lo else lo
        self.n = 0
        self.fresh = True
        return self.step(true_obs, rng, U)

    def draw_step(self, t0: float, Z: np.ndarray, rng: np.random.Generator) -> int:
        """Before a control step from ``t0``: the standard normals of the noise samples at the
        sensor's sample instants strictly inside the step into ``Z`` (the kernel holds them in
        turn, :func:`physics.integrate.integrate_sensed`); a sample at the step's end is drawn
        by the measurement after it. Returns their number (0, nothing drawn, without noise)."""
        if self.noise == 0.0:
            return 0
        t1 = t0 + self.dt                       # as the kernel computes it
        _, n = samples_inside(t0, t1, self.rate)
        self.last_drawn = n
        if n > 0:
            Z[:n] = rng.standard_normal((n, 4))
            self.z = Z[n - 1].copy()
        self.fresh = bool(on_sample(t1, self.rate))
        return n

    def _draw(self, rng: np.random.Generator) -> np.ndarray:
        """The measurement's standard normals: 4 of the displacement noise (a fresh sample at a
        sample instant, else the held one), then 4 of the velocity estimates'."""
        if self.fresh:
            z = rng.standard_normal(len(self.cols))
            self.z = z[:4].copy()
            return z
        return np.concatenate((self.z, rng.standard_normal(len(self.cols) - 4)))

    def step(self, true_obs: np.ndarray, rng: np.random.Generator,
             U: np.ndarray | None = None) -> np.ndarray:
        """Measure ``true_obs`` (normalised, as the kernel wrote it) and return the float32
        observation the agent sees now; the displacement noise sample goes to the controls ``U``
        (the physics' sensed displacement until the next measurement) when given."""
        if U is not None and (self.noise == 0.0 or self.orbit is None):
            # one compiled call, the same numbers as step_python (the supervisor's orbit
            # entries take the Python path)
            z = self._draw(rng) if self.noise > 0.0 else _NO_DRAW
            out = np.empty(true_obs.shape[0], dtype=np.float32)
            _sense(true_obs, z, self._sigma, self._cols, U, self.noise_control, self.noise,
                   self.buffer, self.n, self.k, self.time_col, out)
            self.n += 1
            return out
        return self.step_python(true_obs, rng, U)

    def step_python(self, true_obs: np.ndarray, rng: np.random.Generator,
                    U: np.ndarray | None = None) -> np.ndarray:
        """:meth:`step` in numpy (any settings; the reference of its compiled path)."""
        m = self._measure(true_obs, rng, U)
        L = len(self.buffer)
        self.buffer[self.n % L] = m
        if self.n == 0:
            self.buffer[:] = m
        out = self.buffer[(self.n - min(self.k, self.n)) % L].astype(np.float32)
        out[self.time_col] = true_obs[self.time_col]
        self.n += 1
        return out

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


_NO_DRAW = np.zeros(0)


@njit
def _sense(true_obs, z, sigma, cols, U, noise_control, noise, buffer, n, k, time_col, out):
    """:meth:`Sensing.step` without the supervisor's orbit entries, compiled: the measurement
    (``true_obs`` + ``sigma`` z at ``cols``; the noise ``noise`` z of the 4 displacements into
    ``U``) into the latency ring ``buffer`` (all of it at the episode's first measurement, n =
    0) and the float32 observation of k measurements ago (its ``time`` the present) into ``out``."""
    L = buffer.shape[0]
    row = n % L
    for i in range(true_obs.shape[0]):
        buffer[row, i] = true_obs[i]
    for j in range(cols.shape[0]):
        buffer[row, cols[j]] += sigma[j] * z[j]
    if cols.shape[0] > 0:
        for j in range(4):                  # x1, y1, x2, y2: the AMB axes' order
            U[noise_control + j] = noise * z[j]
    if n == 0:
        for r in range(L):
            if r != row:
                for i in range(true_obs.shape[0]):
                    buffer[r, i] = buffer[row, i]
    src = (n - min(k, n)) % L
    for i in range(true_obs.shape[0]):
        out[i] = buffer[src, i]
    out[time_col] = true_obs[time_col]
