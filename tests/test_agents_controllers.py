"""Baseline controllers: action spaces, SB3 predict interface, and what each one physically does."""
import numpy as np
import pytest

from agents.controllers import (BASELINES, BuiltinRelevitate, MaxDamping, Passive, PidRelevitate,
                                WhirlSwitch, make_baseline)
from agents.plant import Plant, make_env
from agents.rollout import run_episodes

SHORT = dict(episode_time=0.03, terminate_on_failure=False)
LEV = {"power_return_time": 0.005}
ENVS = [("RotorDrop-Damping-v0", {}), ("RotorDrop-Relevitate-v0", {"command": "discrete", **LEV}),
        ("RotorDrop-Relevitate-v0", {"command": "continuous", **LEV}),
        ("RotorDrop-Full-v0", {"command": "discrete", **LEV}),
        ("RotorDrop-Full-v0", {"command": "continuous", **LEV})]


@pytest.mark.parametrize("env_id,kw", ENVS)
def test_controllers_obey_the_action_space(env_id, kw):
    """Every supported baseline gives actions inside the env's action space, every step, and
    batched predict agrees with the single-observation call."""
    env = make_env(env_id, overrides={"contact.friction": 0.5}, **SHORT, **kw)
    plant = Plant.from_env(env)
    ran = []
    for name, cls in BASELINES.items():
        if not cls.supports(plant):
            with pytest.raises(ValueError, match="needs action channels"):
                make_baseline(name, plant)
            continue
        ctrl = make_baseline(name, plant)
        obs, _ = env.reset(seed=0)
        done = False
        start = True
        while not done:
            a, state = ctrl.predict(obs, episode_start=np.array([start]))
            start = False
            assert state is None
            assert env.action_space.contains(a if plant.discrete else np.asarray(a, np.float32)), (name, a)
            batch, _ = make_baseline(name, plant).predict(np.stack([obs, obs]))
            assert len(batch) == 2
            obs, _, term, trunc, _ = env.step(a)
            done = term or trunc
        ran.append(name)
    assert "passive" in ran and len(ran) >= 2
    env.close()


def test_unknown_baseline_is_named():
    env = make_env("RotorDrop-Damping-v0", **SHORT)
    with pytest.raises(KeyError, match="max-damping"):
        make_baseline("maximum", Plant.from_env(env))


def _damping_trace(ctrl_cls, mu, episode_time):
    ep = run_episodes("RotorDrop-Damping-v0", ctrl_cls, [0], dict(
        overrides={"contact.friction": mu}, episode_time=episode_time, terminate_on_failure=False),
        record=True)[0]
    names = list(ep.obs_names)
    return ep, ep.obs[:, names.index("damping1")], ep.obs[:, names.index("damping2")]


def test_passive_holds_the_scene_damping_and_max_damping_reaches_c_max():
    """Spec §6: the damper starts at support.damping and follows its command with a 10 ms lag."""
    from physics.scene import load_scene
    s = load_scene("paper").support
    _, c1, c2 = _damping_trace(Passive, 0.1, 0.06)
    np.testing.assert_allclose(c1, s.damping, rtol=1e-6)
    np.testing.assert_allclose(c2, s.damping, rtol=1e-6)
    _, c1, _ = _damping_trace(MaxDamping, 0.1, 0.06)
    # first-order lag: after 50 ms (5 time constants) within 1 % of C_max
    assert c1[-1] == pytest.approx(s.damping_max, rel=0.01)
    assert np.all(np.diff(c1) >= -1e-6)


def test_whirl_switch_reacts_to_whirl_only():
    """At mu = 0.1 the rotor rests at the bottom (no backward orbit): the switch never fires.
    At mu = 0.6 the passive drop whirls (spec §7: orbit angular momentum opposes the spin), and
    the switch raises the damping well above the passive value."""
    from physics.scene import load_scene
    s = load_scene("paper").support
    _, c1, _ = _damping_trace(WhirlSwitch, 0.1, 0.15)
    np.testing.assert_allclose(c1, s.damping, rtol=1e-6)
    _, c1, _ = _damping_trace(WhirlSwitch, 0.6, 0.15)
    assert c1.max() > 0.5 * (s.damping + s.damping_max)


@pytest.mark.parametrize("command,cls", [("discrete", BuiltinRelevitate), ("continuous", PidRelevitate)])
def test_pid_relevitates_after_power_returns(command, cls):
    """Spec §5: with power back the ramped PID lifts the rotor off (contact-free within half the
    clearance); the passive controller leaves it on the retainer bearings."""
    kw = dict(overrides={"contact.friction": 0.1}, episode_time=0.15, terminate_on_failure=False,
              command=command, power_return_time=0.02)
    pid = run_episodes("RotorDrop-Relevitate-v0", cls, [0], kw, record=True)[0]
    passive = run_episodes("RotorDrop-Relevitate-v0", Passive, [0], dict(kw, command="discrete"))[0]
    assert pid.kpis["relevitated"] and not passive.kpis["relevitated"]
    # the lift-off cannot start before the power returns
    assert pid.kpis["relevitation_time_s"] > 0.02
    if command == "continuous":
        power = pid.obs[:, list(pid.obs_names).index("amb_power")]
        currents = pid.actions
        assert np.all(currents[power < 0.5] == 0.0)
        assert np.all(np.abs(currents) <= 1.0)
