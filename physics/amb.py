"""Active magnetic bearings (spec §5): two levels, chosen by ``effects.amb``.

* ``linear``: F = -k_amb x - c_amb x' + weight share, per AMB and axis.
* ``actuator``: a differential electromagnet pair per AMB axis (bias current i_0, control
  current i, nonlinear gap law, current limit, force capacity from iron saturation), an optional
  first-order coil lag and a PID position controller with a filtered derivative and a gravity
  feed-forward current. After a fault the controller can be switched back on with a reference
  ramped from the landing position to the centre and a reset integrator, or the control
  currents can be commanded directly (reactivation, spec §5).

Force of one axis (spec §5), positive towards +x::

    F = k cos(alpha) [(i_0 + i)^2 / (g_0 - x)^2 - (i_0 - i)^2 / (g_0 + x)^2],   k = mu_0 N^2 A_g / 4

Each magnet's term is capped at B_sat^2 A_g cos(alpha) / mu_0 (flux density at most B_sat), which
bounds the force near the stator. At the centre: k_i = 4 k cos(alpha) i_0 / g_0^2 (current gain),
k_s = 4 k cos(alpha) i_0^2 / g_0^3 (negative stiffness).

An effect of the drop model (docs/architecture.md "Adding an effect"): its scene keys, packed
slots (parameters, controls), states and parameter packing are declared here;
:mod:`physics.model` composes them.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ._jit import njit, njit_borrow, njit_inline
from .rotor import ST_AMB1, add_external, add_station_force, axis_motion
from .sensor import sensed_motion

MU_0 = 4e-7 * math.pi

SCENE_KEYS = ("amb.*", "effects.amb", "rotor.mass", "world.gravity", "positions.amb1",
              "positions.amb2", "effects.gravity")
AMB_NONE, AMB_LINEAR, AMB_ACTUATOR = 0, 1, 2
#: the actuator's axes, in the order of its per-axis states and controls
AMB_AXES = ("AMB1.x", "AMB1.y", "AMB2.x", "AMB2.y")
#: the actuator's parameters (spec §5): k cos(alpha), g_0, i_0, current limit, current/gap cap,
#: PID gains, derivative filter, coil lag, lift-off ramp
ACTUATOR_PARAMS = ("amb.force_constant", "amb.air_gap", "amb.bias_current", "amb.current_limit",
                   "amb.ratio_max", "amb.kp", "amb.ki", "amb.kd", "amb.derivative_filter",
                   "amb.coil_time_constant", "amb.liftoff_ramp_time")


def declare(layout) -> None:
    """The AMBs' slots. Controls: ``amb.power`` > 0 runs the AMBs under their built-in controller
    (linear law or PID). Actuator level only: ``amb.direct`` > 0 applies the control currents
    ``amb.current_command`` + j (j = axis, see AMB_AXES) instead of the PID; ``amb.t_on`` is
    the time the PID was switched on and ``amb.reference0`` + j the reference it ramps from
    (spec §5 reactivation). A supervisor over the PID shifts the reference of AMB plane k by
    ``amb.reference_offset`` + 2k (radial) and + 2k + 1 (tangential, along a forward orbit) [m]
    in the frame of the sensed orbit and scales the three PID gains by ``amb.gain``."""
    p = layout.params
    p.add("amb.stiffness", const="P_K_AMB")
    p.add("amb.damping", const="P_C_AMB")
    p.block("amb1.bias", "amb2.bias", consts=("P_AMB_BIAS1", "P_AMB_BIAS2"))
    p.add_each(*ACTUATOR_PARAMS, consts=(
        "P_AMB_KMAG", "P_AMB_G0", "P_AMB_I0", "P_AMB_ILIM", "P_AMB_RMAX", "P_AMB_KP", "P_AMB_KI",
        "P_AMB_KD", "P_AMB_TD", "P_AMB_TL", "P_AMB_RAMP"))
    p.block("amb1.feedforward_current", "amb2.feedforward_current",     # gravity feed-forward
            consts=("P_AMB_IFF1", "P_AMB_IFF2"))
    layout.index.add("flag.amb", const="F_AMB")
    # first state of each per-axis block
    layout.index.add_each("state.amb_integral", "state.amb_filter", "state.amb_current",
                          consts=("I_AMB_INT", "I_AMB_FILT", "I_AMB_COIL"))
    u = layout.controls
    u.add("amb.power", const="U_AMB_POWER")
    u.add("amb.direct", const="U_AMB_DIRECT")
    u.add("amb.current_command", len(AMB_AXES), const="U_ICMD")
    u.add("amb.t_on", const="U_T_ON")
    u.add("amb.reference0", len(AMB_AXES), const="U_REF0")
    u.add("amb.reference_offset", len(AMB_AXES), const="U_REF_OFF")
    u.add("amb.gain", const="U_AMB_GAIN")


def pack(scene, P, I, layout) -> None:
    """The AMBs' parameters and flag (level)."""
    s, fx, p = scene, scene.effects, layout.params
    I[layout.index["flag.amb"]] = {"none": AMB_NONE, "linear": AMB_LINEAR,
                                   "actuator": AMB_ACTUATOR}[fx.amb]
    g = s.world.gravity if fx.gravity else 0.0
    P[p["amb.stiffness"]], P[p["amb.damping"]] = s.amb.stiffness, s.amb.damping
    P[p["amb1.bias"]], P[p["amb2.bias"]] = weight_shares(s.rotor.mass * g, s.positions.amb1,
                                                         s.positions.amb2)
    if fx.amb == "actuator":
        a = s.amb
        ac = actuator_constants(a, P[p["amb1.bias"]], P[p["amb2.bias"]])
        for name, value in zip(ACTUATOR_PARAMS, (
                ac.force_constant, a.air_gap, a.bias_current, a.current_limit, ac.ratio_max,
                a.kp, a.ki, a.kd, a.derivative_filter, a.coil_time_constant,
                a.liftoff_ramp_time)):
            P[p[name]] = value
        P[p["amb1.feedforward_current"]], P[p["amb2.feedforward_current"]] = ac.feedforward


def states(scene, I, layout, sizes, add) -> None:
    """The actuator's PID integral, derivative-filter and (with a coil lag) coil-current states,
    one block of 4 (AMB_AXES) each."""
    if scene.effects.amb != "actuator":
        return
    i, c = layout.index, sizes.clearance
    I[i["state.amb_integral"]] = add(f"{AMB_AXES[0]}.integral", 0.01 * c)
    for ax in AMB_AXES[1:]:
        add(f"{ax}.integral", 0.01 * c)
    I[i["state.amb_filter"]] = add(f"{AMB_AXES[0]}.filter", c)
    for ax in AMB_AXES[1:]:
        add(f"{ax}.filter", c)
    if scene.amb.coil_time_constant > 0.0:
        size = max(scene.amb.current_limit, 1e-3)
        I[i["state.amb_current"]] = add(f"{AMB_AXES[0]}.current", size)
        for ax in AMB_AXES[1:]:
            add(f"{ax}.current", size)


@njit
def linear_force(d, v, k_amb, c_amb, bias):
    """Force of one AMB axis for displacement d and velocity v at its plane, plus a bias force."""
    return -k_amb * d - c_amb * v + bias


def weight_shares(weight: float, z1: float, z2: float) -> tuple[float, float]:
    """Static weight carried by supports at z1 and z2 (centre of mass at z = 0), lever rule."""
    return weight * z2 / (z2 - z1), -weight * z1 / (z2 - z1)


STANDARD_GRAVITY = 9.80665


def static_weight_share(scene) -> float:
    """The rotor weight on the more loaded retainer bearing [N]: the film law's reference load
    (spec §4) and the environments' force scale. Without gravity (``world.gravity = 0``) the
    share under standard gravity keeps both defined."""
    g = scene.world.gravity if scene.world.gravity > 0.0 else STANDARD_GRAVITY
    return max(weight_shares(scene.rotor.mass * g, scene.positions.rb1, scene.positions.rb2))


# ------------------------------------------------------------------------- actuator level --
@njit
def magnet_pair_force(i, x, k_mag, g0, i0, ratio_max):
    """Force of a differential electromagnet pair along +x (spec §5).

    ``k_mag`` = k cos(alpha); ``ratio_max`` caps the current-to-gap ratio of each magnet
    (flux density B = mu_0 N i / (2 g) <= B_sat); the gaps are floored at 1 % of g_0.
    """
    g_pos = max(g0 - x, 0.01 * g0)
    g_neg = max(g0 + x, 0.01 * g0)
    r_pos = min(abs(i0 + i) / g_pos, ratio_max)
    r_neg = min(abs(i0 - i) / g_neg, ratio_max)
    return k_mag * (r_pos * r_pos - r_neg * r_neg)


@njit
def ramp_reference(t, t_on, r0, ramp_time):
    """Lift-off reference: from the landing position r0 at t_on linearly to the centre."""
    if ramp_time <= 0.0:
        return 0.0
    s = (t - t_on) / ramp_time
    if s >= 1.0:
        return 0.0
    if s <= 0.0:
        return r0
    return r0 * (1.0 - s)


@njit
def pid_current(e, z_int, q, kp, ki, kd, tau_d, i_ff):
    """Control current of the PID: i_ff - (kp e + ki int(e) + kd de/dt filtered).

    The filtered derivative is (e - q) / tau_d with the filter state q' = (e - q) / tau_d.
    """
    return i_ff - (kp * e + ki * z_int + kd * (e - q) / tau_d)


@njit
def clamp(v, lo, hi):
    return lo if v < lo else (hi if v > hi else v)


@njit
def actuator_command(t, d, z_int, q, u_direct, u_power, u_icmd, t_on, ref0, offset, lim, ramp,
                     i_ff, kp, ki, kd, td):
    """Commanded control current of one actuator axis, its error e and integral rate (spec §5).

    ``d``: displacement at the axis; ``z_int``, ``q``: its PID integral and derivative-filter
    states; ``u_*``, ``t_on``, ``ref0``: its controls (``U_AMB_DIRECT``, ``U_AMB_POWER``,
    ``U_ICMD + j``, ``U_T_ON``, ``U_REF0 + j``, ``U_REF_OFF + j``); the rest its parameters
    (``P_AMB_*``, the gains already scaled by ``U_AMB_GAIN``; ``i_ff`` the gravity feed-forward
    current, zero on x axes). Scalars only, so that the model's ``rhs`` inlines it.

    Direct mode: ``u_icmd`` clipped to the current limit (U is a public input). PID mode:
    feed-forward minus PID of e = d - ramped reference, with conditional-integration anti-windup
    (the integral stops while the current is saturated and the error would saturate it further).
    Off: zero.
    """
    if u_direct > 0.0:
        return clamp(u_icmd, -lim, lim), 0.0, 0.0
    if u_power <= 0.0:
        return 0.0, 0.0, 0.0
    e = d - ramp_reference(t, t_on, ref0, ramp) - offset
    raw = pid_current(e, z_int, q, kp, ki, kd, td, i_ff)
    if (raw > lim and e < 0.0) or (raw < -lim and e > 0.0):
        return (lim if raw > lim else -lim), e, 0.0
    return clamp(raw, -lim, lim), e, e


@dataclass(frozen=True)
class ActuatorConstants:
    """Derived constants of the actuator level (spec §5), per AMB axis."""
    force_constant: float        # k cos(alpha) = mu_0 N^2 A_g cos(alpha) / 4 [N m^2 / A^2]
    current_gain: float          # k_i at the centre [N/A]
    negative_stiffness: float    # k_s at the centre [N/m]
    ratio_max: float             # largest current / gap ratio of one magnet (saturation) [A/m]
    force_capacity: float        # force of one magnet at saturation [N]
    feedforward: tuple[float, float]   # gravity current of AMB1 and AMB2 (y axes) [A]


def actuator_constants(amb, weight1: float, weight2: float) -> ActuatorConstants:
    """Constants of a scene's ``amb`` group; ``weight1/2`` are the weight shares of AMB1/2 [N]."""
    k_mag = MU_0 * amb.turns ** 2 * amb.pole_area / 4.0 * math.cos(math.radians(amb.pole_angle_deg))
    g0, i0 = amb.air_gap, amb.bias_current
    k_i = 4.0 * k_mag * i0 / g0 ** 2
    k_s = 4.0 * k_mag * i0 ** 2 / g0 ** 3
    ratio_max = 2.0 * amb.saturation_flux / (MU_0 * amb.turns)
    cap = k_mag * ratio_max ** 2
    ff = (weight1 / k_i, weight2 / k_i) if k_i > 0.0 else (0.0, 0.0)
    return ActuatorConstants(k_mag, k_i, k_s, ratio_max, cap, ff)


def pid_dynamic_stiffness(amb, k_i: float, k_s: float, omega: float) -> complex:
    """Closed-loop dynamic stiffness K(j omega) of one actuator axis around the centre.

    F = -K x with K = k_i C(j omega) L(j omega) - k_s, C the filtered PID, L the coil lag.
    """
    s = 1j * omega
    C = amb.kp + amb.kd * s / (1.0 + s * amb.derivative_filter)
    if omega > 0.0:
        C += amb.ki / s
    L = 1.0 / (1.0 + s * amb.coil_time_constant)
    return k_i * C * L - k_s


def pid_steady_states(amb, X: complex, omega: float) -> tuple[complex, complex, complex]:
    """Complex amplitudes of (integral, filter state, coil control current) on the periodic
    orbit x = Re(X e^{j omega t}) (zero mean; the caller adds the feed-forward current)."""
    if omega <= 0.0:
        return 0j, 0j, 0j
    s = 1j * omega
    Z = X / s
    Q = X / (1.0 + s * amb.derivative_filter)
    I_cmd = -(amb.kp * X + amb.ki * Z + amb.kd * (X - Q) / amb.derivative_filter)
    return Z, Q, I_cmd / (1.0 + s * amb.coil_time_constant)


# ----------------------------------------------------------------------------- kernels --
#: the orbit frame's unit vectors are regularised within this fraction of the clearance of the
#: centre (an offset fades out there instead of jumping with the direction of a tiny orbit)
ORBIT_FRAME_CORE = 0.05


@njit
def orbit_offset(dx, dy, radial, tangential, spin, clearance):
    """(x, y) reference offset [m] of ``radial`` along the sensed displacement (dx, dy) and
    ``tangential`` perpendicular to it along a forward orbit (the direction of ``spin``), with
    unit vectors (dx, dy) / sqrt(r^2 + r_0^2), r_0 = ``ORBIT_FRAME_CORE`` x clearance."""
    if radial == 0.0 and tangential == 0.0:
        return 0.0, 0.0
    n = math.sqrt(dx * dx + dy * dy + (ORBIT_FRAME_CORE * clearance) ** 2)
    ux, uy = dx / n, dy / n
    s = 1.0 if spin >= 0.0 else -1.0
    return radial * ux - tangential * s * uy, radial * uy + tangential * s * ux


@njit_borrow
def amb_currents(t, y, P, I, U, out):
    """Control currents of the 4 actuator axes (AMB1 x, AMB1 y, AMB2 x, AMB2 y) now [A]: the coil
    currents when they lag, else the command of the law :func:`force` applies."""
    for j in range(4):
        if I[I_AMB_COIL] >= 0:
            out[j] = y[I[I_AMB_COIL] + j]
            continue
        k = j // 2
        dx, dyy, ddx, ddy = axis_motion(y, P, I, ST_AMB1 + k)
        if I[F_SENSOR]:
            dx, dyy, _, _ = sensed_motion(y, P, I, U, k, dx, dyy, ddx, ddy)
        ox, oy = orbit_offset(dx, dyy, U[U_REF_OFF + 2 * k], U[U_REF_OFF + 2 * k + 1], y[I[S_W]],
                              P[P_CLR])
        out[j] = actuator_command(
            t, dyy if j % 2 == 1 else dx, y[I[I_AMB_INT] + j], y[I[I_AMB_FILT] + j],
            U[U_AMB_DIRECT], U[U_AMB_POWER], U[U_ICMD + j], U[U_T_ON], U[U_REF0 + j],
            oy if j % 2 == 1 else ox, P[P_AMB_ILIM], P[P_AMB_RAMP],
            P[P_AMB_IFF1 + k] if j % 2 == 1 else 0.0,
            U[U_AMB_GAIN] * P[P_AMB_KP], U[U_AMB_GAIN] * P[P_AMB_KI], U[U_AMB_GAIN] * P[P_AMB_KD],
            P[P_AMB_TD])[0]


@njit_inline
def acting(I, U):
    """The AMBs apply forces or run states now: the actuator always (its PID states), the
    linear law while powered."""
    amb = I[F_AMB]
    return amb == AMB_ACTUATOR or (amb == AMB_LINEAR and U[U_AMB_POWER] > 0.0)


@njit_inline
def reads_sensor(I, U):
    """The AMBs' law reads the sensed displacement (and so the held sensor noise) now: the
    linear law or the actuator's PID while powered; not direct coil currents, not unpowered."""
    amb = I[F_AMB]
    return U[U_AMB_POWER] > 0.0 and (
        amb == AMB_LINEAR or (amb == AMB_ACTUATOR and U[U_AMB_DIRECT] <= 0.0))


@njit_inline
def force(t, y, P, I, U, dy, aux, load):
    """The AMBs' forces at their stations into the load, their power as external work, and the
    actuator's PID, filter and coil rates (spec §5)."""
    # actuator: the PID states evolve only under the built-in controller; the magnets pull while
    # powered or driven directly. The per-axis law takes scalars so that it compiles inline here
    # (as an array-taking call it cost ~90 ns per axis)
    amb = I[F_AMB]
    pid_on = U[U_AMB_POWER] > 0.0 and U[U_AMB_DIRECT] <= 0.0
    pulls = U[U_AMB_POWER] > 0.0 or U[U_AMB_DIRECT] > 0.0
    for k in range(2):
        dx, dyy, ddx, ddy = axis_motion(y, P, I, ST_AMB1 + k)
        # the controller's view (physics/sensor.py): the true motion without sensing
        sx, sy, svx, svy = dx, dyy, ddx, ddy
        if I[F_SENSOR]:
            sx, sy, svx, svy = sensed_motion(y, P, I, U, k, dx, dyy, ddx, ddy)
        ox, oy = orbit_offset(sx, sy, U[U_REF_OFF + 2 * k], U[U_REF_OFF + 2 * k + 1],
                              y[I[S_W]], P[P_CLR])
        if amb == AMB_LINEAR:
            fx = linear_force(sx, svx, P[P_K_AMB], P[P_C_AMB], 0.0)
            fy = linear_force(sy, svy, P[P_K_AMB], P[P_C_AMB], P[P_AMB_BIAS1 + k])
        else:
            fx = fy = 0.0
            for a in range(2):                      # x, then y axis of AMB k
                j = 2 * k + a
                d = dyy if a == 1 else dx
                i_int, i_q = I[I_AMB_INT] + j, I[I_AMB_FILT] + j
                i_cmd, e, de_int = actuator_command(
                    t, sy if a == 1 else sx, y[i_int], y[i_q], U[U_AMB_DIRECT],
                    U[U_AMB_POWER], U[U_ICMD + j],
                    U[U_T_ON], U[U_REF0 + j], oy if a == 1 else ox, P[P_AMB_ILIM],
                    P[P_AMB_RAMP], P[P_AMB_IFF1 + k] if a == 1 else 0.0,
                    U[U_AMB_GAIN] * P[P_AMB_KP],
                    U[U_AMB_GAIN] * P[P_AMB_KI], U[U_AMB_GAIN] * P[P_AMB_KD], P[P_AMB_TD])
                i_act = i_cmd
                if I[I_AMB_COIL] >= 0:               # first-order coil lag
                    ic = I[I_AMB_COIL] + j
                    i_act = y[ic]
                    dy[ic] = (i_cmd - i_act) / P[P_AMB_TL]
                if pid_on:
                    dy[i_int] = de_int
                    dy[i_q] = (e - y[i_q]) / P[P_AMB_TD]
                if pulls:
                    f = magnet_pair_force(i_act, d, P[P_AMB_KMAG], P[P_AMB_G0],
                                          P[P_AMB_I0], P[P_AMB_RMAX])
                    if a == 1:
                        fy = f
                    else:
                        fx = f
        load = add_external(add_station_force(load, P, I, aux, ST_AMB1 + k, fx, fy),
                            fx * ddx + fy * ddy)
    return load
