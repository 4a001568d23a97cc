"""Numba kernels of the environments: one control step (action -> physics -> monitor -> reward,
observation) for one rotor, and the same over N rotors in one parallel call.

Everything an episode needs lives in flat arrays so that the single environment and the batched
VecEnv run the very same code (the batch owns (N, ...) stacks, each environment a row view):

* ``C``  float64 configuration of the episode (indices ``C_*``), set at reset,
* ``M``  float64 running monitor (time, step size, whirl revolutions, peaks, re-levitation,
  whether and when a penetration passed its validity bound ``C_PEN_BOUND`` / ``C_STATOR_BOUND``
  of :func:`physics.validity.validity_bound`...),
* ``out`` float64 per-step results (reward and its terms, flags, status; indices ``O_*``).

The physics is :func:`physics.integrate.integrate_segment_into` on :func:`physics.model.rhs`; the
control step is sampled ``n_sub`` times (dense output) for the contact force, whirl and
re-levitation monitors, so short impacts and fast orbits are not missed between control steps.
"""
from __future__ import annotations

import math

import numba
import numpy as np

from physics.jit import njit, njit_borrow, njit_parallel
from physics.integrate import integrate_sensed
from physics.model import (A_FR, A_PFRIC, A_QMAX, A_WS, F_SENSOR, I_AMB_FILT, I_AMB_INT, I_CS,
                           N_AUX_PLANE, P_CLR, ST_AMB1, ST_RB1, S_W, U_AMB_DIRECT, U_AMB_GAIN,
                           U_AMB_POWER, U_CS1, U_ICMD, U_REF0, U_REF_OFF, U_T_ON, amb_currents,
                           axis_motion, delayed_motion, rhs, sensed_motion, sleeve_motion)

from .constraints import latch_validity, plane_events, step_events

# the kernel tables (also read as K.C_*, K.M_*... by the Python side)
from .slots import (  # noqa: F401
    CONFIG, C_DT, C_T_FAULT, C_T_END, C_T_POWER, C_DAMP, C_LEV, C_RTOL, C_HMAX, C_HMIN,
    C_FIXED, C_MAXSTEPS, C_W_WHIRL, C_W_CONTACT, C_W_DISP, C_W_EFFORT, C_W_SUCCESS,
    C_W_FAILURE, C_F_REF, C_GAP, C_LOAD_RATING, C_HOLD, C_FULL, C_CS_MIN, C_CS_MAX, C_ILIM,
    C_RELEV_RADIUS, C_WHIRL_RADIUS, C_WHIRL_REVS, C_SUP_OFFSET, C_SUP_OCTAVES, C_P_COEF,
    C_PEN_BOUND, C_STATOR_BOUND, C_ENDS, C_UNLATCHED, N_C, LEV_NONE, LEV_DISCRETE, LEV_CONTINUOUS,
    LEV_SUPERVISOR, DAMP_NONE, DAMP_LINEAR, DAMP_FROM_MAX, SUP_MIN_RADIUS, MONITOR, M_T, M_H,
    M_REV1, M_REV2, M_WHIRL, M_PEAK_F, M_MAX_DISP, M_OK_START, M_RELEV, M_RELEV_T, M_EFFORT,
    M_CTRL_ON, M_POWER, M_REV_PEAK, M_PEAK_Q, M_STATOR, M_OVERLOAD, M_BEYOND, M_LEFT_T, M_PHI,
    M_FRICTION, N_M, OUTPUTS, O_REWARD, O_R_WHIRL, O_R_CONTACT, O_R_DISP, O_R_EFFORT, O_R_SUCCESS,
    O_R_FAILURE, O_FORCE, O_TERM, O_TRUNC, O_STATUS, O_ERR, O_STATOR, O_OVERLOAD, O_RELEV,
    O_BEYOND, N_O, ERR_NONE, ERR_NAN, ERR_RANGE, INFO, V_FORCE, V_R_WHIRL, V_R_CONTACT,
    V_R_DISP, V_R_EFFORT, V_R_SUCCESS, V_R_FAILURE, V_TIME, V_COST, V_COST_STATOR,
    V_COST_OVERLOAD, V_COST_VALIDITY, V_WHIRL_REVS, V_WHIRL, V_PEAK_REVS, V_PEAK_F,
    V_MAX_DISP_UM, V_RELEV_T, V_RELEV, V_EFFORT, V_BALL_Q, V_PRESSURE_MPA, V_TIME_VALID,
    V_FRICTION,
    N_V_FLOAT, N_V, V_STATOR, V_OVERLOAD, V_BEYOND, MISSING)

ACTION_TOL = 1e-6            # actions may exceed [-1, 1] by this much (float32 round-off)
TWO_PI = 2.0 * math.pi


@njit
def _power_back(t, C):
    """AMB power has returned by time t (control-step round-off tolerated)."""
    return t >= C[C_T_POWER] - 1e-9 * C[C_DT]


@njit
def check_action(a, C):
    """ERR_NONE, ERR_NAN (non-finite entry) or ERR_RANGE (outside [-1, 1] / not 0 or 1)."""
    n = a.shape[0]
    for j in range(n):
        if not math.isfinite(a[j]):
            return ERR_NAN
        if a[j] < -1.0 - ACTION_TOL or a[j] > 1.0 + ACTION_TOL:
            return ERR_RANGE
    if int(C[C_LEV]) == LEV_DISCRETE and n == 1 and a[0] != 0.0 and a[0] != 1.0:
        return ERR_RANGE
    return ERR_NONE


@njit
def first_bad_action(A, C):
    """(row, error) of the first row of ``A`` that :func:`check_action` refuses, else (-1,
    ERR_NONE): the batch checks every action before it advances any environment."""
    for e in range(A.shape[0]):
        err = check_action(A[e], C[e])
        if err != ERR_NONE:
            return e, err
    return -1, ERR_NONE


@njit
def _switch_on(t, y, P, I, U):
    """Engage the built-in PID: ramp the reference from the sensed position (delayed and noisy
    with position sensing, physics/sensor.py), reset integrators."""
    U[U_AMB_POWER] = 1.0
    U[U_AMB_DIRECT] = 0.0
    U[U_T_ON] = t
    for j in range(4):
        px, py, vx, vy = axis_motion(y, P, I, ST_AMB1 + j // 2)
        if I[F_SENSOR]:
            px, py, _, _ = sensed_motion(y, P, I, U, j // 2, px, py, vx, vy)
        U[U_REF0 + j] = px if j % 2 == 0 else py
        y[I[I_AMB_INT] + j] = 0.0
        y[I[I_AMB_FILT] + j] = 0.0


@njit
def damper_fraction(a, mode):
    """(C - C_min) / (C_max - C_min) commanded by the damper action ``a`` (clipped to [-1, 1]):
    linear over the box (``DAMP_LINEAR``: 0 is mid-range), or full damping for every a >= 0
    and linear down to C_min at -1 (``DAMP_FROM_MAX``: the zero action is C_max)."""
    a = min(max(a, -1.0), 1.0)
    return 0.5 * (a + 1.0) if mode == DAMP_LINEAR else min(a + 1.0, 1.0)


@njit
def apply_action(a, y, P, I, U, C, M):
    """Map a checked action onto the controls U (and the PID reset).

    Returns the sum of squared normalised damper commands and the number of controlled channels
    (the currents' share of the effort is added after the step, from the applied currents)."""
    effort = 0.0
    n_eff = 0
    if C[C_DAMP] > 0.0:
        for k in range(2):                      # the damper commands come first
            frac = damper_fraction(a[k], C[C_DAMP])
            U[U_CS1 + k] = C[C_CS_MIN] + frac * (C[C_CS_MAX] - C[C_CS_MIN])
            effort += frac * frac
            n_eff += 1
    lev = int(C[C_LEV])
    if lev != LEV_NONE:
        t = M[M_T]
        if M[M_POWER] == 0.0 and _power_back(t, C):
            M[M_POWER] = 1.0
        o = 2 if C[C_DAMP] > 0.0 else 0          # after the damper commands, if any
        if M[M_POWER] > 0.0:
            if lev == LEV_DISCRETE or lev == LEV_SUPERVISOR:
                want = a[o] >= 0.5 if a.shape[0] == 1 else a[o] > 0.0
                if want and M[M_CTRL_ON] == 0.0:
                    _switch_on(t, y, P, I, U)
                    M[M_CTRL_ON] = 1.0
                if lev == LEV_SUPERVISOR and M[M_CTRL_ON] > 0.0:
                    supervise(a, o + 1, U, C)
            else:
                U[U_AMB_DIRECT] = 1.0
                for j in range(4):
                    U[U_ICMD + j] = min(max(a[o + j], -1.0), 1.0) * C[C_ILIM]
                M[M_CTRL_ON] = 1.0
        n_eff += 4
    return effort, n_eff


@njit
def orbit_frame(y, P, I, k):
    """Sensed orbit at AMB plane k: radius r [m] and angular rate relative to the spin direction
    [rad/s] (< 0: the orbit turns backwards; 0 below ``SUP_MIN_RADIUS`` x clearance, where the
    direction of the orbit is noise). With ``sensor.delay`` of the delayed motion; the noise is
    added by :mod:`rotordrop_env.sensors`, which recomputes these from the noisy values."""
    px, py, vx, vy = axis_motion(y, P, I, ST_AMB1 + k)
    px, py, vx, vy = delayed_motion(y, P, I, k, px, py, vx, vy)
    spin = 1.0 if y[I[S_W]] >= 0.0 else -1.0
    r = math.sqrt(px * px + py * py)
    rate = spin * (px * vy - py * vx) / (r * r) if r > SUP_MIN_RADIUS * P[P_CLR] else 0.0
    return r, rate


@njit
def retainer_orbits(Y, P, I, out):
    """The rotor axis (x, y) at retainer plane 1 and 2 in each state row of ``Y``, a flexible
    rotor's elastic motion included (:func:`physics.model.axis_motion`): ``out[j] = (x1, y1, x2,
    y2)`` [m], the episode view's orbits (:mod:`rotordrop_env.render`)."""
    for j in range(Y.shape[0]):
        for k in range(2):
            px, py, _, _ = axis_motion(Y[j], P, I, ST_RB1 + k)
            out[j, 2 * k] = px
            out[j, 2 * k + 1] = py


@njit
def supervise(a, o, U, C):
    """The supervisor's commands (action entries o: gain, o+1...o+4: radial and tangential
    offset of AMB plane 1 and 2) onto the built-in PID: gain scale 2^(a C_SUP_OCTAVES), reference
    offsets a x C_SUP_OFFSET along the radial and tangential axes of the sensed orbit, which
    the PID evaluates continuously (:func:`physics.model.orbit_offset`)."""
    U[U_AMB_GAIN] = 2.0 ** (C[C_SUP_OCTAVES] * min(max(a[o], -1.0), 1.0))
    for j in range(4):
        U[U_REF_OFF + j] = min(max(a[o + 1 + j], -1.0), 1.0) * C[C_SUP_OFFSET]


@njit
def observe(t, y, P, I, U, C, M, aux, cur, scale, obs):
    """Fill ``obs`` = physical values / scale (layout: see rotordrop_env.layout)."""
    n = 0
    if C[C_FULL] > 0.0:
        for i in range(y.shape[0]):
            obs[n] = y[i]
            n += 1
    else:
        for k in range(2):                      # as the sensors report it (delayed)
            px, py, vx, vy = axis_motion(y, P, I, ST_AMB1 + k)
            px, py, vx, vy = delayed_motion(y, P, I, k, px, py, vx, vy)
            obs[n], obs[n + 1], obs[n + 2], obs[n + 3] = px, py, vx, vy
            n += 4
        obs[n] = y[I[S_W]]
        obs[n + 1] = aux[A_WS]
        obs[n + 2] = aux[N_AUX_PLANE + A_WS]
        n += 3
        if C[C_DAMP] > 0.0:
            obs[n] = y[I[I_CS]]
            obs[n + 1] = y[I[I_CS] + 1]
            n += 2
    obs[n] = t - C[C_T_FAULT]
    n += 1
    if int(C[C_LEV]) != LEV_NONE:
        # power available for the next action (M_POWER latches only when that action is applied)
        obs[n] = 1.0 if _power_back(t, C) else 0.0
        obs[n + 1] = M[M_CTRL_ON]
        for j in range(4):
            obs[n + 2 + j] = cur[j]
        n += 6
        if int(C[C_LEV]) == LEV_SUPERVISOR:
            for k in range(2):
                r, rate = orbit_frame(y, P, I, k)
                obs[n + k] = r
                obs[n + 2 + k] = rate
            n += 4
    for i in range(n):
        obs[i] /= scale[i]


@njit
def observe_now(y, P, I, U, C, M, work, aux, cur, scale, obs):
    """Observation of the current state (used at reset)."""
    t = M[M_T]
    rhs(t, y, P, I, U, work[0], aux)
    if int(C[C_LEV]) != LEV_NONE:
        amb_currents(t, y, P, I, U, cur)
    observe(t, y, P, I, U, C, M, aux, cur, scale, obs)


@njit_borrow
def step_one(a, y, P, I, U, Z, atol, work, t_sub, Y_sub, aux, cur, C, M, scale, obs, out):
    """One control step of one environment (``Z``: standard normals of the sensor noise samples
    inside the step, drawn by :meth:`rotordrop_env.sensors.Sensing.draw_step`; unread without
    noise). Results go to ``obs`` and ``out``; nothing raises:
    ``out[O_ERR]`` flags a bad action (nothing is advanced), ``out[O_STATUS]`` an integrator
    failure (see physics.integrate status codes). It allocates nothing, so it is compiled without
    reference counting (:data:`physics.jit.njit_borrow`: its row views cost nothing; ~5 % of
    a 0.2 ms step)."""
    for i in range(N_O):
        out[i] = 0.0
    err = check_action(a, C)
    if err != ERR_NONE:
        out[O_ERR] = err
        return
    effort, n_eff = apply_action(a, y, P, I, U, C, M)

    dt = C[C_DT]
    t0 = M[M_T]
    t1 = t0 + dt
    n_sub = t_sub.shape[0]
    for k in range(n_sub):
        t_sub[k] = t0 + dt * (k + 1) / n_sub
    t_sub[n_sub - 1] = t1
    status, t_end, h, _, _, _, _ = integrate_sensed(
        y, t0, t1, P, I, U, Z, C[C_RTOL], atol, M[M_H], C[C_HMAX], C[C_HMIN], C[C_FIXED] > 0.0,
        int(C[C_MAXSTEPS]), t_sub, Y_sub, 0, work, aux)
    if status != 0:                             # y is at t_end: report where and with what step
        out[O_STATUS] = status
        M[M_T] = t_end
        M[M_H] = h
        return
    if C[C_FIXED] == 0.0:
        M[M_H] = h
    for i in range(y.shape[0]):
        Y_sub[n_sub - 1, i] = y[i]

    # ---- monitors at the sub-samples ----
    clr = P[P_CLR]
    spin = 1.0 if y[I[S_W]] >= 0.0 else -1.0
    dts = dt / n_sub
    f_step = 0.0
    q_step = 0.0
    disp_step = 0.0
    back = 0.0
    stator = False
    beyond = False
    lev = int(C[C_LEV])
    for s in range(n_sub):
        ys = Y_sub[s]
        ts = t_sub[s]
        rhs(ts, ys, P, I, U, None, aux)        # the diagnostics alone (the same bits)
        ok = M[M_POWER] > 0.0
        for k in range(2):
            fr = aux[k * N_AUX_PLANE + A_FR]
            f_step = max(f_step, fr)
            M[M_FRICTION] += abs(aux[k * N_AUX_PLANE + A_PFRIC]) * dts    # rectangle rule
            q_step = max(q_step, aux[k * N_AUX_PLANE + A_QMAX])
            px, py, pvx, pvy = axis_motion(ys, P, I, ST_RB1 + k)
            sx, sy, svx, svy = sleeve_motion(ys, I, k)
            r_abs = math.sqrt(px * px + py * py)
            disp_step = max(disp_step, r_abs)
            ex, ey = px - sx, py - sy
            r2 = ex * ex + ey * ey
            if r2 > (C[C_WHIRL_RADIUS] * clr) ** 2:  # orbit angle, beyond part of the clearance
                dth = (ex * (pvy - svy) - ey * (pvx - svx)) / r2 * dts
                db = -spin * dth / TWO_PI
                M[M_REV1 + k] += db
                back += 0.5 * db
            if fr > 0.0 or r_abs >= C[C_RELEV_RADIUS]:
                ok = False
            at_stator, past_bound = plane_events(ys, P, I, aux, k, C)     # the constraints
            if at_stator:
                stator = True
            if past_bound:
                beyond = True
        latch_validity(beyond, ts, M)
        if lev != LEV_NONE and (M[M_RELEV] == 0.0 or C[C_UNLATCHED] > 0.0):
            if ok:
                if M[M_OK_START] < 0.0:
                    M[M_OK_START] = ts
                if M[M_RELEV] == 0.0 and ts - M[M_OK_START] >= C[C_HOLD] - 1e-12:
                    M[M_RELEV] = 1.0
                    M[M_RELEV_T] = M[M_OK_START] - C[C_T_FAULT]
                    out[O_R_SUCCESS] = C[C_W_SUCCESS]
                    out[O_RELEV] = 1.0
            else:
                M[M_OK_START] = -1.0
                M[M_RELEV] = 0.0            # unlatched: the success is lost again (else it is 0)
    # aux now holds the diagnostics at t1 (last sub-sample)
    if lev != LEV_NONE:
        amb_currents(t1, y, P, I, U, cur)
        for j in range(4):
            c = cur[j] / C[C_ILIM] if C[C_ILIM] > 0.0 else 0.0
            effort += c * c
    if n_eff > 0:
        effort /= n_eff                          # mean squared normalised command
    M[M_T] = t1
    M[M_PEAK_F] = max(M[M_PEAK_F], f_step)
    M[M_PEAK_Q] = max(M[M_PEAK_Q], q_step)
    M[M_MAX_DISP] = max(M[M_MAX_DISP], disp_step)
    M[M_REV_PEAK] = max(M[M_REV_PEAK], M[M_REV1], M[M_REV2])
    if M[M_REV_PEAK] >= C[C_WHIRL_REVS]:
        M[M_WHIRL] = 1.0

    # ---- reward terms ----
    out[O_FORCE] = f_step
    out[O_R_WHIRL] = 0.0 - C[C_W_WHIRL] * max(back, 0.0)          # 0.0 - x: no negative zeros
    out[O_R_CONTACT] = 0.0 - C[C_W_CONTACT] * f_step / C[C_F_REF]
    out[O_R_DISP] = 0.0 - C[C_W_DISP] * disp_step / clr
    out[O_R_EFFORT] = 0.0 - C[C_W_EFFORT] * effort
    M[M_EFFORT] += effort * dt
    if step_events(f_step, stator, beyond, C, M, out):
        out[O_TERM] = 1.0
        remaining = max(round((C[C_T_END] - t1) / dt), 0.0)
        out[O_R_FAILURE] = -C[C_W_FAILURE] * remaining
    elif t1 >= C[C_T_END] - 1e-9 * dt:
        out[O_TRUNC] = 1.0
    out[O_REWARD] = (out[O_R_WHIRL] + out[O_R_CONTACT] + out[O_R_DISP] + out[O_R_EFFORT]
                     + out[O_R_SUCCESS] + out[O_R_FAILURE])
    observe(t1, y, P, I, U, C, M, aux, cur, scale, obs)


@njit_borrow
def step_rows(A, Y, P, I, U, Z, ATOL, WORK, TSUB, YSUB, AUX, CUR, C, M, SCALE, OBS, OUT):
    """:func:`step_one` for N environments (rows), one after the other on the calling thread
    (no parallel launch: the batch's choice when threads do not pay); without reference
    counting, as ``step_one``."""
    for e in range(Y.shape[0]):
        step_one(A[e], Y[e], P[e], I[e], U[e], Z[e], ATOL[e], WORK[e], TSUB[e], YSUB[e], AUX[e], CUR[e],
                 C[e], M[e], SCALE[e], OBS[e], OUT[e])


@njit_parallel
def step_batch(A, Y, P, I, U, Z, ATOL, WORK, TSUB, YSUB, AUX, CUR, C, M, SCALE, OBS, OUT):
    """:func:`step_one` for N environments (rows), in parallel over environments."""
    for e in numba.prange(Y.shape[0]):
        step_one(A[e], Y[e], P[e], I[e], U[e], Z[e], ATOL[e], WORK[e], TSUB[e], YSUB[e], AUX[e], CUR[e],
                 C[e], M[e], SCALE[e], OBS[e], OUT[e])



@njit
def info_values(out, M, C, v):
    """The ``info`` numbers of one environment (``V_*`` layout) from its kernel outputs, monitor
    and configuration: the step's, and the episode's KPIs so far. No NaN: ``MISSING`` for a
    re-levitation time before re-levitation and for ball KPIs without Sopanen-Mikkola balls."""
    v[V_FORCE] = out[O_FORCE]
    v[V_R_WHIRL] = out[O_R_WHIRL]
    v[V_R_CONTACT] = out[O_R_CONTACT]
    v[V_R_DISP] = out[O_R_DISP]
    v[V_R_EFFORT] = out[O_R_EFFORT]
    v[V_R_SUCCESS] = out[O_R_SUCCESS]
    v[V_R_FAILURE] = out[O_R_FAILURE]
    v[V_TIME] = M[M_T] - C[C_T_FAULT]
    v[V_COST_STATOR] = out[O_STATOR]
    v[V_COST_OVERLOAD] = out[O_OVERLOAD]
    v[V_COST_VALIDITY] = out[O_BEYOND]       # a penetration past its contact law's validity
    v[V_COST] = v[V_COST_STATOR] + v[V_COST_OVERLOAD] + v[V_COST_VALIDITY]
    v[V_WHIRL_REVS] = max(M[M_REV1], M[M_REV2])
    v[V_PEAK_REVS] = M[M_REV_PEAK]
    v[V_PEAK_F] = M[M_PEAK_F]
    v[V_MAX_DISP_UM] = M[M_MAX_DISP] * 1e6
    v[V_RELEV_T] = M[M_RELEV_T] if M[M_RELEV] > 0.0 else MISSING
    v[V_EFFORT] = M[M_EFFORT]
    if C[C_P_COEF] >= 0.0:
        v[V_BALL_Q] = M[M_PEAK_Q]
        v[V_PRESSURE_MPA] = C[C_P_COEF] * np.cbrt(M[M_PEAK_Q]) * 1e-6
    else:
        v[V_BALL_Q] = MISSING
        v[V_PRESSURE_MPA] = MISSING
    # time after the fault within the contact laws' validity (all of it until a bound is passed)
    v[V_TIME_VALID] = (M[M_LEFT_T] if M[M_BEYOND] > 0.0 else M[M_T]) - C[C_T_FAULT]
    v[V_FRICTION] = M[M_FRICTION]
    v[V_WHIRL] = M[M_WHIRL]
    v[V_RELEV] = M[M_RELEV]
    v[V_STATOR] = M[M_STATOR]
    v[V_OVERLOAD] = M[M_OVERLOAD]
    v[V_BEYOND] = M[M_BEYOND]


@njit
def info_rows(OUT, M, C, V):
    """:func:`info_values` of N environments (rows)."""
    for e in range(OUT.shape[0]):
        info_values(OUT[e], M[e], C[e], V[e])
