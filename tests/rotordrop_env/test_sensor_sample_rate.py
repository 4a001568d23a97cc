"""The sensors' own sample rate (scene key sensor.sample_rate, kwarg sensor_sample_rate;
physics/sensor.py): the noise is one sample per axis at t = k / f_s, held until the next,
whatever the consumer's control step. Inside a step the physics is integrated in pieces split
at the sample instants (the built-in PID reads each held sample in turn); at the steps' ends
the held sample changes exactly when an instant has passed; the samples have the requested
standard deviation and no memory; noise 0 draws and splits nothing; bad rates are one-line
errors."""
import math

import gymnasium as gym
import numpy as np
import pytest

import rotordrop_env  # noqa: F401  (registers the ids)
from physics.equilibrium import levitated_state
from physics.integrate import integrate_segment, integrate_sensed
from physics.model import N_AUX, U_SENS_NOISE, build_model
from physics.scene import SceneError, load_scene
from physics.sensor import samples_inside
from rotordrop_env import kernels as K

SIGMA = 1e-6
#: re-levitation by the built-in PID from the first step (power back at the fault): the PID
#: reads the sensed displacement, noise included, all episode
PID_ON = dict(command="discrete", power_return_time=0.0, terminate_on_failure=False)


def instants_inside(t0, t1, rate):
    """The sample instants k / rate strictly inside (t0, t1), by plain enumeration."""
    k = np.arange(math.floor(t0 * rate) - 1, math.ceil(t1 * rate) + 2)
    t = k / rate
    return t[(t > t0 + 1e-9 / rate) & (t < t1 - 1e-9 / rate)]


@pytest.mark.parametrize("t0, distinct", [(1e-3, 10), (1.23e-3, 11)])
def test_a_1ms_step_integrates_in_pieces_at_the_10khz_sample_instants(t0, distinct):
    """The PID's plant over one 1 ms step at f_s = 10 kHz: the kernel's state is that of
    integrating piece by piece between the instants k / f_s (enumerated here), the held noise
    set to sigma z_i from the i-th instant on: 10 held values on a step that starts on an
    instant, 11 on one that does not. Holding one sample over the step gives another state."""
    m = build_model(load_scene("paper", {"effects.amb": "actuator", "sensor.noise": SIGMA}))
    rate, dt = 1e4, 1e-3
    assert m.param("sensor.sample_rate") == rate
    inside = instants_inside(t0, t0 + dt, rate)
    assert samples_inside(t0, t0 + dt, rate)[1] == len(inside) == distinct - 1
    Z = np.random.default_rng(1).standard_normal((len(inside), 4))
    y0, U0 = levitated_state(m), m.controls(True)
    U0[U_SENS_NOISE:U_SENS_NOISE + 4] = SIGMA * np.array([0.3, -0.2, 0.5, 0.1])
    sv = m.scene.solver
    atol, work = np.full(m.n_state, 1e-9), np.empty((9, m.n_state))
    no_t, no_Y = np.empty(0), np.empty((0, m.n_state))

    def piece(y, ta, tb, U, h):
        return integrate_segment(y, ta, tb, m.P, m.I, U, sv.rtol, atol, h, sv.max_step,
                                 sv.min_step, False, 10**6, no_t, no_Y, 0, work)

    y, U = y0.copy(), U0.copy()
    status = integrate_sensed(y, t0, t0 + dt, m.P, m.I, U, Z, sv.rtol, atol, 1e-5, sv.max_step,
                              sv.min_step, False, 10**6, no_t, no_Y, 0, work, np.empty(N_AUX))[0]
    assert status == 0
    assert np.array_equal(U[U_SENS_NOISE:U_SENS_NOISE + 4], SIGMA * Z[-1])

    ref, Uref, h, t = y0.copy(), U0.copy(), 1e-5, t0
    for i, tb in enumerate(list(inside) + [t0 + dt]):
        _, t, h, *_ = piece(ref, t, tb, Uref, h)
        if i < len(inside):
            Uref[U_SENS_NOISE:U_SENS_NOISE + 4] = SIGMA * Z[i]
    assert np.array_equal(y, ref)

    held = y0.copy()
    piece(held, t0, t0 + dt, U0.copy(), 1e-5)
    assert not np.array_equal(y, held)


@pytest.mark.parametrize("power", [0.0, 1.0])
def test_direct_currents_read_no_noise_so_the_step_is_not_split(power):
    """Coil currents set directly (the controller seat; powered or not): nothing inside the
    model reads the sensed displacement, so a 1 ms step at f_s = 10 kHz is one piece, its state
    independent of the noise samples bit for bit, and the step's last sample is held at its end
    (what the observations read there). The split is a cost only the PID's reading justifies."""
    from physics.model import U_AMB_DIRECT, U_AMB_POWER, U_ICMD
    m = build_model(load_scene("paper", {"effects.amb": "actuator", "sensor.noise": SIGMA,
                                         "sensor.delay": 1e-4}))
    t0, dt, rate = 1.23e-3, 1e-3, 1e4
    n = samples_inside(t0, t0 + dt, rate)[1]
    y0, U0 = levitated_state(m), m.controls(True)
    U0[U_AMB_POWER], U0[U_AMB_DIRECT] = power, 1.0
    U0[U_ICMD:U_ICMD + 4] = [0.2, 1.1, -0.3, 0.9]
    sv = m.scene.solver
    atol, work = np.full(m.n_state, 1e-9), np.empty((9, m.n_state))
    no_t, no_Y = np.empty(0), np.empty((0, m.n_state))
    ends = []
    for seed in (1, 2):
        Z = np.random.default_rng(seed).standard_normal((n, 4))
        y, U = y0.copy(), U0.copy()
        res = integrate_sensed(y, t0, t0 + dt, m.P, m.I, U, Z, sv.rtol, atol, 1e-5, sv.max_step,
                               sv.min_step, False, 10**6, no_t, no_Y, 0, work, np.empty(N_AUX))
        assert res[0] == 0
        assert np.array_equal(U[U_SENS_NOISE:U_SENS_NOISE + 4], SIGMA * Z[-1])
        ends.append(y)
    assert np.array_equal(ends[0], ends[1])
    whole = y0.copy()
    integrate_segment(whole, t0, t0 + dt, m.P, m.I, U0.copy(), sv.rtol, atol, 1e-5, sv.max_step,
                      sv.min_step, False, 10**6, no_t, no_Y, 0, work)
    assert np.array_equal(ends[0], whole)


def noise_run(control_dt, rate, steps, seed=3, **kw):
    """(step start and end times, the held noise after each step [m], the rows of Z each step
    drew) of a re-levitation episode with noise sampled at ``rate``."""
    env = gym.make("RotorDrop-Relevitate-v1", control_dt=control_dt, episode_time=steps * control_dt,
                   sensor_noise=SIGMA, sensor_sample_rate=rate, **PID_ON, **kw)
    u = env.unwrapped
    env.reset(seed=seed)
    t, held, drawn = [u._b.M[K.M_T]], [u._b.U[U_SENS_NOISE:U_SENS_NOISE + 4].copy()], []
    for _ in range(steps):
        env.step(1)
        t.append(u._b.M[K.M_T])
        held.append(u._b.U[U_SENS_NOISE:U_SENS_NOISE + 4].copy())
        drawn.append(u._sensing.last_drawn)
    env.close()
    return np.array(t), np.array(held), drawn


@pytest.mark.parametrize("control_dt, rate", [(1e-4, 2e3), (3e-4, 2e3), (1e-3, 1e4),
                                              (3.5e-4, 1e4), (5e-3, 1e4)])
def test_the_held_sample_changes_at_sample_instants_not_at_step_starts(control_dt, rate):
    """After each control step the physics holds a new sample exactly when a sample instant
    k / f_s lies in (t_n, t_n+1] (a step shorter than 1 / f_s keeps it; one not a multiple of
    1 / f_s changes it on some steps only); each step drew one sample per instant strictly
    inside it, the one at its end drawn by the measurement after it."""
    t, held, drawn = noise_run(control_dt, rate, steps=24)
    changed = np.any(held[1:] != held[:-1], axis=1)
    passed = np.floor(t[1:] * rate + 1e-6) != np.floor(t[:-1] * rate + 1e-6)
    assert np.array_equal(changed, passed)
    assert [len(instants_inside(a, b, rate)) for a, b in zip(t[:-1], t[1:])] == drawn
    if control_dt < 1 / rate:
        assert not changed.all()
    at_end = np.abs(t[1:] * rate - np.round(t[1:] * rate)) < 1e-6
    index = np.floor(t * rate + 1e-6)
    assert sum(drawn) + at_end.sum() == index[-1] - index[0]     # one sample per instant


def test_the_samples_have_the_requested_std_and_no_memory():
    """4000 held samples (one per 0.1 ms step at 10 kHz, 4 axes): std sigma within 5 %
    (4.6 standard errors), mean and lag-1 correlation within 4 standard errors of 0."""
    _, held, drawn = noise_run(1e-4, 1e4, steps=1000)
    z = held[1:] / SIGMA
    assert not any(drawn)                       # every step ends on an instant: fresh there
    assert np.std(z) == pytest.approx(1.0, rel=0.05)
    assert abs(np.mean(z)) < 4 / math.sqrt(z.size)
    r = np.mean([np.corrcoef(z[:-1, j], z[1:, j])[0, 1] for j in range(4)])
    assert abs(r) < 4 / math.sqrt(z.size)


def test_same_seed_same_samples_another_seed_others():
    a = noise_run(1e-3, 1e4, steps=15, seed=7)
    b = noise_run(1e-3, 1e4, steps=15, seed=7)
    c = noise_run(1e-3, 1e4, steps=15, seed=8)
    assert np.array_equal(a[1], b[1]) and not np.array_equal(a[1], c[1])


def test_without_noise_the_sample_rate_changes_nothing():
    """Noise 0: no sample is drawn or held, the step is one piece, whatever the rate."""
    def run(**kw):
        env = gym.make("RotorDrop-Relevitate-v1", episode_time=0.02, sensor_delay=1e-4,
                       **PID_ON, **kw)
        obs, _ = env.reset(seed=2)
        rows = [obs] + [env.step(1)[0] for _ in range(20)]
        assert env.unwrapped._b.Z.shape == (0, 4)
        return np.array(rows), env.unwrapped.state
    a_obs, a_y = run()
    b_obs, b_y = run(sensor_sample_rate=2e3)
    assert np.array_equal(a_obs, b_obs) and np.array_equal(a_y, b_y)


@pytest.mark.parametrize("kw, match", [
    (dict(sensor_sample_rate=500.0),
     r"sensor_sample_rate = 500.0 must be a sample rate in hertz in \[1000, 100000\]"),
    (dict(sensor_sample_rate=2e5), "sensor_sample_rate = 200000.0"),
    (dict(sensor_sample_rate="10kHz"), "sensor_sample_rate = '10kHz'"),
    (dict(sensor_sample_rate=float("nan")), "sensor_sample_rate = nan"),
    (dict(sensor_sample_rate=True), "sensor_sample_rate = True"),
    (dict(sensor_sample_rate=2e4, overrides={"sensor.sample_rate": 5e3}),
     "sensor_sample_rate = 20000 contradicts the scene's sensor.sample_rate = 5000"),
])
def test_bad_sample_rates_are_one_line_errors(kw, match):
    with pytest.raises(ValueError, match=match) as err:
        gym.make("RotorDrop-Full-v1", sensor_noise=SIGMA, **kw)
    assert "\n" not in str(err.value)


def test_the_scene_key_has_its_range():
    with pytest.raises(SceneError, match=r"sensor.sample_rate = 500.0 is out of range: must be in "
                                         r"\[1000, 100000\] Hz"):
        load_scene("paper", {"sensor.sample_rate": 500.0})
    env = gym.make("RotorDrop-Full-v1", sensor_noise=SIGMA, overrides={"sensor.sample_rate": 5e3})
    assert env.unwrapped.sensor_sample_rate == 5e3
    with pytest.raises(AttributeError, match="sensor_sample_rate is fixed"):
        env.unwrapped.sensor_sample_rate = 2e4


@pytest.mark.parametrize("control_dt, rate", [(2e-4, 1e4), (2.5e-4, 1e4), (2.5e-4, 3e3),
                                              (1e-4, 1e4)])
def test_a_step_draws_its_normals_in_one_call_as_one_per_sample_and_measurement(control_dt, rate):
    """The step's standard normals, drawn in one call before the kernel step, are the numbers a
    draw per sample instant strictly inside the step (4 each: the held samples the physics
    reads) and then one for the measurement after it (8 when an instant falls at its end: a
    new displacement sample and the velocity estimates; else the 4 velocity ones) would give:
    the environment's generator is left exactly where those draws leave it."""
    env = gym.make("RotorDrop-Full-v1", command="continuous", control_dt=control_dt,
                   episode_time=60 * control_dt, sensor_noise=SIGMA, sensor_sample_rate=rate,
                   terminate_on_failure=False)
    u = env.unwrapped
    env.reset(seed=4)
    env.action_space.seed(4)
    ref = np.random.Generator(np.random.PCG64())
    ref.bit_generator.state = u.np_random.bit_generator.state
    counts = set()
    for _ in range(60):
        t0 = u._b.M[K.M_T]
        env.step(env.action_space.sample())
        t1 = t0 + control_dt
        n = len(instants_inside(t0, t1, rate))
        at_end = abs(t1 * rate - round(t1 * rate)) < 1e-6
        inside = ref.standard_normal((n, 4))
        measured = ref.standard_normal(8 if at_end else 4)
        assert np.array_equal(u._b.Z[:n], inside)
        assert np.array_equal(u._b.Z[n:n + 1 + at_end].ravel(), measured)
        counts.add((n, at_end))
    assert ref.random() == u.np_random.random()
    per_step = control_dt * rate
    if abs(per_step - round(per_step)) > 1e-6:         # steps of different draws were met
        assert len(counts) > 1


def test_a_refused_action_draws_no_noise_as_in_a_batch():
    """A refused action (a ValueError, nothing advanced) draws nothing from the environment's
    generator: the episode goes on as if it had never been sent, and the batch, which checks
    all actions before any environment draws, agrees step for step."""
    from rotordrop_env import BatchedRotorDropVecEnv
    kw = dict(command="continuous", control_dt=2e-4, episode_time=0.004, sensor_noise=SIGMA,
              obs_latency_steps=(0, 2))
    one = gym.make("RotorDrop-Full-v1", **kw)
    clean = gym.make("RotorDrop-Full-v1", **kw)
    batch = BatchedRotorDropVecEnv("RotorDrop-Full-v1", 1, seed=9, n_threads=1, **kw)
    one.reset(seed=9), clean.reset(seed=9), batch.reset()
    acts = np.random.default_rng(1).uniform(-1, 1, (12, 6)).astype(np.float32)
    for k, a in enumerate(acts):
        if k % 4 == 1:
            bad = a.copy()
            bad[3] = np.nan
            with pytest.raises(ValueError, match="non-finite action"):
                one.step(bad)
            with pytest.raises(ValueError, match="non-finite action"):
                batch.step(bad[None])
        o1, r1, *_ = one.step(a)
        o2, r2, *_ = clean.step(a)
        o3, r3, *_ = batch.step(a[None])
        assert np.array_equal(o1, o2) and r1 == r2
        assert np.array_equal(o1, o3[0]) and np.float32(r1) == r3[0]
