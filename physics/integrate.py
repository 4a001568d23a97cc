"""Dormand-Prince 5(4) integration of the model: adaptive or fixed step, dense output.

One kernel serves both modes; it stops exactly at the segment end (the driver splits the run at
the fault time and at control steps) and samples the solution at requested output times with
the method's 4th-order continuous extension. It never raises: it returns a status code that
the Python layer turns into a clear error.
"""
import math

import numpy as np

from ._jit import njit, njit_borrow
from .amb import reads_sensor
from .layout import Slots
from .model import A_FR, A_LOAD, A_QMAX, F_SENSOR, N_AUX, N_AUX_PLANE, P_SENS_RATE, P_SENS_SIGMA, rhs
from .sensor import hold_noise, samples_inside

# step-resolved peaks per retainer plane k at peaks[k * N_PEAK + j]: contact force, bearing
# load, largest ball load
PEAKS = Slots("peak")
P_FR, P_LOAD, P_QMAX = PEAKS.add_each("contact_force", "bearing_load", "ball_load_max")
N_PEAK = PEAKS.freeze().size

OK, STEP_COLLAPSE, TOO_MANY_STEPS, NOT_FINITE = 0, 1, 2, 3
SAMPLE_BLOCK = 64       # output samples per block of sample_diagnostics' column-major copies

# Butcher tableau (Dormand & Prince 1980) and dense-output polynomial (Hairer et al.)
_C = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0])
_A = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [1 / 5, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3 / 40, 9 / 40, 0.0, 0.0, 0.0, 0.0],
    [44 / 45, -56 / 15, 32 / 9, 0.0, 0.0, 0.0],
    [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0.0, 0.0],
    [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656, 0.0],
    [35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84],
])
_E = np.array([-71 / 57600, 0.0, 71 / 16695, -71 / 1920, 17253 / 339200, -22 / 525, 1 / 40])
_PD = np.array([
    [1.0, -8048581381 / 2820520608, 8663915743 / 2820520608, -12715105075 / 11282082432],
    [0.0, 0.0, 0.0, 0.0],
    [0.0, 131558114200 / 32700410799, -68118460800 / 10900136933, 87487479700 / 32700410799],
    [0.0, -1754552775 / 470086768, 14199869525 / 1410260304, -10690763975 / 1880347072],
    [0.0, 127303824393 / 49829197408, -318862633887 / 49829197408, 701980252875 / 199316789632],
    [0.0, -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844],
    [0.0, 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423],
])


@njit
def _dense(th, j):
    """Weight of stage j in the continuous extension at theta = th (over th h)."""
    return _PD[j, 0] + th * (_PD[j, 1] + th * (_PD[j, 2] + th * _PD[j, 3]))


@njit
def integrate_segment(y, t0, t1, P, I, U, rtol, atol, h, h_max, h_min, fixed, max_steps,
                      t_out, Y_out, out_pos, work, peaks=None, clock=None):
    """Advance ``y`` (in place) from t0 to exactly t1: :func:`integrate_segment_into` with a
    diagnostics scratch array of its own (its arguments and return values)."""
    return integrate_segment_into(y, t0, t1, P, I, U, rtol, atol, h, h_max, h_min, fixed,
                                  max_steps, t_out, Y_out, out_pos, work, np.empty(N_AUX), peaks,
                                  clock)


@njit_borrow
def integrate_segment_into(y, t0, t1, P, I, U, rtol, atol, h, h_max, h_min, fixed, max_steps,
                           t_out, Y_out, out_pos, work, aux, peaks=None, clock=None):
    """Advance ``y`` (in place) from t0 to exactly t1.

    Samples the solution into ``Y_out[out_pos:]`` for every ``t_out[j]`` in (t0, t1].
    ``work`` is a (9, n) scratch array (stages, a trial state and a sum) and ``aux`` an
    (N_AUX,) one (the right-hand side's diagnostics of each evaluation),
    so nothing is allocated: the kernel is compiled without reference counting
    (:data:`physics._jit.njit_borrow`; its stage rows are views at no cost). ``peaks`` (optional, (2 N_PEAK,)) keeps the running maxima of the contact force,
    bearing load and largest ball load per retainer plane at every accepted step end (the
    first-same-as-last stage's diagnostics), whatever the output rate; without it the branch is
    compiled out. ``clock`` (optional, (1,)) receives the time reached after every accepted
    step, for a progress bar read by another thread. Returns (status, t reached, next step size, output position, rhs calls,
    steps, rejected steps).
    """
    n = y.shape[0]
    K = work[:7]
    ytry = work[7]
    acc = work[8]
    n_rhs = 0
    n_steps = 0
    n_rej = 0
    t = t0
    err_old = 1e-4
    h = min(h, h_max, t1 - t0)
    rhs(t, y, P, I, U, K[0], aux)
    n_rhs += 1
    n_out = t_out.shape[0]
    while out_pos < n_out and t_out[out_pos] <= t0:
        out_pos += 1
    while t < t1:
        if n_steps >= max_steps:
            return TOO_MANY_STEPS, t, h, out_pos, n_rhs, n_steps, n_rej
        last = t + h >= t1 - 1e-15 * abs(t1)
        h_free = h
        if last:
            h = t1 - t
        # stages 2..7 (the 7th is evaluated at the new point: first-same-as-last)
        for s in range(1, 7):
            # j outer, i inner (contiguous, vectorised), the first and last terms fused into the
            # passes around them; per i: 0.0 + a_s0 k_0 + ... + a_s,s-1 k_s-1, in this order
            if s == 1:
                for i in range(n):
                    ytry[i] = y[i] + h * (0.0 + _A[1, 0] * K[0, i])
            else:
                a = _A[s, 0]
                for i in range(n):
                    acc[i] = 0.0 + a * K[0, i]
                for j in range(1, s - 1):
                    a = _A[s, j]
                    for i in range(n):
                        acc[i] += a * K[j, i]
                a = _A[s, s - 1]
                for i in range(n):
                    ytry[i] = y[i] + h * (acc[i] + a * K[s - 1, i])
            rhs(t + _C[s] * h, ytry, P, I, U, K[s], aux)
        n_rhs += 6
        n_steps += 1
        err = 0.0
        finite = True
        a = _E[0]
        for i in range(n):
            acc[i] = 0.0 + a * K[0, i]
        for j in range(1, 6):
            a = _E[j]
            for i in range(n):
                acc[i] += a * K[j, i]
        a = _E[6]
        for i in range(n):                  # scaled errors (vectorised), then summed in order
            sc = atol[i] + rtol * max(abs(y[i]), abs(ytry[i]))
            acc[i] = h * (acc[i] + a * K[6, i]) / sc
        for i in range(n):
            err += acc[i] * acc[i]
            if not math.isfinite(ytry[i]):
                finite = False
        err = math.sqrt(err / n)
        if not finite or not math.isfinite(err):
            if fixed:
                return NOT_FINITE, t, h, out_pos, n_rhs, n_steps, n_rej
            err = 1e10
        if fixed or err <= 1.0:
            t_new = t1 if last else t + h
            # dense output for samples in (t, t_new]
            while out_pos < n_out and t_out[out_pos] <= t_new:
                th = (t_out[out_pos] - t) / h
                b0, b2, b3 = _dense(th, 0), _dense(th, 2), _dense(th, 3)
                b4, b5, b6 = _dense(th, 4), _dense(th, 5), _dense(th, 6)
                for i in range(n):                 # one pass, the stages summed in order
                    a = 0.0
                    a += K[0, i] * th * b0
                    a += K[2, i] * th * b2
                    a += K[3, i] * th * b3
                    a += K[4, i] * th * b4
                    a += K[5, i] * th * b5
                    a += K[6, i] * th * b6
                    Y_out[out_pos, i] = y[i] + h * a
                out_pos += 1
            for i in range(n):
                y[i] = ytry[i]
                K[0, i] = K[6, i]
            t = t_new
            if clock is not None:
                clock[0] = t
            if peaks is not None:               # aux holds the diagnostics at t_new (stage 7)
                for k in range(2):
                    o, q = k * N_AUX_PLANE, k * N_PEAK
                    peaks[q + P_FR] = max(peaks[q + P_FR], aux[o + A_FR])
                    peaks[q + P_LOAD] = max(peaks[q + P_LOAD], aux[o + A_LOAD])
                    peaks[q + P_QMAX] = max(peaks[q + P_QMAX], aux[o + A_QMAX])
            if not fixed:
                # PI step control (Hairer & Wanner IV.2, beta = 0.06): half the rejections of DOPRI5's
                # beta = 0.04 in the drops, whose steps sit near the stability limit, at the same work
                fac = 10.0 if err == 0.0 else min(10.0, max(0.2, 0.9 * err ** -0.15 * err_old ** 0.06))
                err_old = max(err, 1e-4)
                h = min(h * fac, h_max)
                if last:
                    h = max(h, min(h_free, h_max))
        else:
            n_rej += 1
            h = h * min(1.0, max(0.2, 0.9 * err ** -0.2))
            if h < h_min:
                return STEP_COLLAPSE, t, h, out_pos, n_rhs, n_steps, n_rej
    return OK, t, h, out_pos, n_rhs, n_steps, n_rej


@njit_borrow
def integrate_sensed(y, t0, t1, P, I, U, Z, rtol, atol, h, h_max, h_min, fixed, max_steps,
                     t_out, Y_out, out_pos, work, aux):
    """:func:`integrate_segment_into` from t0 to t1 with the sensor noise held per sensor sample
    (physics/sensor.py): split at the n sample instants inside (t0, t1), the held sample
    U_SENS_NOISE set to sensor.noise x ``Z[i]`` (standard normals, the AMB axes' order) from the
    i-th of them on. Without noise it is one call of :func:`integrate_segment_into` (nothing split,
    ``Z`` unread); so it is when nothing inside the model reads the noise during the step (the
    AMBs driven by direct coil currents or unpowered: :func:`physics.amb.reads_sensor`), the
    last sample of the step then held at its end for what reads it there (the observations).
    Like :func:`integrate_segment_into`, it allocates nothing (``aux``: the diagnostics
    scratch). Returns what that returns (the counts summed over the pieces)."""
    if not I[F_SENSOR] or P[P_SENS_SIGMA] == 0.0:
        return integrate_segment_into(y, t0, t1, P, I, U, rtol, atol, h, h_max, h_min, fixed,
                                      max_steps, t_out, Y_out, out_pos, work, aux)
    rate = P[P_SENS_RATE]
    k0, n = samples_inside(t0, t1, rate)
    if not reads_sensor(I, U):
        res = integrate_segment_into(y, t0, t1, P, I, U, rtol, atol, h, h_max, h_min, fixed,
                                     max_steps, t_out, Y_out, out_pos, work, aux)
        if n > 0 and res[0] == OK:
            hold_noise(Z[n - 1], P, U)
        return res
    t = t0
    h_next = h
    n_rhs = n_steps = n_rej = 0
    for i in range(n + 1):
        ta = t1 if i == n else (k0 + 1 + i) / rate
        if ta > t:
            status, t, h_ret, out_pos, a, b, c = integrate_segment_into(
                y, t, ta, P, I, U, rtol, atol, h_next, h_max, h_min, fixed, max_steps, t_out,
                Y_out, out_pos, work, aux)
            n_rhs += a
            n_steps += b
            n_rej += c
            if status != OK:
                return status, t, h_ret, out_pos, n_rhs, n_steps, n_rej
            if not fixed:                  # a fixed step keeps its size (the last one is cut)
                h_next = h_ret
        if i < n:
            hold_noise(Z[i], P, U)
    return OK, t, h_next if not fixed else h, out_pos, n_rhs, n_steps, n_rej


@njit_borrow
def sample_diagnostics(T, Y, i0, i1, P, I, U, AUX, Y_cols, block):
    """``AUX[k]``: the right-hand side's per-plane diagnostics at output sample ``k`` (time
    ``T[k]``, state ``Y[k]``, the integrator's row-major output) for k in [i0, i1), with
    controls ``U``; and ``Y_cols[k] = Y[k]``: ``Y_cols`` and ``AUX`` are column-major, the layout
    the metrics read (whole time series of single states), written here, after the integration,
    in blocks of ``SAMPLE_BLOCK`` samples (a column-major write per sample touches a cache line
    per column) through ``block`` ((SAMPLE_BLOCK, N_AUX) scratch, row-major). The values are
    those of :func:`physics.model.diagnostics`. Allocates nothing, so it is compiled without
    reference counting (:data:`physics._jit.njit_borrow`): the rows ``Y[k]`` and ``block[k]``
    are passed to ``rhs`` as views at no cost."""
    n = Y.shape[1]
    for k0 in range(i0, i1, SAMPLE_BLOCK):
        m = min(SAMPLE_BLOCK, i1 - k0)
        for k in range(m):
            rhs(T[k0 + k], Y[k0 + k], P, I, U, None, block[k])     # diagnostics only
        for j in range(N_AUX):
            for k in range(m):
                AUX[k0 + k, j] = block[k, j]
        for i in range(n):
            for k in range(m):
                Y_cols[k0 + k, i] = Y[k0 + k, i]
