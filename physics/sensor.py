"""Position sensing at the AMB planes (scene group ``sensor``; docs/physics.md "Position sensing").

What the built-in AMB controller (the actuator's PID, the linear law), the supervisor's orbit
frame and the environments' observations see of the displacement d of one AMB axis::

    d_s(t) = d(t - tau) + n_k,   t in [t_k, t_k+1)

* **Delay** tau = ``sensor.delay`` (sensor electronics, anti-alias filter, sampling and one or
  two controller samples), as its (2,2) Padé approximant, an all-pass with unit gain::

      e^{-s tau} ~ (1 - s tau/2 + (s tau)^2/12) / (1 + s tau/2 + (s tau)^2/12) = 1 - s tau / D(s)

  realised with two states per axis, both in metres (w = d / D(s): q1 = w, q2 = tau w')::

      q1' = q2 / tau,   q2' = (12 / tau) (d - q1 - q2 / 2),   d(t - tau) ~ d - q2,
      d'(t - tau) ~ d' - q2'                                                       (S1)

  Phase -2 atan((w tau / 2) / (1 - (w tau)^2 / 12)) against the exact -w tau
  (:func:`pade_phase`): short by 0.07 deg at w tau = 1, 0.65 deg at pi/2 (f = 1/(4 tau)), 2.0 deg
  at 2, 13 deg at pi (f = 1/(2 tau)); the first-order approximant is short by 4.2 deg at w tau = 1
  and 14 deg at pi/2. With tau <= 0.2 ms, w tau = 1 is 800 Hz, beyond the PID's crossover and
  the rotor's 167 Hz spin. Its poles (-3 +- i sqrt(3)) / tau are what limits the explicit
  integrator's step (h ~ tau), which a higher order would only make faster.
* **Noise** n_k: one Gaussian sample of standard deviation sigma = ``sensor.noise`` per axis
  at each sensor sample instant t_k = k / f_s (f_s = ``sensor.sample_rate``), held until the
  next (zero-order hold), whatever the step of the one who reads it: the built-in PID, the
  supervisor's orbit frame and the observations all see the sample current at their time. The
  held sample is the U entries ``U_SENS_NOISE``; a control step that spans sample instants is
  integrated in pieces split there when the AMBs' law reads them (:func:`physics.integrate.integrate_sensed`;
  driven by direct coil currents nothing inside the model does, and the step is one piece), the entries
  set between pieces from standard normals the environments draw from their ``np_random``
  (:func:`samples_inside` says how many), so the kernel stays deterministic given its inputs.

The actuator's PID differentiates the sensed error d_s - ref through its derivative filter
(physics/amb.py), so it sees both the delay and the held noise's steps; the linear AMB law
(an idealised stiffness and damping) takes the delayed velocity without the noise.

Off (both zero) the model has no sensing state and the kernel reads the true displacement.
"""
from __future__ import annotations

import math

from ._jit import njit, njit_inline
from .rotor import ST_AMB1, axis_motion

#: states per AMB plane: q1, q2 of the x axis, then of the y axis (S1)
STATES_PER_PLANE = 4
SCENE_KEYS = ("sensor.delay", "sensor.noise", "sensor.sample_rate")
#: sample instants closer than this fraction of a sample period to a time count as at it
SAMPLE_TOL = 1e-6
#: the AMB axes whose displacement is sensed (the order of the delay states and noise controls)
AXES = ("AMB1.x", "AMB1.y", "AMB2.x", "AMB2.y")


def declare(layout) -> None:
    """The delay tau, the sensing flag (on when sensor.delay or sensor.noise > 0), the first
    delay state's slot, and the held noise samples ``sensor.noise`` + j [m] of AMB axis j that
    the sensed displacement carries until the next sample."""
    layout.params.add("sensor.delay", const="P_SENS_TAU")
    layout.params.add("sensor.noise", const="P_SENS_SIGMA")
    layout.params.add("sensor.sample_rate", const="P_SENS_RATE")
    layout.index.add("flag.sensor", const="F_SENSOR")
    layout.index.add("state.sensor", const="I_SENS")
    layout.controls.add("sensor.noise", len(AXES), const="U_SENS_NOISE")


def pack(scene, P, I, layout) -> None:
    I[layout.index["flag.sensor"]] = scene.sensor.delay > 0.0 or scene.sensor.noise > 0.0
    P[layout.params["sensor.delay"]] = scene.sensor.delay
    P[layout.params["sensor.noise"]] = scene.sensor.noise
    P[layout.params["sensor.sample_rate"]] = scene.sensor.sample_rate


def states(scene, I, layout, sizes, add) -> None:
    """The Pade delay states q1, q2 per AMB axis (only with sensor.delay)."""
    if scene.sensor.delay <= 0.0:
        return
    first = -1
    for ax in AXES:
        i = add(f"{ax}.sensor_q1", sizes.clearance)
        add(f"{ax}.sensor_q2", sizes.clearance)
        first = i if first < 0 else first
    I[layout.index["state.sensor"]] = first


@njit
def pade_rates(d, q1, q2, tau):
    """(q1', q2') of an axis's delay states (S1) at the true displacement ``d``."""
    return q2 / tau, 12.0 / tau * (d - q1 - 0.5 * q2)


@njit
def delay_rates(dx, dy_, y, i, tau, dy):
    """Write the rates of one AMB plane's delay states y[i:i + 4] (x axis q1, q2, then y axis)
    at the true displacements (dx, dy_) into ``dy``."""
    dy[i], dy[i + 1] = pade_rates(dx, y[i], y[i + 1], tau)
    dy[i + 2], dy[i + 3] = pade_rates(dy_, y[i + 2], y[i + 3], tau)


@njit
def delayed(d, v, q1, q2, tau):
    """(d(t - tau), d'(t - tau)) of the (2,2) Padé approximant (S1), from the true displacement
    ``d`` and velocity ``v`` and the axis's delay states."""
    return d - q2, v - 12.0 / tau * (d - q1 - 0.5 * q2)


@njit
def sample_index(t, rate):
    """Index k of the sensor sample current at time ``t`` (the last instant k / rate <= t)."""
    return math.floor(t * rate + SAMPLE_TOL)


@njit
def samples_inside(t0, t1, rate):
    """(k0, n): the sample current at t0 is k0, and n sample instants k / rate, k = k0 + 1 ...
    k0 + n, lie strictly inside (t0, t1) (one at t1 is the next step's first)."""
    k0 = sample_index(t0, rate)
    return k0, math.ceil(t1 * rate - SAMPLE_TOL) - 1 - k0


@njit
def on_sample(t, rate):
    """``t`` is a sensor sample instant."""
    x = t * rate
    return abs(x - round(x)) < SAMPLE_TOL


@njit
def hold_noise(z, P, U):
    """Hold the sample sigma z (z: 4 standard normals, the AMB axes' order) in U_SENS_NOISE."""
    for j in range(4):
        U[U_SENS_NOISE + j] = P[P_SENS_SIGMA] * z[j]


def steady_states(X: complex, omega: float, tau: float) -> tuple[complex, complex]:
    """Complex amplitudes (Q1, Q2) of the delay states on the periodic motion
    d = Re(X e^{j omega t}) (the levitated unbalance orbit); (X, 0) at rest."""
    s = 1j * omega
    W = X / (1.0 + s * tau / 2.0 + (s * tau) ** 2 / 12.0)
    return W, s * tau * W


def pade_response(omega: float, tau: float) -> complex:
    """The (2,2) Padé approximant of e^{-s tau} at s = j omega (1 for tau = 0)."""
    if tau <= 0.0:
        return 1.0 + 0j
    s = 1j * omega * tau
    return 1.0 - s / (1.0 + s / 2.0 + s * s / 12.0)


def pade_phase(omega: float, tau: float) -> float:
    """Phase [rad] of the (2,2) Padé approximant of e^{-s tau} at s = j omega (continuous past
    w tau = sqrt(12), where the denominator's real part changes sign)."""
    return -2.0 * math.atan2(omega * tau / 2.0, 1.0 - (omega * tau) ** 2 / 12.0)


# ----------------------------------------------------------------------------- kernels --
@njit_inline
def delayed_motion(y, P, I, k, px, py, vx, vy):
    """The true motion (px, py, vx, vy) of AMB plane k as its sensors' delay passes it on (the
    Pade states, S1); unchanged without ``sensor.delay``."""
    i = I[I_SENS]
    if i >= 0:
        i += STATES_PER_PLANE * k
        tau = P[P_SENS_TAU]
        px, vx = delayed(px, vx, y[i], y[i + 1], tau)
        py, vy = delayed(py, vy, y[i + 2], y[i + 3], tau)
    return px, py, vx, vy


@njit_inline
def sensed_motion(y, P, I, U, k, px, py, vx, vy):
    """What the sensors of AMB plane k report of its true motion (px, py, vx, vy): delayed, plus
    the held noise samples U_SENS_NOISE. Only called with I[F_SENSOR] set; the velocities carry
    the delay, not the noise."""
    px, py, vx, vy = delayed_motion(y, P, I, k, px, py, vx, vy)
    return px + U[U_SENS_NOISE + 2 * k], py + U[U_SENS_NOISE + 2 * k + 1], vx, vy


@njit_inline
def delay_states(y, P, I, dy):
    """The Pade delay states' rates (S1) of both AMB planes."""
    i_sens = I[I_SENS]
    tau = P[P_SENS_TAU]
    for k in range(2):
        dx, dyy, _, _ = axis_motion(y, P, I, ST_AMB1 + k)
        delay_rates(dx, dyy, y, i_sens + STATES_PER_PLANE * k, tau, dy)
