"""The steady levitated state before the fault (issue: start the drop clean).

The AMBs carry the rotor's weight and the unbalance orbit has settled (closed form), each sleeve
rests on its ball set under its own weight and each housing sags on its springs (Newton solve).
"""
import math

import numpy as np

from .ball_bearing import ball_forces
from .model import (I_PLANES, J_HX, J_SX, N_PLANE_IDX, P_G, P_HALF_PLAY,
                    P_KLIN, P_KS, P_KTOT, P_MH, P_MS, P_NB, P_UB_PHASE, RB_LINEAR, RB_SM, F_RB, F_AMB,
                    AMB_LINEAR, S_PHI, S_VX, S_X, S_W, Model, AMB_ACTUATOR, AMB_AXES, I_AMB_INT,
                    I_AMB_FILT, I_AMB_COIL, P_AMB_IFF1, I_CS, I_THERM, I_SENS, P_SENS_TAU,
                    P_Z_AMB1, A_STF, FX_ROW, I_FX, N_AUX, P_FX_SHAPE, P_FX_W2, ST_AMB1, rhs)
from .rotor import axis_at
from .sensor import STATES_PER_PLANE, pade_response, steady_states
from .amb import actuator_constants, pid_dynamic_stiffness, pid_steady_states
from .roots import bisect_decreasing
from .rotor import steady_unbalance_orbit


def sleeve_rest_offset(P: np.ndarray, I: np.ndarray) -> float:
    """Vertical inner-ring offset u_y at which the bearing carries the sleeve's weight."""
    weight = P[P_MS] * P[P_G]
    if weight == 0.0:
        return 0.0
    if I[F_RB] == RB_LINEAR:
        return -weight / P[P_KLIN]

    def lift(uy):                       # upward bearing force on the inner ring
        return -ball_forces(0.0, uy, 0.0, int(P[P_NB]), P[P_HALF_PLAY], 0.0, P[P_KTOT])[1]

    # lift(lo) >> weight, lift(0) = 0; bisection is robust for the clearance kink
    return bisect_decreasing(lift, weight, -P[P_HALF_PLAY] - 1e-3, 0.0)


def levitated_state(model: Model) -> np.ndarray:
    """State vector at t = 0: rotor on its settled unbalance orbit, bodies in static balance."""
    s, P, I = model.scene, model.P, model.I
    y = np.zeros(model.n_state)
    omega = s.rotor.speed_rpm * math.pi / 30.0
    y[I[S_W]] = omega
    pos = 0j
    if I[S_PHI] >= 0 and I[F_AMB] in (AMB_LINEAR, AMB_ACTUATOR):
        k, c = _amb_support(model, omega)
        Z = steady_unbalance_orbit(s.unbalance.mass * s.unbalance.radius, omega, s.rotor.mass, k, c)
        pos = Z * complex(math.cos(P[P_UB_PHASE]), math.sin(P[P_UB_PHASE]))
        vel = 1j * omega * pos
        y[I[S_X]], y[I[S_X] + 1] = pos.real, pos.imag
        y[I[S_VX]], y[I[S_VX] + 1] = vel.real, vel.imag
    if I[F_AMB] == AMB_ACTUATOR:
        _actuator_states(model, y, pos, omega)
    if I[I_SENS] >= 0:                  # sensor delay states on the settled orbit
        for k in range(2):
            X = complex(*axis_at(P[P_Z_AMB1 + k], pos.real, pos.imag, 0.0, 0.0))
            for a, Xa in enumerate((X, -1j * X)):      # y = Re(-i X e^{i omega t})
                q1, q2 = steady_states(Xa, omega, P[P_SENS_TAU])
                i = I[I_SENS] + STATES_PER_PLANE * k + 2 * a
                y[i], y[i + 1] = q1.real, q2.real
    if I[I_CS] >= 0:
        y[I[I_CS]] = y[I[I_CS] + 1] = s.support.damping
    if I[I_THERM] >= 0:                 # sleeve temperatures (effects.thermal)
        y[I[I_THERM]] = y[I[I_THERM] + 1] = s.thermal.initial_rise
    if model.elastic_modes:
        _elastic_sag(model, y)
    uy = sleeve_rest_offset(P, I) if I[F_RB] in (RB_SM, RB_LINEAR) else 0.0
    sleeve_mass = P[P_MS] if I[I_PLANES + J_SX] >= 0 else 0.0
    for k in range(2):
        base = I_PLANES + k * N_PLANE_IDX
        hy = 0.0
        if I[base + J_HX] >= 0:
            hy = -(P[P_MH] + sleeve_mass) * P[P_G] / P[P_KS]
            y[I[base + J_HX] + 1] = hy
        if I[base + J_SX] >= 0:
            y[I[base + J_SX] + 1] = hy + uy
    return y


def _elastic_sag(model: Model, y: np.ndarray, iterations: int = 3) -> None:
    """A flexible rotor's static elastic deflection under the AMB forces at t = 0: the modal
    coordinates eta (x plane, then y) at which omega^2 eta balances the AMB station forces'
    share S^T f(eta) (gravity does no work on the elastic modes, physics/flexible/floating.py;
    the unbalance's rotating force is left to the motion). The AMB forces follow the deflection,
    which a soft shaft makes large: Newton steps on a finite-difference Jacobian (the AMB laws
    are linear in it or nearly so: one or two steps converge)."""
    P, I, n = model.P, model.I, model.elastic_modes
    i0 = int(I[I_FX])
    w2 = np.tile(P[P_FX_W2:P_FX_W2 + n], 2)
    shape = [P[P_FX_SHAPE + (ST_AMB1 + k) * FX_ROW:P_FX_SHAPE + (ST_AMB1 + k) * FX_ROW + n]
             for k in range(2)]
    aux, dy = np.zeros(N_AUX), np.zeros(model.n_state)
    U = model.controls(True)

    def residual(eta: np.ndarray) -> np.ndarray:
        y[i0:i0 + 2 * n] = eta
        rhs(0.0, y, P, I, U, dy, aux)
        q = np.concatenate([sum(shape[k] * aux[A_STF + 2 * (ST_AMB1 + k) + a] for k in range(2))
                            for a in range(2)])
        return w2 * eta - q

    eta = np.zeros(2 * n)
    step = model.scene.contact.clearance * 1e-3 / max(float(np.abs(shape).max()), 1e-12)
    for _ in range(iterations):
        r0 = residual(eta)
        J = np.column_stack([(residual(eta + step * e) - r0) / step for e in np.eye(2 * n)])
        eta = eta - np.linalg.solve(J, r0)
    y[i0:i0 + 2 * n] = eta


def _amb_support(model: Model, omega: float) -> tuple[float, float]:
    """Total AMB stiffness and damping (both bearings) that the unbalance orbit sees at omega."""
    a = model.scene.amb
    H = pade_response(omega, model.scene.sensor.delay)     # the controller sees x delayed
    if model.I[F_AMB] == AMB_LINEAR:
        if H == 1.0:
            return 2 * a.stiffness, 2 * a.damping
        K = (a.stiffness + 1j * omega * a.damping) * H
        return 2 * K.real, 2 * K.imag / omega
    ac = actuator_constants(a, 0.0, 0.0)
    K = pid_dynamic_stiffness(a, ac.current_gain, ac.negative_stiffness, omega)
    if H != 1.0:                        # K = k_i C L H - k_s
        K = (K + ac.negative_stiffness) * H - ac.negative_stiffness
    return 2 * K.real, (2 * K.imag / omega if omega > 0.0 else 0.0)


def _actuator_states(model: Model, y: np.ndarray, pos: complex, omega: float) -> None:
    """PID and coil states on the settled orbit x + i y = pos e^{i omega t} (AMB axes in order)."""
    I, P, a = model.I, model.P, model.scene.amb
    for j in range(len(AMB_AXES)):
        X = pos if j % 2 == 0 else -1j * pos          # y = Re(-i pos e^{i omega t})
        if I[I_SENS] >= 0:                            # the PID sees the delayed orbit
            X = X * pade_response(omega, P[P_SENS_TAU])
        Z, Q, Ic = pid_steady_states(a, X, omega)
        y[I[I_AMB_INT] + j] = Z.real
        y[I[I_AMB_FILT] + j] = Q.real
        if I[I_AMB_COIL] >= 0:
            y[I[I_AMB_COIL] + j] = Ic.real + (P[P_AMB_IFF1 + j // 2] if j % 2 == 1 else 0.0)
