"""Physics added for the environments: actuator AMBs (spec §5) and the semi-active damper (§6)."""
import math

import gymnasium as gym
import numpy as np
import pytest

import rotordrop_env  # noqa: F401
from physics import compute_metrics, load_scene, simulate
from physics.amb import actuator_constants, magnet_pair_force, weight_shares
from physics.model import build_model
from physics.scene import SceneError

from helpers import phys

ACTUATOR = {"effects.amb": "actuator"}


def _constants(scene):
    shares = weight_shares(scene.rotor.mass * scene.world.gravity, scene.positions.amb1,
                           scene.positions.amb2)
    return actuator_constants(scene.amb, *shares), shares


def test_force_law_gives_the_spec_current_gain_and_negative_stiffness():
    """Spec §5: N = 250, A_g = 1e-3 m², g_0 = 0.6 mm, i_0 = 3 A, alpha = 22.5° -> k_i ≈ 605 N/A,
    k_s ≈ 3.0e6 N/m at the centre (checked by finite differences of the force law)."""
    s = load_scene("paper", ACTUATOR)
    c, _ = _constants(s)
    a = s.amb
    f = lambda i, x: magnet_pair_force(i, x, c.force_constant, a.air_gap, a.bias_current, c.ratio_max)
    di, dx = 1e-4, 1e-9
    k_i = (f(di, 0.0) - f(-di, 0.0)) / (2 * di)
    k_s = (f(0.0, dx) - f(0.0, -dx)) / (2 * dx)
    assert k_i == pytest.approx(605.0, rel=0.005)
    assert k_s == pytest.approx(3.0e6, rel=0.01)
    assert f(0.0, 0.0) == 0.0                          # balanced bias at the centre


def test_lift_force_from_the_resting_position():
    """Spec §5: rotor resting on the retainer bearings, lifting gap ≈ 0.9 mm: ≈ 800 N at full
    current, about 1.7 x the weight share it must lift."""
    s = load_scene("paper", ACTUATOR)
    c, shares = _constants(s)
    a = s.amb
    x = -s.contact.clearance                           # 0.3 mm down: upper gap 0.9 mm
    lift = magnet_pair_force(a.current_limit, x, c.force_constant, a.air_gap, a.bias_current,
                             c.ratio_max)
    assert lift == pytest.approx(800.0, rel=0.02)
    assert lift / shares[0] == pytest.approx(1.7, abs=0.05)
    # without control current the bias flux pulls the rotor down onto the retainer bearing
    assert magnet_pair_force(0.0, x, c.force_constant, a.air_gap, a.bias_current, c.ratio_max) < 0


def test_force_capacity_caps_the_force_at_the_stator():
    s = load_scene("paper", ACTUATOR)
    c, _ = _constants(s)
    a = s.amb
    f = magnet_pair_force(a.current_limit, 0.999 * a.air_gap, c.force_constant, a.air_gap,
                          a.bias_current, c.ratio_max)
    assert 0.0 < f <= c.force_capacity
    # B_sat^2 A_g cos(alpha) / mu_0
    assert c.force_capacity == pytest.approx(
        a.saturation_flux ** 2 * a.pole_area * math.cos(math.radians(a.pole_angle_deg))
        / (4e-7 * math.pi), rel=1e-9)


def test_actuator_amb_levitates_the_spinning_rotor():
    """Before the fault the PID-controlled electromagnets hold the rotor on its small unbalance
    orbit (m_u e / m ≈ 1 µm above the critical speeds), with no contact."""
    s = load_scene("paper", dict(ACTUATOR, **{"amb.off_time": 0.05}))
    r = simulate(s, t_end=0.05)
    orbit = np.hypot(*r.orbit("RB1").T)
    m_u_e = s.unbalance.mass * s.unbalance.radius
    assert orbit.max() < 3 * m_u_e / s.rotor.mass
    assert compute_metrics(r)["first_contact_time_s"] is None


def test_actuator_states_only_when_enabled():
    base = build_model(load_scene("paper")).n_state
    assert build_model(load_scene("paper", ACTUATOR)).n_state == base + 8    # 4 integrals, 4 filters
    lag = build_model(load_scene("paper", dict(ACTUATOR, **{"amb.coil_time_constant": 1e-3})))
    assert lag.n_state == base + 12                                           # + 4 coil currents
    damp = build_model(load_scene("paper", {"effects.semi_active_damper": True}))
    assert damp.n_state == base + 2


def test_actuator_scene_errors_name_the_parameter():
    with pytest.raises(SceneError, match="amb.current_limit"):
        load_scene("paper", dict(ACTUATOR, **{"amb.current_limit": 4.0}))
    with pytest.raises(SceneError, match="amb.kp"):
        load_scene("paper", dict(ACTUATOR, **{"amb.kp": 1000.0}))
    with pytest.raises(SceneError, match="cannot carry"):
        load_scene("paper", dict(ACTUATOR, **{"amb.turns": 50}))
    with pytest.raises(SceneError, match="support.damping"):
        load_scene("paper", {"effects.semi_active_damper": True, "support.damping": 1000.0})


def test_damper_follows_its_command_with_the_first_order_lag():
    """Spec §6: C_s lags its command with tau = 10 ms: after one tau it has covered 1 - 1/e."""
    env = gym.make("RotorDrop-Damping-v1", episode_time=0.02)
    u = env.unwrapped
    env.reset(seed=0)
    c0 = u.scene.support.damping
    c_max = u.scene.support.damping_max
    for _ in range(10):                                # 10 ms = one time constant
        obs = env.step(np.ones(2, np.float32))[0]
    c = phys(env, obs, "damping1")
    assert c == pytest.approx(c_max - (c_max - c0) / math.e, rel=1e-3)
    for _ in range(10):
        obs = env.step(-np.ones(2, np.float32))[0]
    c2 = phys(env, obs, "damping2")
    c_min = u.scene.support.damping_min
    assert c2 == pytest.approx(c_min + (c - c_min) / math.e, rel=1e-3)


def test_discrete_command_relevitates_the_rotor_at_low_friction():
    """Paper scene at mu = 0.1: switching the built-in controller on when power returns lifts the
    rotor off the retainer bearings and holds it (contact-free, within c/2)."""
    def run(action):
        env = gym.make("RotorDrop-Relevitate-v1", overrides={"contact.friction": 0.1},
                       episode_time=0.2)
        env.reset(seed=0)
        done, forces = False, []
        while not done:
            obs, r, term, trunc, info = env.step(action)
            forces.append(info["contact_force_N"])
            done = term or trunc
        return info, np.array(forces)

    info, forces = run(1)
    assert info["kpi_relevitated"] == np.True_
    # not before power returns (50 ms) plus the lift-off ramp (50 ms), within the episode
    assert 0.1 <= info["kpi_relevitation_time_s"] < 0.18
    assert forces[-30:].max() == 0.0
    assert info["reward_success"] == 0.0               # the bonus was paid once, earlier
    off, forces_off = run(0)
    # still down: the retainer bearings carry the weight, each plane on average its share (the
    # step's larger plane force is read); the last 30 ms still hold some bounce, hence the half
    s = load_scene("paper")
    share = weight_shares(s.rotor.mass * s.world.gravity, s.positions.rb1, s.positions.rb2)[0]
    assert off["kpi_relevitated"] == np.False_ and forces_off[-30:].mean() > 0.5 * share


def test_direct_currents_act_after_power_returns_only():
    env = gym.make("RotorDrop-Relevitate-v1", command="continuous", episode_time=0.06)
    u = env.unwrapped
    env.reset(seed=0)
    full_lift = np.array([0.0, 1.0, 0.0, 1.0], np.float32)
    for k in range(60):
        obs = env.step(full_lift)[0]
        cur = phys(env, obs, "i1y")
        if k < 49:                                     # power returns at 50 ms
            assert cur == 0.0 and phys(env, obs, "amb_power") == 0.0
        if k == 49:                                    # observed as soon as the next action can use it
            assert phys(env, obs, "amb_power") == 1.0
    assert cur == pytest.approx(u.scene.amb.current_limit)
    # full lifting current from the bottom: the rotor rises off the retainer bearings
    assert phys(env, obs, "y1") > -u.scene.contact.clearance
