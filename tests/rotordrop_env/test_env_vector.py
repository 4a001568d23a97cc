"""The Gymnasium vector environment (each id's vector_entry_point): made by gymnasium.make_vec
for every id, the same episodes as single environments (observations, rewards, flags, infos,
final observations and infos, auto-resets), and Gymnasium's own SAME_STEP SyncVectorEnv."""
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import rotordrop_env
from rotordrop_env.layout import COMMANDS

MODES = [(i, None) for i in rotordrop_env.ENV_IDS if "Relevitate" not in i and "Full" not in i] + \
    [(i, c) for i in rotordrop_env.ENV_IDS if "Relevitate" in i or "Full" in i for c in COMMANDS]


def _kw(command, **kw):
    return dict(kw, command=command) if command else kw


def make_vec(env_id, n, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("error")                 # e.g. missing autoreset metadata
        return gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **kw)


@pytest.mark.parametrize("env_id,command", MODES)
def test_make_vec_builds_the_batched_vector_env_for_every_id_and_command(env_id, command):
    envs = make_vec(env_id, 3, episode_time=0.004, **_kw(command))
    single = gym.make(env_id, **_kw(command))
    assert isinstance(envs.unwrapped, rotordrop_env.RotorDropVectorEnv)
    assert envs.metadata["autoreset_mode"] is AutoresetMode.SAME_STEP
    assert envs.single_observation_space == single.observation_space
    assert envs.single_action_space == single.action_space
    assert envs.observation_space.shape == (3, *single.observation_space.shape)
    obs, info = envs.reset(seed=0)
    assert obs.dtype == np.float32 and obs.shape == envs.observation_space.shape
    assert envs.spec.id == env_id and envs.spec.kwargs["command"] == command if command else True
    for _ in range(5):
        obs, r, term, trunc, info = envs.step(envs.action_space.sample())
        assert obs in envs.observation_space and r.shape == (3,)
    envs.close()


def _compare_info(vec_info: dict, e: int, single: dict) -> None:
    assert {k for k in vec_info if not k.startswith("_")} - {"final_obs", "final_info"} == set(single)
    for k, v in single.items():
        assert vec_info[k][e] == v and vec_info["_" + k][e], k
        assert vec_info[k].dtype == np.asarray(v).dtype, k


@pytest.mark.parametrize("extra", [{}, dict(reward="kpi", sensor_noise=2e-6, obs_latency_steps=(0, 2))])
def test_the_vector_env_steps_as_single_envs_episode_by_episode(extra):
    """16 supervisor Full environments with random scenarios and short episodes (some end
    early at a bearing overload: a low static load rating): each row is the single
    environment of the same seed, through the auto-resets."""
    n, steps = 16, 26
    kw = dict(command="supervisor", randomize=True, episode_time=0.012,
              overrides={"bearing.static_load_rating": 3000.0}, **extra)
    envs = make_vec("RotorDrop-Full-v1", n, **kw)
    singles = [gym.make("RotorDrop-Full-v1", **kw) for _ in range(n)]
    obs, info = envs.reset(seed=5)
    for e, env in enumerate(singles):
        o, i = env.reset(seed=5 + e)
        assert np.array_equal(obs[e], o)
        _compare_info(info, e, i)
        assert envs.unwrapped.envs[e].scenario == env.unwrapped.scenario
    rng = np.random.default_rng(0)
    ends = {"terminated": 0, "truncated": 0}
    for _ in range(steps):
        a = rng.uniform(-1, 1, (n, 8)).astype(np.float32)
        obs, rew, term, trunc, info = envs.step(a)
        assert rew.dtype == np.float64
        for e, env in enumerate(singles):
            o, r, t, tr, i = env.step(a[e])
            assert (rew[e], term[e], trunc[e]) == (r, t, tr)
            if t or tr:
                ends["terminated" if t else "truncated"] += 1
                assert info["_final_obs"][e] and info["_final_info"][e]
                assert np.array_equal(info["final_obs"][e], o)
                _compare_info(info["final_info"], e, i)
                assert i["kpi_episode_time_s"] > 0.0            # the episode's KPIs
                o, i = env.reset()
            else:
                assert not info.get("_final_obs", np.zeros(n, bool))[e]
            assert np.array_equal(obs[e], o)
            _compare_info(info, e, i)
    assert ends["truncated"] >= n and ends["terminated"] >= 1   # both kinds of end were seen


@pytest.mark.parametrize("mode", [AutoresetMode.SAME_STEP, AutoresetMode.NEXT_STEP])
def test_the_vector_env_matches_gymnasiums_sync_vector_env_in_both_autoreset_modes(mode):
    """Gymnasium's own SyncVectorEnv of the same id and autoreset mode: same observations,
    rewards, flags and infos (Gymnasium stores bool infos as object arrays: compared by value),
    also with sensor noise and a drawn latency (each env's random stream)."""
    n, kw = 3, dict(episode_time=0.005, randomize=True, sensor_noise=2e-6, obs_latency_steps=(0, 2))
    ours = make_vec("RotorDrop-Damping-v1", n, autoreset_mode=mode, **kw)
    assert ours.metadata["autoreset_mode"] is mode
    ref = gym.make_vec("RotorDrop-Damping-v1", num_envs=n, vectorization_mode="sync",
                       vector_kwargs={"autoreset_mode": mode}, **kw)
    outs = [v.reset(seed=3) for v in (ours, ref)]
    ours.action_space.seed(0)
    finals = 0
    for _ in range(13):
        a = ours.action_space.sample()
        outs = [v.step(a) for v in (ours, ref)]
        (o1, *rest1, i1), (o2, *rest2, i2) = outs
        assert np.array_equal(o1, o2)
        for x, y in zip(rest1, rest2):
            assert np.array_equal(x, y)
        assert set(i1) == set(i2)
        for key in i1:
            if key == "final_info":
                finals += 1
                assert set(i1[key]) == set(i2[key])
                for k2 in i1[key]:
                    assert np.array_equal(i1[key][k2], i2[key][k2].astype(i1[key][k2].dtype)), k2
            elif key == "final_obs":
                for x, y in zip(i1[key], i2[key]):
                    assert (x is None and y is None) or np.array_equal(x, y)
            else:
                assert np.array_equal(i1[key], i2[key].astype(i1[key].dtype)), key
    # two episode ends (5-step episodes): SAME_STEP reports them with final infos
    assert finals == (2 if mode is AutoresetMode.SAME_STEP else 0)


def test_gymnasiums_observation_wrappers_take_the_next_step_mode():
    """Gymnasium's vector observation wrappers (NormalizeObservation...) accept NEXT_STEP only;
    its RecordEpisodeStatistics takes both."""
    from gymnasium.wrappers.vector import NormalizeObservation, RecordEpisodeStatistics
    with pytest.raises(ValueError, match="NEXT_STEP"):
        NormalizeObservation(make_vec("RotorDrop-Damping-v1", 2, episode_time=0.003))
    for mode in ("NextStep", "SameStep"):
        envs = RecordEpisodeStatistics(make_vec("RotorDrop-Damping-v1", 2, episode_time=0.003,
                                                autoreset_mode=mode))
        if mode == "NextStep":
            envs = NormalizeObservation(envs)
        envs.reset(seed=0)
        lengths = []
        for _ in range(8):
            *_, info = envs.step(envs.action_space.sample())
            if "episode" in info:
                lengths += list(info["episode"]["l"][info["_episode"]])
        assert lengths == [3, 3, 3, 3]                  # two episodes of each env
    with pytest.raises(ValueError, match="autoreset_mode"):
        make_vec("RotorDrop-Damping-v1", 2, autoreset_mode="Disabled")


def test_sync_and_async_make_vec_still_work():
    for mode in ("sync", "async"):
        envs = gym.make_vec("RotorDrop-Passive-v1", num_envs=2, vectorization_mode=mode,
                            episode_time=0.003)
        envs.reset(seed=0)
        for _ in range(4):
            *_, info = envs.step(envs.action_space.sample())
        assert "kpi_peak_contact_force_N" in info
        envs.close()


def test_a_copied_vector_env_steps_like_the_original_and_renders():
    import copy
    import pickle
    envs = make_vec("RotorDrop-Full-v1", 2, episode_time=0.003, render_mode="rgb_array",
                    command="continuous", autoreset_mode="NextStep")
    envs.reset(seed=0)
    envs.action_space.seed(0)
    acts = [envs.action_space.sample() for _ in range(8)]
    envs.step(acts[0])
    for twin in (copy.deepcopy(envs), pickle.loads(pickle.dumps(envs))):
        assert twin.unwrapped.envs[0]._b.y is not envs.unwrapped.envs[0]._b.y
    twin = copy.deepcopy(envs)
    for a in acts[1:]:                                  # through the episode ends
        (o1, r1, t1, u1, _), (o2, r2, t2, u2, _) = envs.step(a), twin.step(a)
        assert np.array_equal(o1, o2) and np.array_equal(r1, r2)
        assert np.array_equal(t1 | u1, t2 | u2)
        f1, f2 = envs.render(), twin.render()
        assert len(f1) == 2 and all(np.array_equal(x, y) for x, y in zip(f1, f2))
    envs.close()
    with pytest.raises(gym.error.ClosedEnvironmentError):
        envs.step(acts[0])


def test_the_vector_env_set_attr_call_and_errors():
    envs = make_vec("RotorDrop-Damping-v1", 2, episode_time=0.003)
    with pytest.raises(gym.error.ResetNeeded):
        envs.step(np.zeros((2, 2), np.float32))
    envs.reset(seed=0)
    envs.unwrapped.set_attr("w_whirl", [1.0, 2.0])
    assert envs.unwrapped.get_attr("w_whirl") == (1.0, 2.0)
    with pytest.raises(AttributeError, match="control_dt is fixed"):
        envs.unwrapped.set_attr("control_dt", 1e-4)
    assert len(envs.unwrapped.call("kpis")) == 2
    with pytest.raises(ValueError, match="out-of-range action"):
        envs.step(np.full((2, 2), 2.0, np.float32))
    with pytest.raises(ValueError, match="max_episode_steps"):
        make_vec("RotorDrop-Damping-v1", 2, max_episode_steps=3)


def test_a_flexible_vector_env_steps_as_single_envs_episode_by_episode():
    """make_vec with the paper-flexible scene (supervisor Full, random scenarios): each row is
    the single environment of the same seed, through the auto-resets."""
    n, steps = 3, 8
    kw = dict(scene="paper-flexible", command="supervisor", randomize=True, episode_time=0.004)
    envs = make_vec("RotorDrop-Full-v1", n, **kw)
    singles = [gym.make("RotorDrop-Full-v1", **kw) for _ in range(n)]
    assert envs.unwrapped.envs[0].model.elastic_modes == 2
    obs, info = envs.reset(seed=9)
    for e, env in enumerate(singles):
        o, i = env.reset(seed=9 + e)
        assert np.array_equal(obs[e], o)
        _compare_info(info, e, i)
    rng = np.random.default_rng(2)
    ends = 0
    for _ in range(steps):
        a = rng.uniform(-1, 1, (n, 8)).astype(np.float32)
        obs, rew, term, trunc, info = envs.step(a)
        for e, env in enumerate(singles):
            o, r, t, tr, i = env.step(a[e])
            assert (rew[e], term[e], trunc[e]) == (r, t, tr)
            if t or tr:
                ends += 1
                assert np.array_equal(info["final_obs"][e], o)
                o, i = env.reset()
            assert np.array_equal(obs[e], o)
            _compare_info(info, e, i)
    assert ends == 2 * n                             # every row ended at the time limit twice
