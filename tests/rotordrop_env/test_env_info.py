"""The info contract any RL library can rely on (no RL library needed here): the same keys at
reset and at every step, numpy values only, no NaN (documented sentinels), for every id and
command mode, single and vectorised; the safety cost channel; the KPI reward (reward="kpi")."""
import math

import gymnasium as gym
import numpy as np
import pytest
from stable_baselines3.common.env_util import make_vec_env

import rotordrop_env
from rotordrop_env.info import COST_TERMS, MISSING, PEAK_KEYS
from rotordrop_env.layout import COMMANDS
from rotordrop_env.reward import KPI_WEIGHTS, kpi_potential

from helpers import run_env_checkers

_AMB = ("Relevitate", "Full", "Recover")
MODES = [(i, None) for i in rotordrop_env.ENV_IDS if not any(a in i for a in _AMB)] + \
    [(i, c) for i in rotordrop_env.ENV_IDS if any(a in i for a in _AMB) for c in COMMANDS]
#: Recover: a hard early shock, so that the overloaded episode ends within its 12 ms
EARLY_SHOCK = {"events": {"kinds": ("shock",), "shock_peak_g": (20.0, 20.0),
                          "shock_duration": (0.006, 0.006), "delay": (0.001, 0.001)}}
#: a low static load rating: the drop overloads the bearing within ~10 ms (a terminated end)
OVERLOAD = {"bearing.static_load_rating": 1500.0}


def _kw(command, **kw):
    return dict(kw, command=command) if command else kw


def _event(env_id):
    return EARLY_SHOCK if "Recover" in env_id else {}


def _check_values(info: dict, where: str) -> None:
    for k, v in info.items():
        assert isinstance(v, (np.floating, np.bool_, np.integer)), f"{where}: {k} is {type(v)}"
        assert not (isinstance(v, np.floating) and math.isnan(v)), f"{where}: {k} is NaN"
    assert info["cost"] >= 0.0
    assert info["cost"] == sum(info[k] for k in COST_TERMS)


@pytest.mark.parametrize("env_id,command", MODES)
def test_info_has_the_same_numpy_keys_at_reset_and_every_step_and_no_nan(env_id, command):
    """Through a terminated episode (bearing overload), a TimeLimit-truncated one and one
    truncated at the environment's own time limit, with random actions."""
    ends = []
    for max_steps, overrides in ((None, OVERLOAD), (3, None), (None, None)):
        env = gym.make(env_id, episode_time=0.012, overrides=overrides,
                       max_episode_steps=max_steps,
                       **_kw(command, **(_event(env_id) if overrides else {})))
        env.action_space.seed(0)
        _, info = env.reset(seed=1)
        keys = set(info)
        _check_values(info, "reset")
        assert "scenario" not in info and isinstance(env.unwrapped.scenario, dict)
        done = False
        while not done:
            *_, term, trunc, info = env.step(env.action_space.sample())
            assert set(info) == keys
            _check_values(info, "step")
            done = term or trunc
        ends.append((term, trunc))
        assert info["kpi_episode_time_s"] > 0.0
        if not info["kpi_relevitated"]:                 # the documented sentinel
            assert info["kpi_relevitation_time_s"] == MISSING
    assert ends == [(True, False), (False, True), (False, True)]
    assert info["kpi_max_ball_load_N"] > 0.0 and info["kpi_max_contact_pressure_MPa"] > 0.0


def test_the_damping_env_reports_no_relevitation_with_the_sentinel():
    env = gym.make("RotorDrop-Damping-v1", episode_time=0.003)
    env.reset(seed=0)
    for _ in range(3):
        *_, info = env.step(np.zeros(2, np.float32))
    assert info["kpi_relevitated"] == np.False_ and info["kpi_relevitation_time_s"] == MISSING
    assert "relevitated" not in info


def test_without_ball_model_the_ball_kpis_are_the_sentinel():
    env = gym.make("RotorDrop-Passive-v1", episode_time=0.003,
                   overrides={"effects.retainer_bearing": "linear"})
    *_, info = (env.reset(seed=0), env.step(np.zeros(1, np.float32)))[1]
    assert info["kpi_max_ball_load_N"] == MISSING == info["kpi_max_contact_pressure_MPa"]


@pytest.mark.parametrize("env_id,command", MODES)
def test_vectorised_infos_keep_the_contract(env_id, command):
    """The Gymnasium vector env: one numpy array per key with an all-True mask, at reset and
    every step, final infos included; the SB3 VecEnv: the single env's dicts."""
    kw = _kw(command, episode_time=0.004)
    envs = gym.make_vec(env_id, num_envs=2, vectorization_mode="vector_entry_point", **kw)
    _, info = envs.reset(seed=0)
    keys = set(info)
    ended = 0
    for _ in range(5):
        *_, info = envs.step(envs.action_space.sample())
        ended += "final_info" in info
        finals = {"final_obs", "_final_obs", "final_info", "_final_info"}
        assert set(info) - finals == keys
        for part in ({k: v for k, v in info.items() if k not in finals}, info.get("final_info", {})):
            for k, v in part.items():
                assert isinstance(v, np.ndarray) and v.shape == (2,) and v.dtype != object, k
                assert not (v.dtype.kind == "f" and np.isnan(v).any()), k
    assert ended == 1                                   # the episodes ended at step 4
    venv = rotordrop_env.make_batched(env_id, 2, seed=0, n_threads=1, **kw)
    venv.reset()
    single_keys = set(gym.make(env_id, **kw).reset(seed=0)[1])
    assert set(venv.reset_infos[0]) == single_keys
    for _ in range(5):
        *_, infos = venv.step(np.stack([venv.action_space.sample() for _ in range(2)]))
        for i in infos:
            assert set(i) - {"terminal_observation", "TimeLimit.truncated"} == single_keys
            _check_values({k: v for k, v in i.items() if k in single_keys}, "sb3")


def test_the_cost_counts_stator_contact_and_bearing_overload():
    """Safety-Gymnasium convention: cost >= 0 each step; an overload step costs 1 (the
    static safety factor C_0 / F below 1), an uneventful one 0; the contact-law validity
    component is there and 0."""
    env = gym.make("RotorDrop-Damping-v1", episode_time=0.05, overrides=OVERLOAD)
    env.reset(seed=0)
    costs = []
    while True:
        *_, term, trunc, info = env.step(np.zeros(2, np.float32))
        costs.append((info["cost"], info["cost_bearing_overload"], info["cost_stator_contact"],
                      info["cost_contact_validity"]))
        if term or trunc:
            break
    assert term and info["kpi_bearing_overload"]
    assert costs[-1][:2] == (1.0, 1.0) and costs[-1][3] == 0.0
    assert all(c == (0.0, 0.0, 0.0, 0.0) for c in costs[:-1])
    env = gym.make("RotorDrop-Damping-v1", episode_time=0.05, terminate_on_failure=False,
                   overrides={"amb.air_gap": 5e-4, "contact.friction": 0.5})
    env.reset(seed=0)
    infos = [env.step(np.zeros(2, np.float32))[4] for _ in range(50)]  # a whirl reaches the stator
    stator = np.array([i["cost_stator_contact"] for i in infos])
    assert 0 < stator.sum() < 50 and set(stator) == {0.0, 1.0}
    assert all(i["cost"] == i["cost_stator_contact"] + i["cost_bearing_overload"] for i in infos)
    assert infos[-1]["kpi_stator_contact"]


# ----------------------------------------------------------------------- KPI reward --
W = dict(w_whirl=2.0, w_verdict=0.5, w_severity=0.3, w_force=0.25, w_disp=0.75, force_ref=5e3,
         disp_ref_um=600.0, whirl_ref_revs=10.0)


@pytest.mark.parametrize("env_id,command", MODES)
def test_both_checkers_pass_with_the_kpi_reward(env_id, command):
    run_env_checkers(lambda: gym.make(env_id, reward="kpi", episode_time=0.01, **_kw(command)))


def test_the_kpi_reward_returns_minus_the_final_potential():
    env = gym.make("RotorDrop-Damping-v1", reward="kpi", reward_kwargs=W, episode_time=0.06,
                   terminate_on_failure=False, overrides={"contact.friction": 0.6})
    env.reset(seed=0)
    env.action_space.seed(0)
    ret, done = 0.0, False
    while not done:
        _, r, term, trunc, info = env.step(env.action_space.sample())
        assert isinstance(r, float)
        ret += r
        done = term or trunc
    assert info["kpi_peak_contact_force_N"] > 0.0
    assert ret == pytest.approx(-kpi_potential(*(info[k] for k in PEAK_KEYS), **W), rel=1e-9)


def test_the_default_reward_is_unchanged_and_the_kpi_reward_equals_the_sb3_wrapper():
    """The default reward is the sum of its terms; the env's reward="kpi" is what the SB3
    wrapper agents.learning.reward.KpiReward computes on default-reward envs (one implementation),
    also for re-levitation (bonus, time charge) and after auto-resets."""
    from agents.learning.reward import KpiReward
    kw = dict(command="discrete", power_return_time=0.002, episode_time=0.05,
              terminate_on_failure=False, overrides={"contact.friction": 0.1})
    wk = dict(W, w_relevitate=0.7, w_time=1.5)
    env = gym.make("RotorDrop-Relevitate-v1", **kw)
    env.reset(seed=0)
    for _ in range(5):
        _, r, *_, info = env.step(1)
        assert r == sum(info["reward_" + t] for t in
                        ("whirl", "contact", "displacement", "effort", "success", "failure"))
    own = make_vec_env("RotorDrop-Relevitate-v1", 2, seed=0,
                       env_kwargs=dict(kw, reward="kpi", reward_kwargs=wk))
    wrapped = KpiReward(make_vec_env("RotorDrop-Relevitate-v1", 2, seed=0, env_kwargs=kw), **wk)
    batched = rotordrop_env.make_batched("RotorDrop-Relevitate-v1", 2, seed=0, n_threads=1,
                                         reward="kpi", reward_kwargs=wk, **kw)
    for v in (own, wrapped, batched):
        v.reset()
    relev = 0
    for _ in range(110):                                  # past two episode ends
        a = np.ones(2, dtype=np.int64)
        (_, r1, d1, i1), (_, r2, d2, _), (_, r3, d3, _) = (v.step(a) for v in (own, wrapped, batched))
        np.testing.assert_allclose(r1, r2, rtol=1e-6, atol=1e-7)
        np.testing.assert_allclose(r1, r3, rtol=1e-6, atol=1e-7)
        assert np.array_equal(d1, d2) and np.array_equal(d1, d3)
        relev += sum(bool(i["relevitated"]) for i in i1)
    assert relev > 0                                      # the bonus was in play


def test_reward_kwargs_are_checked():
    with pytest.raises(ValueError, match=r"reward_kwargs: unknown key 'w_wirl' \(did you mean w_whirl\?\)"):
        gym.make("RotorDrop-Damping-v1", reward="kpi", reward_kwargs={"w_wirl": 1.0})
    with pytest.raises(ValueError, match=r"reward_kwargs.force_ref must be a finite number > 0"):
        gym.make("RotorDrop-Damping-v1", reward="kpi", reward_kwargs={"force_ref": 0.0})
    with pytest.raises(ValueError, match="reward_kwargs are the weights of reward='kpi'"):
        gym.make("RotorDrop-Damping-v1", reward_kwargs={"w_whirl": 1.0})
    with pytest.raises(ValueError, match="reward = 'kpis' is not a reward"):
        gym.make("RotorDrop-Damping-v1", reward="kpis")
    assert set(KPI_WEIGHTS) >= set(W)


@pytest.mark.parametrize("relevitate", [False, True])
def test_the_sb3_rows_are_the_single_env_info_of_each_row(relevitate):
    """row_infos (the SB3 VecEnv's list) gives each row exactly what info_dict gives that row
    alone: the same keys in the same order, values and numpy types; every dict and scalar its
    own (no row shares a value with another)."""
    from rotordrop_env.info import info_dict, row_infos
    from rotordrop_env import kernels as K
    rng = np.random.default_rng(0)
    v = rng.normal(size=(5, K.N_V))
    latency = np.arange(5, dtype=np.int64)
    rows = row_infos(v, latency, relevitate)
    for e, row in enumerate(rows):
        one = info_dict(v[e], int(latency[e]), relevitate)
        assert list(row) == list(one)
        for k in one:
            assert type(row[k]) is type(one[k]) and row[k] == one[k], k
        assert row["time_s"] is not row["kpi_episode_time_s"]
    assert rows[0]["time_s"] != rows[1]["time_s"] and rows[0] is not rows[1]
