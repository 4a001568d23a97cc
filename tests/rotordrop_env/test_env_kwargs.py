"""Environment kwargs: user-fixed keys stay out of the randomisation, stable draws, the scenario
in reset's info, and clear errors for bad ranges, wrong types and bad discrete actions."""
import math

import gymnasium as gym
import numpy as np
import pytest

import rotordrop_env  # noqa: F401  (registers the ids)
from physics.scene import SceneError
from rotordrop_env import kernels as K
from rotordrop_env.scenario import DEFAULT_RANGES, parse_range

KW = dict(episode_time=0.002, randomize=True)
# the draws of seed 0 before user-fixed keys were kept (training reproducibility: unchanged)
DAMPING_SEED0 = {"contact.friction": 0.3547846749285818, "rotor.speed_rpm": 9079.146855055482,
                 "support.damping": 3066.0393701657113, "support.stiffness": 5395420.222690695,
                 "unbalance.mass": 0.0017199053588004087}
RELEV_SEED0 = {"contact.friction": 0.3547846749285818, "rotor.speed_rpm": 8163.8940957447785,
               "support.damping": 2898.223267984943, "support.stiffness": 211597475.87387675,
               "unbalance.mass": 0.0018691333659165827}


def scenario(env_id, seed=0, **kw):
    env = gym.make(env_id, **{**KW, **kw})
    _, info = env.reset(seed=seed)
    return env.unwrapped.scenario, env.unwrapped.scene


def test_draws_without_fixed_keys_are_unchanged():
    sc, scene = scenario("RotorDrop-Damping-v1")
    assert sc == DAMPING_SEED0                            # bit-identical
    assert scene.contact.friction == DAMPING_SEED0["contact.friction"]
    sc, _ = scenario("RotorDrop-Relevitate-v1")
    assert {k: v for k, v in sc.items() if k != "power_return_time"} == RELEV_SEED0


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_overrides_keep_their_value_and_the_other_draws(seed):
    free, _ = scenario("RotorDrop-Damping-v1", seed)
    sc, scene = scenario("RotorDrop-Damping-v1", seed, overrides={"contact.friction": 0.45})
    assert scene.contact.friction == 0.45 and sc["contact.friction"] == 0.45
    assert {k: v for k, v in sc.items() if k != "contact.friction"} == \
        {k: v for k, v in free.items() if k != "contact.friction"}


def test_a_none_range_fixes_the_key_without_shifting_the_others():
    sc, scene = scenario("RotorDrop-Damping-v1", randomization={"rotor.speed_rpm": None})
    assert scene.rotor.speed_rpm == 10000.0 == sc["rotor.speed_rpm"]      # the scene's value
    assert {k: v for k, v in sc.items() if k != "rotor.speed_rpm"} == \
        {k: v for k, v in DAMPING_SEED0.items() if k != "rotor.speed_rpm"}


def test_power_return_kwarg_is_kept_under_randomisation():
    sc, scene = scenario("RotorDrop-Relevitate-v1", power_return_time=0.03)
    assert sc["power_return_time"] == pytest.approx(0.03, abs=1e-12)
    assert {k: v for k, v in sc.items() if k != "power_return_time"} == RELEV_SEED0
    assert scene.contact.friction == RELEV_SEED0["contact.friction"]


def test_reset_info_reports_the_machine_used():
    sc, scene = scenario("RotorDrop-Full-v1", randomize=False,
                         overrides={"contact.friction": 0.4})
    assert set(sc) == set(DEFAULT_RANGES)
    assert sc["contact.friction"] == 0.4 and sc["support.stiffness"] == scene.support.stiffness
    assert sc["power_return_time"] == pytest.approx(0.05)
    assert all(type(v) is float for v in sc.values())
    sc, scene = scenario("RotorDrop-Passive-v1", seed=3)
    assert set(sc) == set(DEFAULT_RANGES) - {"power_return_time"}
    assert all(sc[k] == scene.get(k) for k in sc)


def test_batched_envs_keep_the_fixed_keys():
    from rotordrop_env import make_batched
    vec = make_batched("RotorDrop-Damping-v1", 2, seed=0, n_threads=1,
                       overrides={"contact.friction": 0.45}, **KW)
    vec.reset()
    assert [s["contact.friction"] for s in vec.get_attr("scenario")] == [0.45, 0.45]
    assert vec.get_attr("scenario")[0]["unbalance.mass"] == DAMPING_SEED0["unbalance.mass"]


def test_default_ranges_are_valid():
    for key, spec in DEFAULT_RANGES.items():
        assert parse_range(key, spec) == spec


@pytest.mark.parametrize("env_id,randomization,match", [
    ("RotorDrop-Damping-v1", {"support.stiffness": (1e3, 1e12)},
     r"randomization\['support.stiffness'\].*\[10000, 1e\+11\] N/m"),
    ("RotorDrop-Damping-v1", {"contact.friction": 0.3}, r"randomization\['contact.friction'\].*\(low, high\)"),
    ("RotorDrop-Damping-v1", {"contact.friction": (0.5, 0.1)}, r"low <= high"),
    ("RotorDrop-Damping-v1", {"contact.friction": (0.1, float("nan"))}, r"finite"),
    ("RotorDrop-Damping-v1", {"contact.friction": ("0.1", 0.3)}, r"real numbers"),
    ("RotorDrop-Damping-v1", {"contact.friction": ("gauss", 0.1, 0.3)}, r"uniform, log_uniform"),
    ("RotorDrop-Damping-v1", {"support.damping": ("log_uniform", 0.0, 10.0)}, r"low > 0"),
    ("RotorDrop-Damping-v1", {"contact.frictoin": (0.1, 0.3)}, r"randomization: unknown.*contact.frictoin"),
    ("RotorDrop-Damping-v1", {"bearing.balls": (8, 12)}, r"bearing.balls is a int parameter"),
    ("RotorDrop-Damping-v1", {"power_return_time": (0.01, 0.02)}, r"re-levitation environments only"),
    ("RotorDrop-Passive-v1", {"power_return_time": None}, r"re-levitation environments only"),
    ("RotorDrop-Relevitate-v1", {"power_return_time": (0.01, 200.0)}, r"\[0, 100\] s"),
    ("RotorDrop-Damping-v1", [("contact.friction", (0.1, 0.3))], r"must be a dict"),
])
def test_bad_randomization_fails_at_construction(env_id, randomization, match):
    with pytest.raises(ValueError, match=match):
        gym.make(env_id, randomization=randomization)


def test_unknown_key_is_a_scene_error():
    with pytest.raises(SceneError):
        gym.make("RotorDrop-Damping-v1", randomization={"contact.frictoin": None})


@pytest.mark.parametrize("kwargs,match", [
    (dict(terminate_on_failure="no"), r"terminate_on_failure = 'no' must be a bool"),
    (dict(randomize="yes"), r"randomize = 'yes' must be a bool"),
    (dict(full_state=1), r"full_state = 1 must be a bool"),
    (dict(control_dt="1e-3"), r"control_dt = '1e-3' must be a real number"),
    (dict(episode_time=True), r"episode_time = True must be a real number"),
    (dict(samples_per_step=2.5), r"samples_per_step = 2.5 must be an integer"),
    (dict(samples_per_step=float("nan")), r"samples_per_step = nan must be in"),
    (dict(w_whirl="10"), r"w_whirl = '10' must be a real number"),
    (dict(overrides="contact.friction=0.3"), r"overrides = 'contact.friction=0.3' must be a dict"),
])
def test_wrong_typed_kwargs_name_the_kwarg(kwargs, match):
    with pytest.raises(ValueError, match=match):
        gym.make("RotorDrop-Damping-v1", **kwargs)


def test_numpy_bools_and_numbers_are_accepted():
    env = gym.make("RotorDrop-Damping-v1", randomize=np.bool_(True), full_state=np.False_,
                   control_dt=np.float32(1e-3), samples_per_step=np.int64(5), episode_time=0.002)
    assert env.unwrapped.randomize is True and env.unwrapped.full_state is False


@pytest.mark.parametrize("action", [2, -1, np.int64(3)])
def test_discrete_action_error_says_0_or_1(action):
    env = gym.make("RotorDrop-Relevitate-v1", episode_time=0.002)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"must be 0 \(stay off\) or 1 \(switch on\)") as exc:
        env.step(action)
    assert "[-1, 1]" not in str(exc.value)


def test_reset_scenario_option_must_be_a_dict():
    env = gym.make("RotorDrop-Damping-v1", episode_time=0.002)
    with pytest.raises(ValueError, match="scenario = 'contact.friction=0.3' is not a dict"):
        env.reset(options={"scenario": "contact.friction=0.3"})


def test_randomization_without_randomize_is_an_error():
    with pytest.raises(ValueError, match=r"randomization = .*contact.friction.* no effect without "
                                         r"randomize=True"):
        gym.make("RotorDrop-Damping-v1", randomization={"contact.friction": (0.1, 0.3)})
    env = gym.make("RotorDrop-Damping-v1", randomization={}, episode_time=0.002)   # nothing lost
    assert env.unwrapped.randomize is False


@pytest.mark.parametrize("env_id,kwargs,match", [
    ("RotorDrop-Damping-v1", dict(overrides={"contact.friction": 0.45},
                                  randomization={"contact.friction": (0.1, 0.3)}),
     r"randomization\['contact.friction'\] = \(0.1, 0.3\) .* overrides\['contact.friction'\] fixes"),
    ("RotorDrop-Relevitate-v1", dict(power_return_time=0.03,
                                     randomization={"power_return_time": (0.02, 0.04)}),
     r"randomization\['power_return_time'\] = .* the power_return_time = 0.03 kwarg fixes"),
])
def test_a_range_for_a_fixed_key_is_an_error(env_id, kwargs, match):
    with pytest.raises(ValueError, match=match):
        gym.make(env_id, **{**KW, **kwargs})


def test_a_none_range_agrees_with_the_fixing_kwarg():
    sc, _ = scenario("RotorDrop-Relevitate-v1", power_return_time=0.03,
                     overrides={"contact.friction": 0.45},
                     randomization={"power_return_time": None, "contact.friction": None})
    assert sc["power_return_time"] == 0.03 and sc["contact.friction"] == 0.45


@pytest.mark.parametrize("seconds", [0.05, 0.08, 0.03, 0.0333])
def test_power_return_is_reported_without_round_off(seconds):
    """The report is the applied time (on the 1 ms grid) rounded to 1e-12 s; the physics keeps
    the unrounded instant."""
    env = gym.make("RotorDrop-Relevitate-v1", power_return_time=seconds, episode_time=0.002)
    _, info = env.reset(seed=0)
    steps = math.ceil(seconds / 1e-3 - 1e-9)
    on_grid = round(steps * 1e-3, 12)
    assert env.unwrapped.scenario["power_return_time"] == on_grid
    assert repr(env.unwrapped.scenario["power_return_time"]) == repr(round(on_grid, 6))
    C = env.unwrapped._b.C
    t_fault = C[K.C_T_FAULT]
    assert C[K.C_T_POWER] == t_fault + steps * 1e-3


def test_drawn_power_returns_are_reported_cleanly():
    env = gym.make("RotorDrop-Relevitate-v1", **KW)
    for seed in range(5):
        _, info = env.reset(seed=seed)
        value = env.unwrapped.scenario["power_return_time"]
        assert value == round(value, 12) and len(repr(value)) <= 6     # e.g. 0.073
