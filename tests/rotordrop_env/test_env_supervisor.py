"""The supervisory command interface (``command="supervisor"``): the built-in PID runs inside the
physics step and the agent moves its reference in the frame of the sensed orbit, scales its
gains, chooses when to switch it on and sets the support damping."""
import math

import gymnasium as gym
import numpy as np
import pytest

import rotordrop_env  # noqa: F401  (registers the ids)
from physics.model import ORBIT_FRAME_CORE, ST_AMB1, axis_motion
from rotordrop_env.layout import COMMANDS, SUPERVISOR_ACTIONS, SUPERVISOR_OBS

from helpers import run_env_checkers

# frictionless contact and no unbalance: nothing drives an orbit, so the reference decides
# where the levitated rotor rests
STILL = {"unbalance.mass": 0.0, "contact.friction": 0.0}


def amb_radius(env, k: int = 0) -> float:
    u = env.unwrapped
    px, py, _, _ = axis_motion(u._b.y, u._b.P, u._b.I, ST_AMB1 + k)
    return math.hypot(px, py)


def run(env, action_at, steps: int):
    """Radius at AMB plane 1 after every step, with ``action_at(i)`` the action of step i."""
    env.reset(seed=0)
    radii, info = [], {}
    for i in range(steps):
        _, _, _, _, info = env.step(np.asarray(action_at(i), dtype=np.float32))
        radii.append(amb_radius(env))
    return np.array(radii), info


def sup(levitate=1.0, gain=0.0, radial=0.0, tangential=0.0, damping=1.0, full=True):
    a = [levitate, gain, radial, tangential, radial, tangential]
    return ([damping, damping] + a) if full else a


@pytest.mark.parametrize("env_id", ["RotorDrop-Relevitate-v1", "RotorDrop-Full-v1"])
def test_env_checkers_pass(env_id):
    run_env_checkers(lambda: gym.make(env_id, command="supervisor", episode_time=0.01))


def test_spaces_and_names():
    env = gym.make("RotorDrop-Full-v1", command="supervisor", episode_time=0.002)
    u = env.unwrapped
    assert u.action_names == ["damping1", "damping2", *SUPERVISOR_ACTIONS]
    assert env.action_space.shape == (8,) and env.action_space.low.min() == -1.0
    assert u.obs_names[-4:] == list(SUPERVISOR_OBS)
    obs, _ = env.reset(seed=0)
    assert obs.dtype == np.float32 and obs.shape == (len(u.obs_names),)
    relev = gym.make("RotorDrop-Relevitate-v1", command="supervisor", episode_time=0.002)
    assert relev.unwrapped.action_names == list(SUPERVISOR_ACTIONS)


def test_unknown_mode_names_the_modes():
    with pytest.raises(ValueError) as err:
        gym.make("RotorDrop-Full-v1", command="supervise")
    for mode in COMMANDS:
        assert repr(mode) in str(err.value)


def test_zero_commands_reproduce_the_builtin_controller_exactly():
    """Zero offsets, nominal gain, switch on, C_max: the very trajectory of the discrete mode's
    built-in controller with C_max (the "inner loop only" row), which re-levitates."""
    kw = dict(episode_time=0.2, terminate_on_failure=False)
    states = {}
    for command, action in (("discrete", [1.0, 1.0, 1.0]), ("supervisor", sup())):
        env = gym.make("RotorDrop-Full-v1", command=command, **kw)
        env.reset(seed=0)
        traj = []
        for _ in range(200):
            _, _, _, _, info = env.step(np.asarray(action, dtype=np.float32))
            traj.append(env.unwrapped.state)
        states[command] = (np.array(traj), info)
    assert np.array_equal(states["discrete"][0], states["supervisor"][0])
    assert states["supervisor"][1]["kpi_relevitated"]


def test_no_switch_no_levitation():
    env = gym.make("RotorDrop-Relevitate-v1", command="supervisor", episode_time=0.1)
    _, info = run(env, lambda i: sup(levitate=-1.0, radial=-1.0, full=False), 100)
    assert not info["kpi_relevitated"] and info["kpi_control_effort"] == 0.0


@pytest.mark.parametrize("a", [0.1, 0.2])
def test_radial_offset_moves_the_equilibrium_by_the_command(a):
    """A radial offset a x clearance holds the rotor on a ring of radius sqrt(a^2 - r_0^2) c (the
    frame's regularised unit vector); a negative one pulls it to the centre.

    Judged over the 50-150 ms after the offset: held open loop, the ring is not stable. A mode
    (most likely tangential) seeded at rounding level grows at about 140 1/s and leaves the ring
    200-270 ms after the offset, earlier or later with the arithmetic's last bits (a different
    step control or summation order moves it). The agent keeps the ring by acting on it every
    1 ms step; a constant command does not."""
    env = gym.make("RotorDrop-Full-v1", command="supervisor", episode_time=0.5,
                   overrides=STILL, terminate_on_failure=False)
    c = env.unwrapped.scene.contact.clearance
    r, _ = run(env, lambda i: sup(radial=a if i >= 150 else 0.0), 300)
    assert r[149] < 0.05 * c                              # levitated near the centre first
    want = math.sqrt(a * a - ORBIT_FRAME_CORE ** 2) * c
    assert np.mean(r[-100:]) == pytest.approx(want, rel=0.04)       # a slow, settling ring
    assert np.all(np.abs(r[-100:] - want) < 0.25 * want)
    r_in, _ = run(env, lambda i: sup(radial=-a if i >= 150 else 0.0), 500)
    assert r_in[-50:].max() < 0.01 * c


def test_gain_scale_stiffens_the_loop():
    """A higher gain scale (stiffer closed loop) lifts the rotor to the centre sooner; below
    about 0.7 the PID cannot hold it off the retainer."""
    env = gym.make("RotorDrop-Full-v1", command="supervisor", episode_time=0.3,
                   terminate_on_failure=False)
    c = env.unwrapped.scene.contact.clearance
    times = []
    for g in (-0.25, 0.0, 0.5, 1.0):
        r, info = run(env, lambda i: sup(gain=g), 300)
        assert info["kpi_relevitated"] and r[-1] < 0.02 * c
        times.append(info["kpi_relevitation_time_s"])
    assert np.all(np.diff(times) < 0.0), times
    r, _ = run(env, lambda i: sup(gain=-1.0), 300)
    assert r[-1] > 0.5 * c


def test_tangential_offset_drives_a_forward_orbit():
    env = gym.make("RotorDrop-Relevitate-v1", command="supervisor", episode_time=0.3,
                   overrides=STILL, terminate_on_failure=False)
    env.reset(seed=0)
    u = env.unwrapped
    j = u.obs_names.index("orbit_rate1")
    for i in range(300):
        obs, *_ = env.step(np.asarray(sup(tangential=0.1 if i >= 150 else 0.0, full=False),
                                      dtype=np.float32))
    assert obs[j] * u.obs_scale[j] > 50.0                 # rad/s, along the spin


@pytest.mark.parametrize("bad", [0.0, -0.5, 1.5, math.nan, math.inf, "half", True])
def test_supervisor_authority_out_of_range_names_the_range(bad):
    with pytest.raises(ValueError, match=r"supervisor_authority = .* must be (a real number )?in \(0, 1\]"):
        gym.make("RotorDrop-Full-v1", command="supervisor", supervisor_authority=bad)


def test_supervisor_authority_needs_the_supervisor_command():
    with pytest.raises(ValueError, match="supervisor_authority = 0.5 applies to command='supervisor'"):
        gym.make("RotorDrop-Full-v1", command="discrete", supervisor_authority=0.5)


def trajectory(action, steps: int = 120, **kw):
    env = gym.make("RotorDrop-Full-v1", command="supervisor", episode_time=0.12,
                   terminate_on_failure=False, **kw)
    env.reset(seed=3)
    traj = []
    for _ in range(steps):
        env.step(np.asarray(action, dtype=np.float32))
        traj.append(env.unwrapped.state)
    return np.array(traj)


def test_supervisor_authority_scales_the_commands_exactly():
    """Authority a with command x moves the rotor exactly as full authority with a x (a = 1/2:
    the scaling is exact in binary), for the offsets and the gain scale; the default is the
    full range, bit for bit."""
    x = sup(gain=0.6, radial=-0.8, tangential=0.5, damping=0.2)
    half = sup(gain=0.3, radial=-0.4, tangential=0.25, damping=0.2)
    assert np.array_equal(trajectory(x, supervisor_authority=0.5), trajectory(half))
    assert np.array_equal(trajectory(x, supervisor_authority=1.0), trajectory(x))
    assert not np.array_equal(trajectory(x, supervisor_authority=0.5), trajectory(x))
