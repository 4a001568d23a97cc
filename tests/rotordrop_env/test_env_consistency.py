"""The environments take their settings from the physics layer, not from copies of it."""
import gymnasium as gym
import numpy as np

import rotordrop_env  # noqa: F401
from physics.scene import load_scene
from physics.simulate import simulate

FIXED = {"solver.method": "fixed", "solver.dt": 2e-5, "solver.max_step": 1e-5}


def test_fixed_step_env_follows_the_simulator_step_for_step():
    """solver.method = fixed steps with solver.dt (solver.max_step applies to the adaptive
    method only): 1 ms control steps are 50 of the simulator's 20 µs steps, so the passive env's
    states at the control steps equal `rotordrop drop`'s to round-off, through the impacts."""
    env = gym.make("RotorDrop-Passive-v1", overrides=FIXED, terminate_on_failure=False,
                   episode_time=0.03, full_state=True)
    u = env.unwrapped
    env.reset(seed=0)
    states = []
    for _ in range(30):
        env.step(np.zeros(1, np.float32))
        states.append(u.state)
    res = simulate(load_scene("paper", FIXED), t_end=0.13)
    k = np.searchsorted(res.t, 0.1 + np.arange(1, 31) * 1e-3 - 1e-12)
    scale = u.model.scale
    assert np.max(np.abs(np.array(states) - res.Y[k]) / scale) < 1e-9


def test_zero_gravity_scene_steps_with_the_film_reference_force_scale():
    """world.gravity = 0 is a valid scene (range 0-100 m/s^2): the contact-force reward term is
    scaled by the weight share under standard gravity, as the bearing film law is
    (physics.amb.static_weight_share), so the episode runs with finite rewards."""
    from physics.amb import STANDARD_GRAVITY, static_weight_share
    scene = load_scene("paper", {"world.gravity": 0.0})
    share = static_weight_share(scene)
    assert share == static_weight_share(load_scene("paper", {"world.gravity": STANDARD_GRAVITY}))
    env = gym.make("RotorDrop-Damping-v1", overrides={"world.gravity": 0.0}, episode_time=0.02)
    env.reset(seed=0)
    done = False
    while not done:
        obs, reward, term, trunc, info = env.step(np.zeros(2, np.float32))
        assert np.isfinite(obs).all() and np.isfinite(reward)
        done = term or trunc
    assert trunc
