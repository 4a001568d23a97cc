"""Gymnasium environments: checkers, seeding, passive env == simulator, errors, episode end."""
import math

import gymnasium as gym
from rotordrop_env.info import MISSING
import numpy as np
import pytest

import rotordrop_env
from physics import compute_metrics, load_scene, simulate
from physics.ball_bearing import max_contact_pressure
from physics.scene import SceneError
from rotordrop_env.scenario import DEFAULT_RANGES

from helpers import phys, run_env_checkers

VARIANTS = [("RotorDrop-Passive-v1", {}), ("RotorDrop-Damping-v1", {}),
            ("RotorDrop-Relevitate-v1", {"command": "discrete"}),
            ("RotorDrop-Relevitate-v1", {"command": "continuous"}),
            ("RotorDrop-Full-v1", {"command": "discrete"}),
            ("RotorDrop-Full-v1", {"command": "continuous"}),
            ("RotorDrop-Recover-v1", {}), ("RotorDrop-Recover-v1", {"command": "continuous"})]


@pytest.mark.parametrize("env_id,kwargs", VARIANTS, ids=lambda v: v if isinstance(v, str) else
                         v.get("command", ""))
def test_gymnasium_and_sb3_checkers_pass(env_id, kwargs):
    run_env_checkers(lambda: gym.make(env_id, episode_time=0.004, **kwargs).unwrapped)


def test_registered_ids_and_public_attributes():
    assert set(rotordrop_env.ENV_IDS) <= set(gym.registry)
    env = gym.make("RotorDrop-Full-v1", episode_time=0.002)
    u = env.unwrapped
    for name in ("x1", "y1", "vx1", "vy1", "x2", "y2", "vx2", "vy2", "rotor_speed",
                 "sleeve_speed1", "sleeve_speed2", "damping1", "damping2", "amb_power",
                 "controller_on", "i1x", "i1y", "i2x", "i2y"):
        assert name in u.obs_names
    assert len(u.obs_names) == env.observation_space.shape[0] == u.obs_scale.shape[0]
    assert u.action_names == ["damping1", "damping2", "levitate"] and u.dt == 1e-3
    obs, _ = env.reset(seed=0)
    # at the fault the rotor spins at the scene speed and the damper holds support.damping
    assert phys(env, obs, "rotor_speed") == pytest.approx(u.scene.rotor.speed_rpm * math.pi / 30,
                                                          rel=1e-4)
    assert phys(env, obs, "damping1") == pytest.approx(u.scene.support.damping, rel=1e-6)
    assert phys(env, obs, "amb_power") == 0.0


def test_seeding_makes_scenarios_and_trajectories_reproducible():
    def run(seed):
        env = gym.make("RotorDrop-Damping-v1", randomize=True, episode_time=0.005)
        obs, info = env.reset(seed=seed)
        env.action_space.seed(seed)
        traj = [obs]
        for _ in range(5):
            traj.append(env.step(env.action_space.sample())[0])
        return env.unwrapped.scenario, np.array(traj)

    s1, t1 = run(7)
    s2, t2 = run(7)
    s3, _ = run(8)
    assert s1 == s2 and np.array_equal(t1, t2)
    assert s1 != s3
    _, lo, hi = DEFAULT_RANGES["contact.friction"]    # documented friction range
    assert lo <= s1["contact.friction"] <= hi


def test_reset_options_fix_the_scenario():
    env = gym.make("RotorDrop-Relevitate-v1", randomize=True, episode_time=0.003)
    _, info = env.reset(seed=1, options={"scenario": {"contact.friction": 0.33,
                                                      "power_return_time": 0.0123}})
    assert env.unwrapped.scene.contact.friction == 0.33
    # power return is put on the control-step grid (rounded up)
    assert env.unwrapped.scenario["power_return_time"] == pytest.approx(0.013)
    with pytest.raises(SceneError, match="contact.frictoin"):
        env.reset(options={"scenario": {"contact.frictoin": 0.3}})
    with pytest.raises(ValueError, match="unknown reset option"):
        env.reset(options={"friction": 0.3})


@pytest.mark.parametrize("mu,whirl", [(0.25, False), (0.5, True)])
def test_passive_env_reproduces_the_simulator(mu, whirl):
    """Same scene, same physics: states at the control steps and the KPIs of `rotordrop drop`;
    the paper's whirl threshold (spec §7: between mu 0.25 and 0.5) is seen by both."""
    episode = 0.15
    # the mu = 0.5 whirl reaches the preset's 600 µm AMB air gap, which ends the drop's validity
    # (metrics past it are null): a wide gap keeps both runs valid and the physics the same
    ov = {"contact.friction": mu, "amb.air_gap": 3e-3}
    env = gym.make("RotorDrop-Passive-v1", overrides=ov, samples_per_step=20,
                   terminate_on_failure=False, episode_time=episode)
    u = env.unwrapped
    sv = u.scene
    env.reset(seed=0)
    ys, done = [], False
    while not done:
        obs, reward, term, trunc, info = env.step(np.zeros(1, np.float32))
        assert isinstance(reward, float) and type(term) is bool and type(trunc) is bool
        ys.append(phys(env, obs, "y1"))
        done = term or trunc
    assert trunc and not term and len(ys) == 150
    res = simulate(load_scene("paper", ov), t_end=sv.amb.off_time + episode)
    t = sv.amb.off_time + np.arange(1, len(ys) + 1) * u.dt      # the control steps after the fault
    k = np.searchsorted(res.t, t - 1e-12)
    z = sv.positions.amb1                              # sensor 1 = AMB1 plane
    y1 = res.state("y")[k] + z * res.state("b")[k]
    err = np.abs(np.array(ys) - y1)
    # first 40 ms: agreement at the integrator's tolerance (the two runs split the time
    # differently: 1 ms control steps against 10 ms chunks)
    assert err[:40].max() < 50 * sv.solver.rtol * sv.contact.clearance
    m = compute_metrics(res)
    post = res.t > sv.amb.off_time
    f_peak = max(res.contact_force(p)[post].max() for p in ("RB1", "RB2"))
    assert info["kpi_peak_contact_force_N"] == pytest.approx(f_peak, rel=0.02)
    d_max = max(np.hypot(*res.orbit(p)[post].T).max() for p in ("RB1", "RB2")) * 1e6
    assert info["kpi_max_displacement_um"] == pytest.approx(d_max, rel=0.01)
    assert bool(info["kpi_backward_whirl"]) is whirl and m["backward_whirl"] is whirl
    # the retainer numbers: the worst ball's load, sampled every 0.2 ms against 50 µs
    q_max = max(res.max_ball_load(p)[post].max() for p in ("RB1", "RB2"))
    assert info["kpi_max_ball_load_N"] == pytest.approx(q_max, rel=0.02)
    assert info["kpi_max_contact_pressure_MPa"] == pytest.approx(
        1e-6 * max_contact_pressure(sv.bearing, info["kpi_max_ball_load_N"]), rel=1e-12)
    assert info["kpi_whirl_revolutions"] == pytest.approx(
        max(m["planes"][p]["whirl_revolutions"] for p in ("RB1", "RB2")), abs=0.1)


def test_stator_contact_terminates_with_the_failure_penalty():
    env = gym.make("RotorDrop-Passive-v1", overrides={"contact.friction": 0.5}, episode_time=0.3)
    env.reset(seed=0)
    n = 0
    worst_step = 0.0                  # most negative reward of a step that did not terminate
    while True:
        _, r, term, trunc, info = env.step(np.zeros(1, np.float32))
        n += 1
        if not term:
            worst_step = min(worst_step, r)
        if term or trunc:
            break
    # mu = 0.5: the whirling orbit passes the 600 um stator gap (the drop alone reaches ~450 um)
    assert term and not trunc and info["kpi_stator_contact"]
    assert info["kpi_max_displacement_um"] > 600.0 and n < 300
    assert info["reward_failure"] == pytest.approx(-10.0 * (300 - n))
    # ending early never pays: the failure penalty per step beats the whirl penalties it cuts short
    assert -info["reward_failure"] / (300 - n) > -worst_step
    assert sum(info[f"reward_{k}"] for k in rotordrop_env.env.REWARD_TERMS) == pytest.approx(r)


def test_failure_flags_latch_when_the_episode_is_not_terminated():
    """With ``terminate_on_failure=False`` the final KPIs still say the orbit reached the stator
    (the whirl at mu = 0.5 passes the 600 um AMB gap around 50 ms, then the episode runs on)."""
    env = gym.make("RotorDrop-Passive-v1", overrides={"contact.friction": 0.5}, episode_time=0.3,
                   terminate_on_failure=False)
    env.reset(seed=0)
    flags = []
    while True:
        _, _, term, trunc, info = env.step(np.zeros(1, np.float32))
        flags.append(env.unwrapped._b.out[rotordrop_env.kernels.O_STATOR] > 0.0)
        if term or trunc:
            break
    assert trunc and not term and any(flags) and not flags[-1]   # on the stator, then off it
    assert info["kpi_stator_contact"]


@pytest.mark.parametrize("env_id,action,match", [
    ("RotorDrop-Damping-v1", [np.nan, 0.0], "non-finite"),
    ("RotorDrop-Damping-v1", [1.5, 0.0], "out-of-range"),
    ("RotorDrop-Damping-v1", [0.0, 0.0, 0.0], "shape"),
    ("RotorDrop-Relevitate-v1", 2, "out-of-range"),
    ("RotorDrop-Relevitate-v1", float("nan"), "non-finite"),
])
def test_bad_actions_raise_clear_errors(env_id, action, match):
    env = gym.make(env_id, episode_time=0.003).unwrapped
    env.reset(seed=0)
    y0 = env.state
    with pytest.raises(ValueError, match=match):
        env.step(np.asarray(action))
    assert env.time == 0.0 and np.array_equal(env.state, y0)     # nothing advanced


def test_step_before_reset_raises():
    env = gym.make("RotorDrop-Damping-v1").unwrapped
    with pytest.raises(gym.error.ResetNeeded):
        env.step(np.zeros(2, np.float32))


def test_bad_kwargs_raise_clear_errors():
    with pytest.raises(ValueError, match="control_dt"):
        gym.make("RotorDrop-Passive-v1", control_dt=0.0)
    with pytest.raises(ValueError, match="command"):
        gym.make("RotorDrop-Passive-v1", command="discrete")
    with pytest.raises(ValueError, match="w_contact"):
        gym.make("RotorDrop-Damping-v1", w_contact=-1.0)
    with pytest.raises(SceneError, match="contact.friction"):
        gym.make("RotorDrop-Damping-v1", overrides={"contact.friction": 2.0})
    with pytest.raises(ValueError, match="randomization"):
        gym.make("RotorDrop-Damping-v1", randomization={"contact.friction": (0.5, 0.1)})


def test_time_limit_truncates_and_final_info_has_kpis():
    env = gym.make("RotorDrop-Relevitate-v1", episode_time=0.004)
    env.reset(seed=0)
    flags = [env.step(0)[2:4] for _ in range(4)]
    assert flags[:3] == [(False, False)] * 3 and flags[3] == (False, True)
    env.reset(seed=0)
    for _ in range(4):
        *_, info = env.step(0)
    for key in ("kpi_backward_whirl", "kpi_peak_contact_force_N", "kpi_max_displacement_um",
                "kpi_relevitated", "kpi_relevitation_time_s", "kpi_control_effort",
                "kpi_max_ball_load_N", "kpi_max_contact_pressure_MPa"):
        assert key in info
    # not re-levitated: the documented sentinel, never NaN
    assert info["kpi_relevitated"] == np.False_ and info["kpi_relevitation_time_s"] == MISSING


def test_rgb_render_shows_the_orbit():
    env = gym.make("RotorDrop-Passive-v1", episode_time=0.02, render_mode="rgb_array")
    env.reset(seed=0)
    for _ in range(20):
        env.step(np.zeros(1, np.float32))
    img = env.render()
    assert img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3
    assert (img < 200).any() and (img > 250).any()     # drawn lines on a white background
    # the RB1 orbit (matplotlib's first colour) and the force trace were recorded from the reset
    # on, although render() was first called only now
    c0 = np.array([31, 119, 180])
    assert (np.abs(img.astype(int) - c0).sum(axis=2) < 60).sum() > 50
    env.close()
