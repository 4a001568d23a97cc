"""The Recover task: AMBs on from the start, one event per episode drawn from its ranges, the
recovery verdict (contact-free for the hold at the end, not latched), seeding, the vector env,
and the checks of its kwargs."""
import math

import gymnasium as gym
import numpy as np
import pytest

import rotordrop_env
from rotordrop_env.events import EVENT_KINDS, EventRanges
from rotordrop_env.info import MISSING

RECOVER = "RotorDrop-Recover-v1"
#: a transient load, half-sine over 1 s from 5 ms on (downward, 4-5 kN over the episode's last
#: 0.2 s), still on at the end: beyond what the AMBs hold, the rotor rubs to the end
HELD_LOAD = {"kinds": ("load",), "load_peak": (5000.0, 5000.0), "load_duration": (1.0, 1.0),
             "load_angle_deg": (-90.0, -90.0)}
#: a 3 kN, 10 ms half-sine load: the rotor is pushed into contact and pulled back
SHORT_LOAD = dict(HELD_LOAD, load_peak=(3000.0, 3000.0), load_duration=(0.01, 0.01))


def _episode(seed=0, action=None, **kw):
    env = gym.make(RECOVER, **kw)
    obs, info = env.reset(seed=seed)
    a = np.zeros(env.action_space.shape, np.float32) if action is None else action
    obs_seq, forces, infos = [obs], [], [info]
    done = False
    while not done:
        obs, _, term, trunc, info = env.step(a)
        obs_seq.append(obs)
        forces.append(info["contact_force_N"])
        infos.append(info)
        done = term or trunc
    return env.unwrapped, np.array(obs_seq), np.array(forces), infos, term


def test_the_ambs_levitate_from_the_start_without_an_action():
    """No event: the built-in PID holds the rotor centred, powered and on, contact-free for the
    whole episode; the episode is recovered (the hold is met) from its start."""
    env, obs, forces, infos, term = _episode(events={"delay": (1.0, 1.0)}, episode_time=0.1)
    names = env.obs_names
    assert obs[0, names.index("amb_power")] == 1.0 and obs[0, names.index("controller_on")] == 1.0
    pos = obs[:, [names.index(n) for n in ("x1", "y1", "x2", "y2")]]
    assert np.abs(pos).max() < 0.2                  # clearance-normalised: well centred
    assert forces.max() == 0.0 and not term
    # recovered from the first monitor sample on (5 per step)
    assert infos[-1]["kpi_relevitated"]
    assert infos[-1]["kpi_relevitation_time_s"] == pytest.approx(env.dt / 5)
    assert infos[-1]["kpi_friction_energy_J"] == 0.0


def test_a_short_overload_is_recovered_after_it_ends():
    env, _, forces, infos, term = _episode(events=SHORT_LOAD)
    k = infos[-1]
    ev_t = env.scenario["event_time"]
    assert env.scenario["event"] == "load" and not term
    assert forces.max() > 0.0 and k["kpi_relevitated"]
    # the final contact-free period starts after the contact, which the load caused
    last_contact = (np.nonzero(forces)[0].max() + 1) * env.dt
    assert ev_t < k["kpi_relevitation_time_s"] <= last_contact + env.dt
    assert k["kpi_friction_energy_J"] > 0.0


def test_a_held_overload_rubs_to_the_end_and_is_not_recovered():
    env, obs, forces, infos, term = _episode(events=HELD_LOAD)
    k = infos[-1]
    assert not term and not k["kpi_relevitated"]
    assert k["kpi_relevitation_time_s"] == MISSING
    assert (forces[-int(0.05 / env.dt):] > 0.0).all()          # contact in the final hold
    # friction energy: what the rotor's spin lost bounds what the rub dissipated
    w = obs[:, env.obs_names.index("rotor_speed")] * env.obs_scale[env.obs_names.index("rotor_speed")]
    lost = 0.5 * env.scene.rotor.polar_inertia * (w[0] ** 2 - w[-1] ** 2)
    assert 0.0 < k["kpi_friction_energy_J"] <= lost * 1.05


def test_recovery_is_lost_again_on_contact():
    """Not latched: 100 ms contact-free (recovered), then a held overload (not recovered)."""
    env, _, forces, infos, _ = _episode(events=dict(HELD_LOAD, delay=(0.1, 0.1)))
    rec = np.array([bool(i["kpi_relevitated"]) for i in infos])
    assert rec[int(0.08 / env.dt)] and not rec[-1]
    first = np.nonzero(forces)[0].min()
    assert not rec[first + 1:].any()


def test_same_seed_same_event_and_trajectory_and_seeds_differ():
    a = _episode(seed=3, episode_time=0.05)
    b = _episode(seed=3, episode_time=0.05)
    c = _episode(seed=4, episode_time=0.05)
    assert a[0].scenario == b[0].scenario and np.array_equal(a[1], b[1])
    assert a[0].scenario != c[0].scenario


def test_every_kind_is_drawn_within_its_ranges():
    env = gym.make(RECOVER, episode_time=0.002)
    seen = set()
    for seed in range(30):
        env.reset(seed=seed)
        sc = env.unwrapped.scenario
        seen.add(sc["event"])
        r = EventRanges()
        assert r.delay[0] - 1e-3 <= sc["event_time"] <= r.delay[1] + 1e-3
        if sc["event"] == "shock":
            assert r.shock_peak_g[0] <= sc["ground.pulse_peak_g"] <= r.shock_peak_g[1]
            assert r.shock_duration[0] <= sc["ground.pulse_duration"] <= r.shock_duration[1]
    assert seen == set(EVENT_KINDS)


def test_the_vector_envs_agree_with_the_single_env():
    kw = dict(episode_time=0.02)
    single = []
    for seed in (5, 6):
        env = gym.make(RECOVER, **kw)
        env.reset(seed=seed)
        for _ in range(10):
            obs, *_ = env.step(np.zeros(6, np.float32))
        single.append(obs)
    venv = gym.make_vec(RECOVER, num_envs=2, vectorization_mode="vector_entry_point", **kw)
    venv.reset(seed=5)
    for _ in range(10):
        obs, _, _, _, info = venv.step(np.zeros((2, 6), np.float32))
    np.testing.assert_allclose(obs, np.array(single), rtol=1e-6, atol=1e-7)
    assert "kpi_friction_energy_J" in info and info["kpi_relevitated"].shape == (2,)
    sb3 = rotordrop_env.make_batched(RECOVER, n_envs=2, seed=5, **kw)
    sb3.reset()
    for _ in range(10):
        obs, *_ = sb3.step(np.zeros((2, 6), np.float32))
    np.testing.assert_allclose(obs, np.array(single), rtol=1e-6, atol=1e-7)


@pytest.mark.parametrize("kwargs,words", [
    ({"events": {"shock_peak_g": (5.0, 2000.0)}}, ["events['shock_peak_g']", "[0.1, 1000] g"]),
    ({"events": {"shock_duration": (0.02, 0.01)}}, ["events['shock_duration']", "low <= high"]),
    ({"events": {"kinds": ("quake",)}}, ["events['kinds']", "'shock'"]),
    ({"events": {"peak": (1, 2)}}, ["unknown field", "shock_peak_g"]),
    ({"events": [1, 2]}, ["events = [1, 2]", "dict"]),
    ({"power_return_time": 0.05}, ["power_return_time", "stay powered"]),
])
def test_bad_kwargs_name_the_parameter_and_its_range(kwargs, words):
    with pytest.raises(ValueError) as err:
        gym.make(RECOVER, **kwargs)
    for w in words:
        assert w in str(err.value)


def test_events_are_refused_on_a_task_without_events():
    with pytest.raises(ValueError, match="events = .* applies to the tasks with an event"):
        gym.make("RotorDrop-Full-v1", events={"kinds": ("shock",)})


def test_the_event_keys_leave_the_state_layout_alone():
    env = gym.make(RECOVER, episode_time=0.002)
    sizes = set()
    for seed in range(12):
        env.reset(seed=seed)
        sizes.add(env.unwrapped.model.n_state)
    assert len(sizes) == 1
    assert math.isclose(env.unwrapped.scenario["event_time"] % env.unwrapped.dt, 0.0,
                        abs_tol=1e-9) or math.isclose(
        env.unwrapped.scenario["event_time"] % env.unwrapped.dt, env.unwrapped.dt, rel_tol=1e-6)
