"""Imperfect sensing (kwargs sensor_noise, obs_latency_steps; rotordrop_env.sensors): the noise
has the requested standard deviation and the physics' built-in PID sees the same samples, the
latency shifts the observation by exactly k steps and the physics does not see it, same seed -> same episode (single env and batched VecEnv),
bad values raise one-line errors, both env checkers pass."""
import copy
import math
import pickle

import gymnasium as gym
import numpy as np
import pytest

import rotordrop_env  # noqa: F401  (registers the ids)
from physics.scene import SceneError
from rotordrop_env import BatchedRotorDropVecEnv
from physics.model import U_SENS_NOISE
from rotordrop_env.sensors import VELOCITY_ESTIMATE_DT
from tests.helpers import run_env_checkers

FULL = "RotorDrop-Full-v1"
SUP = dict(command="supervisor", control_dt=0.005, episode_time=0.15, terminate_on_failure=False)
#: supervisor action: C_max, PID on, nominal gain, no offsets (the inner loop)
ACTION = np.array([1, 1, 1, 0, 0, 0, 0, 0], dtype=np.float32)
POS = [0, 1, 4, 5]              # x1 y1 x2 y2
VEL = [2, 3, 6, 7]              # vx1 vy1 vx2 vy2


def episode(seed=3, **kw):
    """(observations (steps + 1, n_obs), reset info, true states) of one fixed-action episode."""
    env = gym.make(FULL, **{**SUP, **kw})
    obs, info = env.reset(seed=seed)
    rows, states = [obs], [env.unwrapped.state]
    done = False
    while not done:
        obs, _, term, trunc, _ = env.step(ACTION)
        rows.append(obs)
        states.append(env.unwrapped.state)
        done = term or trunc
    names = env.unwrapped.obs_names
    return np.array(rows, dtype=np.float64), info, np.array(states), names, env.unwrapped.obs_scale


def test_noise_has_the_requested_std_and_the_physics_sees_the_same_samples():
    """One sensing model: the displacement noise sample the observation carries after step n
    is the one the built-in PID and the supervisor's orbit frame see during step n + 1."""
    sigma = 5e-6
    env = gym.make(FULL, **SUP, sensor_noise=sigma)
    obs, _ = env.reset(seed=3)
    u = env.unwrapped
    rows, kernel, held = [obs], [u._b.obs.copy()], [u._b.U[U_SENS_NOISE:U_SENS_NOISE + 4].copy()]
    done = False
    while not done:
        obs, _, term, trunc, _ = env.step(ACTION)
        rows.append(obs)
        kernel.append(u._b.obs.copy())
        held.append(u._b.U[U_SENS_NOISE:U_SENS_NOISE + 4].copy())
        done = term or trunc
    names, scale = u.obs_names, u.obs_scale
    noisy = np.array(rows, dtype=np.float64)
    err = (noisy - np.array(kernel)) * scale
    n = err[:, POS].size                                 # 31 steps x 4 channels
    # the sample std of n Gaussian draws: within 4 standard errors (sigma / sqrt(2n))
    for cols, want in ((POS, sigma), (VEL, math.sqrt(2) * sigma / VELOCITY_ESTIMATE_DT)):
        assert abs(err[:, cols].std() - want) < 4 * want / math.sqrt(2 * n)
        assert abs(err[:, cols].mean()) < 4 * want / math.sqrt(n)
    # the held samples are the observation's displacement noise (float32 round-off of the obs)
    assert np.allclose(err[:, POS], np.array(held), rtol=0.0, atol=1e-10)
    _, _, y0, _, _ = episode()
    _, _, y1, _, _ = episode(sensor_noise=sigma)
    assert not np.array_equal(y0, y1)                    # the built-in PID feels the noise
    # the supervisor's orbit radius is recomputed from the noisy displacements
    r1 = names.index("orbit_radius1")
    assert np.allclose(noisy[:, r1] * scale[r1], np.hypot(noisy[:, 0] * scale[0], noisy[:, 1] * scale[1]))


@pytest.mark.parametrize("k", [1, 3])
def test_latency_shifts_the_observation_by_exactly_k_steps(k):
    clean, _, y0, names, _ = episode()
    late, info, y1, _, _ = episode(obs_latency_steps=k)
    assert info["obs_latency_steps"] == k and np.array_equal(y0, y1)
    t = names.index("time")
    rest = [j for j in range(clean.shape[1]) if j != t]
    assert np.array_equal(late[k:, rest], clean[:-k, rest])      # step n sees step n - k
    assert np.array_equal(late[:k + 1, rest], np.repeat(clean[:1, rest], k + 1, axis=0))
    assert np.array_equal(late[:, t], clean[:, t])               # the clock is not delayed


def test_latency_is_drawn_per_episode_from_the_range():
    env = gym.make(FULL, **SUP, obs_latency_steps=(1, 3))
    env.reset(seed=0)
    drawn = {env.reset()[1]["obs_latency_steps"] for _ in range(40)}
    assert drawn == {1, 2, 3}


def test_same_seed_same_episode_and_the_batch_agrees():
    kw = dict(sensor_noise=3e-6, obs_latency_steps=(0, 2), randomize=True,
              randomization={"amb.coil_time_constant": (2e-4, 1e-3), "amb.current_limit": (2.4, 3.0)})
    a, ia, _, _, _ = episode(seed=11, **kw)
    b, ib, _, _, _ = episode(seed=11, **kw)
    assert np.array_equal(a, b) and ia == ib
    c, _, _, _, _ = episode(seed=12, **kw)
    assert not np.array_equal(a[:5], c[:5])
    venv = BatchedRotorDropVecEnv(FULL, 2, seed=11, **SUP, **kw)
    rows = [venv.reset()]
    for _ in range(len(a) - 2):                                  # before the auto-reset
        rows.append(venv.step(np.stack([ACTION, ACTION]))[0])
    assert np.array_equal(np.array(rows)[:, 0], a[:-1].astype(np.float32))
    second, _, _, _, _ = episode(seed=12, **kw)
    assert np.array_equal(np.array(rows)[:, 1], second[:-1].astype(np.float32))


def test_latency_breaks_a_fast_current_loop_but_not_the_builtin_pid():
    """With 3 ms of observation latency (the agent's own, obs_latency_steps) a 1 kHz PID on the
    raw currents no longer re-levitates; the built-in PID inside the physics step does not get
    that latency (only the sensors' sensor_delay, which both see)."""
    from agents.control.controllers import controller_env_kwargs
    from agents.control.controllers import BASELINES
    from agents.benchmarking.rollout import run_episodes
    relev = {}
    for name in ("pid-relevitate", "builtin-relevitate"):
        cls = BASELINES[name]
        kw = dict(controller_env_kwargs(cls, FULL), terminate_on_failure=False,
                  control_dt=1e-3)                  # a 1 kHz loop (pid-relevitate's seat: 0.2 ms)
        relev[name] = [run_episodes(FULL, cls, [0], dict(kw, obs_latency_steps=k))[0].kpis["relevitated"]
                       for k in (0, 3)]
    assert relev["pid-relevitate"] == [True, False]
    assert relev["builtin-relevitate"] == [True, True]


def test_a_range_that_switches_on_the_coil_lag_gives_the_base_scene_the_coil_states():
    env = gym.make(FULL, **SUP, randomize=True, randomization={"amb.coil_time_constant": (2e-4, 1e-3)})
    assert env.unwrapped.base_scene.amb.coil_time_constant == 2e-4
    _, info = env.reset(seed=0)
    assert 2e-4 <= env.unwrapped.scenario["amb.coil_time_constant"] <= 1e-3
    with pytest.raises(SceneError, match="changes the state layout within its range"):
        gym.make(FULL, randomize=True, randomization={"amb.coil_time_constant": (0.0, 1e-3)})


@pytest.mark.parametrize("kw, match", [
    (dict(sensor_noise=-1e-6), r"sensor_noise = -1e-06 must be a standard deviation in metres in \[0, 0.0001\]"),
    (dict(sensor_noise=True), "sensor_noise = True"),
    (dict(sensor_noise="2um"), "sensor_noise = '2um'"),
    (dict(sensor_noise=float("nan")), "sensor_noise = nan"),
    (dict(obs_latency_steps=(3, 1)), r"obs_latency_steps = \(3, 1\) must be an integer or a pair"),
    (dict(obs_latency_steps=1.5), "obs_latency_steps = 1.5"),
    (dict(obs_latency_steps=-1), "obs_latency_steps = -1"),
    (dict(obs_latency_steps=(0, 101)), r"0 <= low <= high <= 100"),
    (dict(obs_latency_steps=(1, 2, 3)), "obs_latency_steps"),
    (dict(sensor_noise=1e-6, full_state=True), "full_state=True"),
])
def test_bad_sensing_values_raise_one_line_errors(kw, match):
    with pytest.raises(ValueError, match=match) as err:
        gym.make(FULL, **kw)
    assert "\n" not in str(err.value)


def test_sensing_is_fixed_at_construction():
    env = gym.make(FULL, sensor_noise=1e-6)
    with pytest.raises(AttributeError, match="sensor_noise is fixed"):
        env.unwrapped.sensor_noise = 2e-6


def test_env_checkers_pass_with_noise_and_latency():
    run_env_checkers(lambda: gym.make(FULL, **SUP, sensor_noise=2e-6, obs_latency_steps=(1, 3)))
    run_env_checkers(lambda: gym.make("RotorDrop-Passive-v1", episode_time=0.01,
                                      sensor_noise=2e-6, obs_latency_steps=2))


@pytest.mark.parametrize("noise, latency", [(2e-6, (0, 0)), (2e-6, (1, 3)), (0.0, (2, 2)),
                                            (1e-5, (0, 4))])
def test_the_compiled_sensing_step_is_the_numpy_one_bit_for_bit(noise, latency):
    """Sensing.step's compiled path (every setting but the supervisor's orbit entries) gives
    the numpy path's observations, held noise controls and draws, bit for bit, through the
    latency ring's first fill and its wrap-around (with a kernel-like true observation)."""
    from rotordrop_env.sensors import Sensing
    env = gym.make(FULL, command="continuous").unwrapped
    names, scale = env.obs_names, env.obs_scale
    make = lambda: Sensing(noise, latency, names, scale, 1e-4, U_SENS_NOISE)  # noqa: E731
    fast, slow = make(), make()
    slow.step = slow.step_python                         # reset() measures through it too
    assert fast.active
    rng_f, rng_s = np.random.default_rng(5), np.random.default_rng(5)
    U_f, U_s = np.zeros(U_SENS_NOISE + 4), np.zeros(U_SENS_NOISE + 4)
    truth = np.random.default_rng(1).normal(size=(12, len(names)))
    for n, true_obs in enumerate(truth):
        if n % 6 == 0:                                   # a new episode (its latency drawn)
            a, b = fast.reset(true_obs, rng_f, U_f), slow.reset(true_obs, rng_s, U_s)
        else:
            a, b = fast.step(true_obs, rng_f, U_f), slow.step(true_obs, rng_s, U_s)
        assert a.dtype == b.dtype == np.float32
        assert np.array_equal(a, b) and np.array_equal(U_f, U_s) and fast.k == slow.k
    assert rng_f.random() == rng_s.random()              # the same draws were taken


@pytest.mark.parametrize("copier", [copy.deepcopy, lambda e: pickle.loads(pickle.dumps(e))],
                         ids=["deepcopy", "pickle"])
def test_a_copied_noisy_env_continues_as_the_original(copier):
    """Copied mid-episode (noise sampled at 10 kHz inside 0.2 ms steps, latency), a copy's
    compiled calls are bound to its own arrays: it and the original continue identically, and
    the original is not disturbed by the copy's steps."""
    kw = dict(command="continuous", control_dt=2e-4, episode_time=0.01, sensor_noise=2e-6,
              sensor_delay=1e-4, obs_latency_steps=(1, 3))
    env, twin = gym.make(FULL, **kw), gym.make(FULL, **kw)
    acts = np.random.default_rng(2).uniform(-1, 1, (40, 6)).astype(np.float32)
    env.reset(seed=5), twin.reset(seed=5)
    for a in acts[:10]:
        env.step(a), twin.step(a)
    dup = copier(env)
    for a in acts[10:]:
        c = dup.step(a)
        o = env.step(a)
        t = twin.step(a)
        assert np.array_equal(c[0], o[0]) and np.array_equal(o[0], t[0]) and c[1] == o[1] == t[1]
        assert list(c[4]) == list(o[4]) and all(c[4][k] == o[4][k] for k in o[4])


def test_a_batch_senses_each_row_as_its_single_env_through_resets_and_a_copy():
    """The batch draws and measures all rows at once (rotordrop_env.sensors.SensingRows): each
    row is its single environment step for step (noise sampled inside 0.2 ms steps, latency,
    NEXT_STEP autoresets, whose steps advance some rows only), and a deep copy made
    mid-run continues as the original."""
    from gymnasium.vector import AutoresetMode
    kw = dict(command="continuous", control_dt=2e-4, episode_time=0.003, sensor_noise=2e-6,
              sensor_delay=1e-4, obs_latency_steps=(0, 3), terminate_on_failure=False)
    venv = gym.make_vec(FULL, num_envs=3, vectorization_mode="vector_entry_point", n_threads=1,
                        autoreset_mode=AutoresetMode.NEXT_STEP, **kw)
    singles = [gym.make(FULL, **kw) for _ in range(3)]
    obs, _ = venv.reset(seed=7)
    for i, env in enumerate(singles):
        assert np.array_equal(obs[i], env.reset(seed=7 + i)[0])
    acts = np.random.default_rng(3).uniform(-1, 1, (40, 3, 6)).astype(np.float32)
    ended = np.zeros(3, dtype=bool)
    for k, a in enumerate(acts):
        if k == 12:
            twin = copy.deepcopy(venv)
        obs, rew, te, tr, _ = venv.step(a)
        if k >= 12:
            o2, r2, *_ = twin.step(a)
            assert np.array_equal(obs, o2) and np.array_equal(rew, r2)
        for i, env in enumerate(singles):
            if ended[i]:
                assert np.array_equal(obs[i], env.reset()[0]) and rew[i] == 0.0
            else:
                o, r, *_ = env.step(a[i])
                assert np.array_equal(obs[i], o) and rew[i] == r
        ended = te | tr
    assert venv.unwrapped.batch.sensing is not None          # the stacked path was taken
