"""The environments on a flexible rotor (rotor.model = "flexible", presets paper-flexible and
machine-flexible): every id and command mode runs; the observations are the sensed AMB-plane
motion with the elastic deflection in it, close to the rigid rotor's in the stiff limit; the
full state stays normalised; the episode view draws the deflected orbits; the checkers pass."""
import gymnasium as gym
import numpy as np
import pytest

import rotordrop_env
from physics.flexible.shafts import drop_rotor
from physics.flexible.floating import STATIONS
from physics.rotor import axis_at
from rotordrop_env.layout import COMMANDS

from helpers import run_env_checkers

MODES = [(i, c) for i in rotordrop_env.ENV_IDS
         for c in (COMMANDS if "Relevitate" in i or "Full" in i else (None,))]
POSITIONS = ("x1", "y1", "x2", "y2")


def _kw(command, **kw):
    return dict(kw, command=command) if command else kw


def episode(env_id, scene, overrides=None, steps=None, seed=0, **kw):
    """Observations of one episode (reset included) with seeded random actions, and the env."""
    env = gym.make(env_id, scene=scene, overrides=overrides, **kw)
    env.action_space.seed(seed)
    obs, _ = env.reset(seed=seed)
    out, done, n = [obs], False, 0
    while not done and (steps is None or n < steps):
        obs, _, term, trunc, _ = env.step(env.action_space.sample())
        out.append(obs)
        done, n = term or trunc, n + 1
    return np.array(out), env


def rigid_and_elastic(env, plane: str) -> tuple[np.ndarray, np.ndarray]:
    """The rotor axis at a station ('amb1', 'rb2', ...) in the env's present state: the rigid
    body's (x + z a, y + z b) and the elastic modes' (S . eta), from the reduced rotor itself."""
    u = env.unwrapped
    m, y, s = u.model, u.state, STATIONS.index(plane)
    x, yy, a, b = y[m.rotor_axis_indices()]
    z = m.param(plane + ".z")
    rigid = np.array(axis_at.py_func(z, x, yy, a, b))
    n = m.elastic_modes
    if n == 0:
        return rigid, np.zeros(2)
    shape = drop_rotor(u.scene).shape[s]
    i0 = m.state_index("eta_x1")
    return rigid, np.array([shape @ y[i0:i0 + n], shape @ y[i0 + n:i0 + 2 * n]])


@pytest.mark.parametrize("env_id,command", MODES)
def test_every_id_and_command_runs_on_the_flexible_rotor(env_id, command):
    """Each id and command mode on paper-flexible: the elastic states are in the model, the
    observations are finite and in the space, and the sensed positions are the rigid axis plus
    the elastic deflection at the AMB planes."""
    obs, env = episode(env_id, "paper-flexible", steps=6, episode_time=0.01, **_kw(command))
    u = env.unwrapped
    assert u.model.elastic_modes == 2 and u.model.has_state("eta_x1")     # the two bending modes
    assert np.isfinite(obs).all() and all(o in env.observation_space for o in obs)
    pos = [u.obs_names.index(n) for n in POSITIONS]
    seen = obs[-1][pos] * u.obs_scale[pos]
    axis = np.concatenate([sum(rigid_and_elastic(env, p)) for p in ("amb1", "amb2")])
    assert seen == pytest.approx(axis, rel=1e-6, abs=1e-12)


def test_the_observations_hold_the_elastic_deflection_within_the_clearance():
    """Through a drop of the slender machine rotor the sensed AMB-plane positions are the rigid
    axis plus the elastic deflection at every step: the deflection is there (tens of microns:
    the shaft rings at its first bending mode after the impacts) and stays within the
    clearance scale."""
    env = gym.make("RotorDrop-Passive-v1", scene="machine-flexible", episode_time=0.03)
    u = env.unwrapped
    obs, _ = env.reset(seed=0)
    pos = [u.obs_names.index(n) for n in POSITIONS]
    clearance = u.scene.contact.clearance
    deflection = []
    for _ in range(30):
        seen = obs[pos] * u.obs_scale[pos]
        parts = [rigid_and_elastic(env, p) for p in ("amb1", "amb2")]
        assert seen == pytest.approx(np.concatenate([r + e for r, e in parts]), rel=1e-6, abs=1e-12)
        deflection.append(max(np.hypot(*e) for _, e in parts))
        obs, *_ = env.step(env.action_space.sample())
    assert 0.02 * clearance < max(deflection) < 0.5 * clearance
    # the deflection at the retainer planes, where the contact forces act, is bounded likewise
    assert max(np.hypot(*rigid_and_elastic(env, p)[1]) for p in ("rb1", "rb2")) < 0.5 * clearance


def test_the_stiff_limit_observes_the_rigid_rotor():
    """flexible.modulus_scale = 1000 (bending modes far above the cut-off; the static
    correction modes stay, 31 x stiffer): the observations of the first 20 ms (fall, impact,
    first bounces) are the rigid rotor's within 1 % of their range; the paper-flexible shaft
    itself differs by more than that (the elastic deflection is seen)."""
    rigid, _ = episode("RotorDrop-Passive-v1", "paper", episode_time=0.02)
    stiff, env = episode("RotorDrop-Passive-v1", "paper-flexible",
                         {"flexible.modulus_scale": 1000.0, "flexible.static_modes": True},
                         episode_time=0.02)
    soft, _ = episode("RotorDrop-Passive-v1", "paper-flexible", episode_time=0.02)
    assert env.unwrapped.model.elastic_modes == 5           # the static modes only
    pos = [env.unwrapped.obs_names.index(n) for n in POSITIONS]
    span = np.abs(rigid[:, pos]).max()
    assert span > 0.5                                       # the rotor fell onto its retainers
    assert np.abs(stiff[:, pos] - rigid[:, pos]).max() < 0.01 * span
    assert np.abs(soft[:, pos] - rigid[:, pos]).max() > 0.02 * span


def test_the_full_state_of_a_flexible_rotor_stays_finite_and_normalised():
    """full_state=True with the elastic states: named, scaled by their own sizes (a modal
    amplitude that moves a station by one clearance), finite and of order one through
    randomised re-levitation episodes (the unbounded angles aside)."""
    env = gym.make("RotorDrop-Full-v1", scene="machine-flexible", full_state=True, randomize=True,
                   command="supervisor", episode_time=0.02)
    u = env.unwrapped
    n = u.model.elastic_modes
    names = [f"{r}eta_{p}{j + 1}" for r in ("", "d") for p in "xy" for j in range(n)]
    assert set(names) <= set(u.obs_names)
    elastic = [u.obs_names.index(k) for k in names]
    shape = drop_rotor(u.scene).shape
    reach = np.abs(shape).max(axis=0)
    assert u.obs_scale[elastic[:n]] == pytest.approx(u.scene.contact.clearance / reach)
    bounded = [i for i, k in enumerate(u.obs_names) if k not in ("phi", "RB1.theta", "RB2.theta",
                                                                 "E_dissipated", "W_external")]
    for seed in (0, 1):
        obs, _ = episode("RotorDrop-Full-v1", "machine-flexible", seed=seed, full_state=True,
                         randomize=True, command="supervisor", episode_time=0.02)
        assert np.isfinite(obs).all()
        assert np.abs(obs[:, elastic]).max() < 2.0 and np.abs(obs[:, elastic]).max() > 1e-4
        assert np.abs(obs[:, bounded]).max() < 20.0


def test_the_episode_view_draws_the_deflected_orbits():
    """The view records the rotor axis at the retainer planes with the elastic deflection (the
    orbit the contact sees), not the rigid body's, and draws it."""
    env = gym.make("RotorDrop-Damping-v1", scene="machine-flexible", episode_time=0.01,
                   render_mode="rgb_array")
    env.reset(seed=0)
    for _ in range(5):
        env.step(env.action_space.sample())
    view = env.unwrapped._renderer
    last = view.orbit[view.n_orbit - 1]
    parts = [rigid_and_elastic(env, p) for p in ("rb1", "rb2")]
    assert last == pytest.approx(np.concatenate([r + e for r, e in parts]), rel=1e-9, abs=1e-15)
    assert np.abs(last - np.concatenate([r for r, _ in parts])).max() > 1e-8
    frame = env.render()
    assert frame.shape == (432, 768, 3) and frame.std() > 0


def test_the_checkers_pass_on_a_flexible_env():
    run_env_checkers(lambda: gym.make("RotorDrop-Full-v1", scene="paper-flexible", full_state=True,
                                      command="supervisor", episode_time=0.005))


def test_a_flexible_scene_through_overrides_and_a_scene_object():
    """rotor.model = flexible as an override of the paper scene is the paper-flexible preset;
    a Scene object works as well."""
    from physics import load_scene
    a, _ = episode("RotorDrop-Relevitate-v1", "paper", {"rotor.model": "flexible"}, steps=5)
    b, _ = episode("RotorDrop-Relevitate-v1", "paper-flexible", steps=5)
    c, _ = episode("RotorDrop-Relevitate-v1", load_scene("paper-flexible"), steps=5)
    assert np.array_equal(a, b) and np.array_equal(b, c)
