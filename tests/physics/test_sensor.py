"""Position sensing (scene group sensor, physics/sensor.py): off it changes no bit of any
trajectory; the delay's Padé realisation has the Padé's response; the built-in PID sees the
delay with the Padé's phase; the noise is a held U input drawn from the environment's seed;
bad values are one-line errors."""
import hashlib
import math

import gymnasium as gym
import numpy as np
import pytest

import rotordrop_env  # noqa: F401  (registers the ids)
from physics.equilibrium import levitated_state
from physics.model import (ST_AMB1, U_SENS_NOISE, amb_currents, axis_motion, build_model, delayed_motion,
                           rhs, N_AUX, S_VX, P_AMB_KP, P_AMB_KD, P_AMB_TD)
from physics.scene import SceneError, load_scene
from physics.sensor import pade_phase, pade_rates, pade_response
from physics.simulate import Integrator, simulate


def sha(a) -> str:
    return hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()


# sha256 computed on the code before position sensing existed (branch sensing at 0420f67), same
# machine and numba: with sensor.delay = sensor.noise = 0 (the default) the kernels must give the
# same bits (a different CPU / numba / LLVM build could change the last bits; then re-derive the
# hashes from the parent commit the same way before trusting a failure).
DROP_SHA256 = {   # Result.Y of simulate(load_scene("paper", overrides), t_end=0.2)
    "paper": ({}, "2ac782c647192f5a03d9ceb3030d64687b4ef8516038251a70c8ccfd2092eaba"),
    "actuator": ({"effects.amb": "actuator"},
                 "c4e63dbf1d8c78b2c07a8f9812fac7d85128b5cbeba2fba6668b313df5c3a6b6"),
}
#: RotorDrop-Relevitate-v1, episode_time 0.12, reset(seed=3), a fixed action: (observations,
#: states after each step); the PID re-levitates (discrete) or the supervisor offsets it
ENV_SHA256 = {
    "discrete": (1, "1aa23e29796b44a0b2809f02e9802c728fa277d0c5e7257e2505fa3a17124f12",
                 "6e0aa6af3e745a1b471b77fa8a386aa60a9c6590861a901a14ac9ed660fdafff"),
    "supervisor": (np.array([1.0, 0.5, 0.3, -0.2, 0.1, 0.4], np.float32),
                   "37b06efc49691a73755925a5070cf2bb99902fec8bc5f565589aee149acfb8f2",
                   "b5ef28ca6c8865c8699bdc79a1a088939d9bf3e134111d3d9bbcdcd492e9a89c"),
}


@pytest.mark.parametrize("name", sorted(DROP_SHA256))
def test_a_drop_without_sensing_is_bit_for_bit_unchanged(name):
    overrides, want = DROP_SHA256[name]
    r = simulate(load_scene("paper", overrides), t_end=0.2)
    assert sha(r.Y) == want
    assert not any("sensor" in n for n in r.model.names)         # no state when off


def relevitate_episode(command, action, **kw):
    env = gym.make("RotorDrop-Relevitate-v1", command=command, episode_time=0.12, **kw)
    obs, _ = env.reset(seed=3)
    rows, states = [obs], []
    for _ in range(120):
        obs, _, term, trunc, _ = env.step(action)
        rows.append(obs)
        states.append(env.unwrapped._b.y.copy())
        if term or trunc:
            break
    return np.array(rows), np.array(states)


@pytest.mark.parametrize("command", sorted(ENV_SHA256))
def test_a_relevitation_episode_without_sensing_is_bit_for_bit_unchanged(command):
    action, want_obs, want_y = ENV_SHA256[command]
    obs, ys = relevitate_episode(command, action)
    assert (sha(obs), sha(ys)) == (want_obs, want_y)


def test_the_kernel_realisation_is_the_pade_approximant():
    """The rates (S1) are linear: probe their matrices and compare the transfer function
    C (sI - A)^-1 B + D with (2,2) Padé's and with the exact delay."""
    tau = 1e-4
    A = np.array([pade_rates(0.0, *e, tau) for e in ((1.0, 0.0), (0.0, 1.0))]).T
    B = np.array(pade_rates(1.0, 0.0, 0.0, tau))
    Cm, D = np.array([0.0, -1.0]), 1.0                         # d_delayed = d - q2
    for wt in (0.3, 1.0, 2.0):
        s = 1j * wt / tau
        H = Cm @ np.linalg.solve(s * np.eye(2) - A, B) + D
        assert H == pytest.approx(pade_response(wt / tau, tau), rel=1e-12)
        assert abs(H) == pytest.approx(1.0, rel=1e-12)         # an all-pass
        assert np.angle(H) == pytest.approx(pade_phase(wt / tau, tau), abs=1e-12)
    # phase short of the exact -w tau: 0.075 deg at w tau = 1, 2.0 deg at 2 (sensor.py doc)
    assert math.degrees(pade_phase(1.0, 1.0) + 1.0) == pytest.approx(0.0749, abs=1e-4)
    assert math.degrees(pade_phase(2.0, 1.0) + 2.0) == pytest.approx(1.972, abs=1e-3)


def test_the_sensed_displacement_of_a_ramp_is_the_ramp_tau_later():
    """A free rotor (no AMB, no gravity, no unbalance) crossing the centre at v: what the
    sensors report is x(t - tau) = v (t - tau) once the Padé transient, which decays as
    e^{-3 t / tau}, has gone (at t >= 6 tau: e^{-18} of v tau)."""
    tau, v = 2e-4, 0.01
    scene = load_scene("paper", {"effects.amb": "none", "effects.gravity": False,
                                 "effects.unbalance": False, "sensor.delay": tau,
                                 "solver.rtol": 1e-9})
    model = build_model(scene)
    y = levitated_state(model)
    y[model.I[S_VX]] = v
    integ = Integrator(model)
    U = model.controls(False)
    t = 0.0
    for t_next in tau * np.arange(6.0, 11.0):
        integ.advance(y, t, t_next, U)
        t = t_next
        px, _, vx, _ = axis_motion(y, model.P, model.I, ST_AMB1)
        sx, _, svx, _ = delayed_motion(y, model.P, model.I, 0, px, 0.0, vx, 0.0)
        assert px == pytest.approx(v * t, rel=1e-9)
        assert sx == pytest.approx(v * (t - tau), abs=1e-6 * v * tau)
        assert svx == pytest.approx(v, rel=1e-6)


@pytest.mark.parametrize("tau", [1e-4, 2e-4])
def test_the_builtin_pid_sees_the_delay_with_the_pade_phase(tau):
    """Levitated on the unbalance orbit at 10 000 rpm, the actuator PID's command current over
    the true displacement at AMB1 has the phase of -C(jw) H(jw), C the filtered PID, H the
    delay's Padé (6.0 deg more lag per 0.1 ms at w = 1047 rad/s). The PID is linear in what it
    sees, so the only errors are the integration's (rtol 1e-8 of a 1 µm orbit: ~1e-3 deg) and
    the fit's; without the delay the same fit gives -C's phase to 2e-4 deg."""
    s = load_scene("paper", {"effects.amb": "actuator", "amb.off_time": 1.0, "sensor.delay": tau,
                             "solver.t_end": 0.03, "solver.output_rate": 2e5, "solver.rtol": 1e-8})
    r = simulate(s)
    m = r.model
    Y = np.ascontiguousarray(r.Y)
    U, cur = m.controls(True), np.zeros(4)
    x = Y[:, m.index("x")] + s.positions.amb1 * Y[:, m.index("a")]
    i = np.empty(len(r.t))
    for k, (t, y) in enumerate(zip(r.t, Y)):
        amb_currents(t, y, m.P, m.I, U, cur)
        i[k] = cur[0]
    w = Y[0, m.index("Omega")]
    n = int((r.t[-1] - 0.01) * w / (2 * math.pi))                # whole periods after 10 ms
    sel = r.t >= r.t[-1] - n * 2 * math.pi / w
    basis = np.column_stack([np.cos(w * r.t[sel]), np.sin(w * r.t[sel]), np.ones(sel.sum())])
    fx = np.linalg.lstsq(basis, x[sel], rcond=None)[0]
    fi = np.linalg.lstsq(basis, i[sel], rcond=None)[0]
    ratio = complex(fi[0], -fi[1]) / complex(fx[0], -fx[1])
    a, sj = s.amb, 1j * w
    C = a.kp + a.kd * sj / (1 + sj * a.derivative_filter) + a.ki / sj
    want = -C * pade_response(w, tau)
    assert math.degrees(np.angle(ratio / want)) == pytest.approx(0.0, abs=0.01)
    assert abs(ratio / want) == pytest.approx(1.0, abs=1e-4)
    assert math.degrees(np.angle(want / -C)) == pytest.approx(-math.degrees(w * tau), abs=1e-3)


def test_the_noise_is_a_held_input_the_pid_reads():
    """The kernel is deterministic given U: a noise sample n on an axis moves that axis's PID
    command by -(kp + kd / tau_d) n (proportional and unfiltered derivative path), nothing else."""
    m = build_model(load_scene("paper", {"effects.amb": "actuator", "sensor.noise": 1e-6}))
    assert m.n_state == build_model(load_scene("paper", {"effects.amb": "actuator"})).n_state
    y = levitated_state(m)
    U = m.controls(True)
    base, shifted = np.zeros(4), np.zeros(4)
    amb_currents(0.0, y, m.P, m.I, U, base)
    U[U_SENS_NOISE + 1] = 2e-7                                   # AMB1 y
    amb_currents(0.0, y, m.P, m.I, U, shifted)
    gain = m.P[P_AMB_KP] + m.P[P_AMB_KD] / m.P[P_AMB_TD]
    assert shifted - base == pytest.approx([0.0, -gain * 2e-7, 0.0, 0.0], abs=1e-12)
    dy0, dy1, aux = np.zeros(m.n_state), np.zeros(m.n_state), np.zeros(N_AUX)
    U[U_SENS_NOISE + 1] = 0.0
    rhs(0.0, y, m.P, m.I, U, dy0, aux)
    U[U_SENS_NOISE + 1] = 2e-7
    rhs(0.0, y, m.P, m.I, U, dy1, aux)
    assert not np.array_equal(dy0, dy1)                          # the magnet force follows


def test_noise_and_delay_are_reproducible_from_the_seed():
    kw = dict(sensor_noise=1e-6, sensor_delay=1e-4)
    act = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0], np.float32)
    a_obs, a_y = relevitate_episode("supervisor", act, **kw)
    b_obs, b_y = relevitate_episode("supervisor", act, **kw)
    assert np.array_equal(a_obs, b_obs) and np.array_equal(a_y, b_y)
    env = gym.make("RotorDrop-Relevitate-v1", command="supervisor", episode_time=0.12, **kw)
    env.reset(seed=4)
    assert env.unwrapped.model.n_state == 40 + 8                 # 2 delay states per AMB axis
    c_obs, c_y = relevitate_episode("supervisor", act, sensor_delay=1e-4)
    assert not np.array_equal(a_y, c_y)                          # the noise reaches the physics


@pytest.mark.parametrize("overrides, match", [
    ({"sensor.delay": -1e-4}, r"sensor.delay = -0.0001 is out of range: must be in \[0, 0.002\] s"),
    ({"sensor.delay": 0.01}, "sensor.delay = 0.01 is out of range"),
    ({"sensor.noise": 1e-3}, "sensor.noise = 0.001 is out of range"),
    ({"sensor.noise": "1um"}, "sensor.noise"),
])
def test_bad_scene_values_are_one_line_errors(overrides, match):
    with pytest.raises(SceneError, match=match) as err:
        load_scene("paper", overrides)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("kw, match", [
    (dict(sensor_delay=-1e-4), r"sensor_delay = -0.0001 must be a delay in seconds in \[0, 0.002\]"),
    (dict(sensor_delay=5e-3), "sensor_delay = 0.005"),
    (dict(sensor_delay="0.1ms"), "sensor_delay = '0.1ms'"),
    (dict(sensor_delay=True), "sensor_delay = True"),
    (dict(sensor_delay=1e-4, overrides={"sensor.delay": 2e-4}),
     "sensor_delay = 0.0001 contradicts the scene's sensor.delay = 0.0002"),
])
def test_bad_env_values_are_one_line_errors(kw, match):
    with pytest.raises(ValueError, match=match) as err:
        gym.make("RotorDrop-Full-v1", **kw)
    assert "\n" not in str(err.value)


def test_the_drop_driver_refuses_noise_it_cannot_draw():
    with pytest.raises(SceneError, match="sensor.noise = 1e-06 m: the drop driver has no noise"):
        simulate(load_scene("paper", {"sensor.noise": 1e-6}), t_end=0.01)


def test_a_scene_delay_reaches_the_env_and_is_fixed():
    env = gym.make("RotorDrop-Full-v1", overrides={"sensor.delay": 1e-4})
    assert env.unwrapped.sensor_delay == 1e-4
    with pytest.raises(AttributeError, match="sensor_delay is fixed"):
        env.unwrapped.sensor_delay = 2e-4


@pytest.mark.parametrize("dt", [2e-4, 1e-4])
def test_a_raw_current_law_runs_at_a_realistic_control_rate_with_sensing(dt):
    """A digital AMB controller's rate (5-10 kHz): the env steps at control_dt 0.1-0.2 ms
    with the sensors' delay and noise, and whirl-brake (tuned at 1 ms) still re-levitates."""
    from agents.control.controllers import controller_env_kwargs
    from agents.control.controllers import BASELINES
    from agents.benchmarking.rollout import run_episodes
    cls = BASELINES["whirl-brake"]
    kw = dict(controller_env_kwargs(cls, "RotorDrop-Full-v1"), control_dt=dt, episode_time=0.12,
              terminate_on_failure=False, sensor_delay=1e-4, sensor_noise=5e-7)
    ep = run_episodes("RotorDrop-Full-v1", cls, [0], kw)[0]
    assert ep.length == round(0.12 / dt)
    assert ep.kpis["relevitated"]


@pytest.mark.parametrize("amb", ["linear", "actuator"])
def test_the_energy_audit_closes_under_a_delayed_controller(amb):
    """The AMB force acts on the true motion (its power is booked with the true velocity)
    whatever the controller sees: the audit closes through the levitated phase and the drop."""
    from helpers import energy_residual
    scene = load_scene("paper", {"effects.amb": amb, "sensor.delay": 2e-4, "solver.rtol": 1e-8})
    r = simulate(scene, t_end=0.15)
    res, _ = energy_residual(r)
    drop_energy = scene.rotor.mass * scene.world.gravity * scene.contact.clearance
    assert r.contact_force("RB1").max() > 100.0
    assert res.max() < 1e-3 * drop_energy


def _kicked_currents(tau, ts):
    """AMB1 x command current at times ``ts`` of the levitated rotor (no gravity, no unbalance)
    kicked to vx = 1 mm/s at t = 0 under the actuator PID, sensors delayed by ``tau``."""
    s = load_scene("paper", {"effects.amb": "actuator", "effects.gravity": False,
                             "effects.unbalance": False, "amb.off_time": 1.0,
                             "sensor.delay": tau, "solver.rtol": 1e-9})
    m = build_model(s)
    y = levitated_state(m)
    y[m.I[S_VX]] = 1e-3
    integ, U, out = Integrator(m), m.controls(True), np.zeros(4)
    t, cur = 0.0, []
    for t_next in ts:
        if t_next > t:
            integ.advance(y, t, t_next, U)
            t = t_next
        amb_currents(t, y, m.P, m.I, U, out)
        cur.append(out[0])
    return np.array(cur)


def test_the_pid_answers_a_kick_tau_later():
    """Step in velocity: the delayed PID's current is the undelayed one's tau later. Up to tau
    it has barely started: it stays within 15 % of the current the undelayed PID has reached
    by tau (the Padé's all-pass wiggles about zero there, up to 10 %, where the exact delay
    has 0); from 2 tau to 1 ms it follows i_0(t - tau) within 5 % of the
    peak: the two closed loops part only by the force the undelayed PID applied tau earlier
    (measured: 2 % at 1 ms)."""
    tau = 1e-4
    ts = np.arange(0.0, 1e-3 + 1e-9, 1e-5)
    i0, it = _kicked_currents(0.0, ts), _kicked_currents(tau, ts)
    early = (ts > 0.0) & (ts <= tau)
    assert np.abs(it[early]).max() < 0.15 * abs(i0[ts <= tau][-1])
    shifted = np.interp(ts - tau, ts, i0, left=0.0)
    late = ts >= 2 * tau
    assert np.abs(it - shifted)[late].max() < 0.05 * np.abs(i0).max()
