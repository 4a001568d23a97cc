"""Model bookkeeping: observation sizes of the state vector and the retainer's s0 = 1 pressure."""
import gymnasium as gym
import numpy as np
import pytest

import rotordrop_env  # noqa: F401
from physics import load_scene, simulate
from physics.ball_bearing import ball_forces, ball_stiffness, max_contact_pressure, static_max_ball_load
from physics.metrics import compute_metrics, rating_pressure
from physics.model import build_model
from physics.runs.plots import pressure_levels


def test_full_state_observation_sizes_keep_every_state_order_one():
    """An episode at mu = 0.3 with the unbalance off-centre (tilts excited): every state over
    its observation size stays within 10, the tilt rates included (their old size 0.1 tilt =
    7.9e-5 rad/s gave thousands); only the unbounded angles phi and theta grow. The tolerance
    sizes stay as they were (they set the step sizes)."""
    env = gym.make("RotorDrop-Passive-v1", overrides={"contact.friction": 0.3, "unbalance.z": 0.3},
                   full_state=True, terminate_on_failure=False)
    u = env.unwrapped
    env.reset(seed=0)
    peak = np.abs(u.state)
    done = False
    while not done:
        _, _, term, trunc, _ = env.step(np.zeros(1, np.float32))
        peak = np.maximum(peak, np.abs(u.state))
        done = term or trunc
    model = u.model
    obs = dict(zip(model.names, peak / model.obs_scale))
    bounded = {n: v for n, v in obs.items() if not n.endswith(("phi", "theta"))}
    assert max(bounded.values()) < 10.0, bounded
    assert 0.5 < obs["va"] < 10.0 and 0.5 < obs["vb"] < 10.0
    assert model.obs_scale[model.index("va")] == pytest.approx(0.1 / 0.38)
    tilt = model.scene.contact.clearance / 0.38
    assert model.scale[model.index("va")] == pytest.approx(0.1 * tilt)     # tolerance unchanged


def test_observation_size_defaults_to_the_tolerance_size():
    """States without a separate observation size observe at their tolerance size."""
    model = build_model(load_scene("paper"))
    for name in ("x", "vx", "Omega", "RB1.sx", "RB1.svx", "RB1.omega_s", "RB1.theta"):
        i = model.index(name)
        assert model.obs_scale[i] == model.scale[i]


def test_rating_pressure_line_is_where_s0_is_one():
    """The pressure panel's s0 = 1 line is the worst ball's Hertz pressure when the bearing
    carries C_0 statically: the ball forces at that worst-ball load sum to C_0 (s0 = 1), and the
    worst ball carries 4.5 C_0 / z, between ISO's 4.37 (no clearance) and Stribeck's 5."""
    b = load_scene("paper").bearing
    C0 = b.static_load_rating
    q = static_max_ball_load(b, C0)
    K_tot = ball_stiffness(b)[2]
    u = (q / K_tot) ** (2.0 / 3.0) + b.clearance / 2.0     # ring displacement of that ball load
    fx, fy, _, _, _, qmax = ball_forces(u, 0.0, 0.0, b.balls, b.clearance / 2.0, 0.0, K_tot)
    assert qmax == pytest.approx(q, rel=1e-12)
    assert C0 / np.hypot(fx, fy) == pytest.approx(1.0, rel=1e-9)
    assert 4.37 < q * b.balls / C0 < 5.0
    p = rating_pressure(b)
    assert p == pytest.approx(max_contact_pressure(b, q))
    assert p == pytest.approx(3.655e9, rel=1e-3)        # the figure docs/physics.md quotes
    levels = pressure_levels(b)
    assert levels["s0 = 1 (C0 = 40 kN): 3655 MPa"] == pytest.approx(p * 1e-6)
    assert levels["ISO 76 nominal C0 level 4200 MPa"] == 4200.0


def test_a_drop_below_s0_one_plots_above_the_s0_line():
    """The reviewer's overload (30 000 rpm, 0.1 kg unbalance): s0 = 0.9, and its worst-ball
    pressure lies above the s0 = 1 line (it lay below the old 4 200 MPa ISO line)."""
    scene = load_scene("paper", {"unbalance.mass": 0.1, "rotor.speed_rpm": 30000.0,
                                 "amb.air_gap": 3e-3})       # valid to the end: no stator reached
    m = compute_metrics(simulate(scene, t_end=0.3))
    for v in m["planes"].values():
        assert v["static_safety_factor"] < 1.0
        assert v["max_contact_pressure_MPa"] > 1e-6 * rating_pressure(scene.bearing)
