"""Environment speed: env steps per second at the 1 ms control step, single and batched, and
in the controller seat (``--control-dt``), as ratios to Gymnasium's ``Pendulum-v1`` timed in
the same rounds.

    python benchmarks/bench_env.py [--repeats 20] [--steps 600] [--n-envs 16] [--set KEY=VALUE ...]
                                   [--compare-set solver.rtol=1e-4 ...]
                                   [--json docs/data/bench-env.json]
    python benchmarks/bench_env.py --control-dt 2e-4 --control-dt 1e-4 [--repeats 15]
                                   [--compare-set solver.rtol=1e-4 ...] [--law whirl-brake]
                                   [--json docs/data/bench-env-seat.json]
    python benchmarks/bench_env.py --render docs/data/bench-env.json

Both modes time their cases in rounds: each round times ``Pendulum-v1`` (``gym.make``, random
actions) and then every case once, each from a seeded reset (every round the same episodes,
resets as episodes end; every environment of a batch steps ``--steps`` steps, as many as the
single env). They print each rate's median and the median of its per-round ratios to
Pendulum-v1's rate (the machine's speed cancels), then the cost split of one step of each
single env on one trajectory (:func:`cost_split`): the physics alone (``integrate_sensed`` over
each control step, in one compiled loop), the step kernel (physics + sub-sampled monitors,
reward, observation), the Python ``step`` and Gymnasium's wrappers, and what the physics is
made of (right-hand sides per step, the cost of one at the episode's states, their share of the
physics alone). ``--json`` stores the figures; ``--render JSON`` prints the tables of
docs/environments.md from them (:func:`render`). Every figure is timed after a JIT warm-up by
the process CPU time (``--clock cpu``, the default: per core and robust on a machine shared
with other jobs) or by the wall clock (``--clock wall``). ``--compare-set KEY=VALUE`` adds a
run with that scene override (e.g. a looser ``solver.rtol``).

Default mode, the 1 ms control step: paper scene, default environment settings (episode 0.3 s =
300 steps, 5 monitor samples per step; ``--steps`` 600: two episodes), random actions:

* single env: ``gym.make(id)`` (with Gymnasium's wrappers) and ``env.unwrapped``, for the passive
  env and the damping env, for the paper scene as it is (mu = 0.25: drop, bounces, no whirl)
  and at mu = 0.5, which whirls backward (run on through the whirl with
  ``terminate_on_failure=False``; the physics is costliest there);
* batched, at mu = 0.25: the SB3 batch ``BatchedRotorDropVecEnv`` of N = ``--n-envs`` damping
  envs with 1 numba thread (the per-core figure) and with all threads, and the Gymnasium vector
  env (``gymnasium.make_vec``, one thread), each also as the median of its per-round ratios to
  the single damping env (``gym.make``); next to them the Amdahl bound of batching from that
  env's cost split (``gym.make`` step over physics: nothing but the physics left; over the
  kernel call: the Python part removed), and the batch with its default threads (chosen as it
  runs) over one thread, N = 1 and N = ``--n-envs``, by the wall clock, runs interleaved.

With ``--control-dt`` (one or more control steps [s]) it measures the controller seat
(:mod:`agents.control.seats`): ``RotorDrop-Full-v1`` with raw coil currents
(``command="continuous"``) and dampers, the robust suite's sensor noise and the middle of its
sensor delay range, random actions (``--law NAME``: the actions that designed law sends on
the same episodes, recorded and replayed: what a learner near it steps): the single env
(``gym.make`` and ``env.unwrapped``), the SB3 batch (one numba thread: per core) and the
vector env (one thread), and the targets they are held to (:func:`seat_table`).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from typing import Callable, NamedTuple

import gymnasium as gym
import numba
import numpy as np
from tqdm import tqdm

import rotordrop_env
from physics._jit import bound, njit
from physics.scene import parse_assignment
from physics.integrate import integrate_sensed
from physics.model import U_SENS_NOISE, rhs
from rotordrop_env import kernels as K


CLOCK = time.process_time


def _median(fn, repeats: int) -> float:
    fn()                                               # warm-up (JIT, caches)
    return statistics.median(fn() for _ in range(repeats))


def single_env_rate(env_id: str, kwargs: dict, episodes: int, unwrapped: bool, seed: int = 0):
    """Steps per second over whole episodes (random actions except for the passive env)."""
    env = gym.make(env_id, **kwargs)
    stepper = env.unwrapped if unwrapped else env
    space = env.action_space
    space.seed(seed)
    acts = [space.sample() for _ in range(4096)]

    def run():
        steps = 0
        t0 = CLOCK()
        for ep in range(episodes):
            stepper.reset(seed=seed + ep)
            done = False
            while not done:
                _, _, te, tr, _ = stepper.step(acts[steps % len(acts)])
                done = te or tr
                steps += 1
        return steps / (CLOCK() - t0)
    return run


def cost_split(env_id: str, kwargs: dict, episodes: int, seed: int = 0,
               stats: dict | None = None, acts: list | None = None):
    """Per-step microseconds of physics, kernel, unwrapped step and wrapped step of ``env_id``
    on one trajectory (the passive env without action; others with seeded uniform random
    actions, the same in every part). The physics replays the controls ``U`` each step of the
    episode left in the kernel, so it integrates the very trajectory the env steps. ``stats``
    (a dict) receives the integrator's right-hand sides, steps and rejected steps per control
    step of the physics part."""
    env = gym.make(env_id, **kwargs)
    u = env.unwrapped
    space = env.action_space
    space.seed(seed)
    passive = env_id == "RotorDrop-Passive-v1"
    if acts is None:
        acts = [np.zeros(space.shape, dtype=space.dtype) if passive else space.sample()
                for _ in range(4096)]

    def per_step(fn):
        def run():
            steps, total = 0, 0.0
            for _ in range(episodes):
                env.reset(seed=seed)
                t0 = CLOCK()
                done = False
                while not done:
                    done = fn(acts[steps % len(acts)])
                    steps += 1
                total += CLOCK() - t0
            return total / steps * 1e6
        return run

    step = bound(K.step_one, *u._args)     # as the environment calls it (no dispatch)

    def kernel_step(a):
        u._b.act[:] = a
        u.draw_noise()                      # the sensor noise samples inside the step
        step()
        return bool(u._b.out[K.O_TERM] or u._b.out[K.O_TRUNC])

    def unwrapped_step(a):
        _, _, te, tr, _ = u.step(a)
        return te or tr

    def wrapped_step(a):
        _, _, te, tr, _ = env.step(a)
        return te or tr

    env.reset(seed=seed)                    # the controls of each step of one episode
    controls, noises, times, states = [], [], [], []
    while True:
        times.append(u._b.M[K.M_T])
        states.append(u._b.y.copy())
        done = kernel_step(acts[len(controls) % len(acts)])
        controls.append(u._b.U.copy())
        noises.append(u._b.Z.copy())
        if done:
            break
    controls, times, states = np.array(controls), np.array(times), np.array(states)
    noises = np.array(noises)

    def physics():
        env.reset(seed=seed)
        b = u._b
        y = b.y.copy()
        sv = u.scene.solver
        work = np.empty((9, y.size))
        counts = np.zeros(3, dtype=np.int64)
        t0 = CLOCK()
        status = _physics_loop(y, b.M[K.M_T], u.dt, controls, noises, b.P, b.I, sv.rtol, b.atol,
                               b.M[K.M_H], sv.max_step, sv.min_step, work, b.aux.copy(), counts)
        elapsed = CLOCK() - t0
        assert status == 0
        if stats is not None:
            stats.update(zip(("rhs", "steps", "rejected"), (counts / len(controls)).tolist()))
            stats["rhs_ns"] = _median(lambda: rhs_cost(b), 5)
        return elapsed / len(controls) * 1e6

    def rhs_cost(b):
        """ns per right-hand side (with its rates) at the start of each step of the episode."""
        t0 = CLOCK()
        _rhs_loop(times, states, controls, b.P, b.I, np.empty(b.y.size), b.aux.copy())
        return (CLOCK() - t0) / len(controls) * 1e9

    return dict(physics=physics, kernel=per_step(kernel_step), unwrapped=per_step(unwrapped_step),
                wrapped=per_step(wrapped_step))


@njit
def _rhs_loop(T, Y, controls, P, I, dy, aux):
    """The right-hand side at each time, state and controls of a trajectory, in one compiled
    call."""
    for k in range(T.shape[0]):
        rhs(T[k], Y[k], P, I, controls[k], dy, aux)


@njit
def _physics_loop(y, t, dt, controls, noises, P, I, rtol, atol, h, h_max, h_min, work, aux, counts):
    """The physics alone: a control step of integrate_sensed per row of ``controls`` (the U of
    each step, its sensor-noise entries held from the step before) and of ``noises`` (the
    step's noise samples: the step is integrated in pieces at the sensor's sample instants, as
    the environment does), in one compiled call; ``counts`` += its right-hand sides, steps and
    rejected steps."""
    no_t = np.empty(0)
    no_Y = np.empty((0, y.shape[0]))
    U = controls[0].copy()
    for k in range(controls.shape[0]):
        for j in range(U.shape[0]):             # the step's controls, the held noise kept
            if j < U_SENS_NOISE or j >= U_SENS_NOISE + 4:
                U[j] = controls[k, j]
        status, _, h, _, n_rhs, n_steps, n_rej = integrate_sensed(
            y, t, t + dt, P, I, U, noises[k], rtol, atol, h, h_max, h_min, False, 10**9, no_t,
            no_Y, 0, work, aux)
        counts[0] += n_rhs
        counts[1] += n_steps
        counts[2] += n_rej
        if status != 0:
            return status
        t += dt
    return 0


def batched_rate(env_id: str, kwargs: dict, n_envs: int, steps: int, threads: int | None,
                 seed: int = 0, clock=None):
    """Env steps per second of a batch (``threads`` None: the batch's own choice), timed by
    ``clock`` (default: the --clock of the run)."""
    clock = clock or CLOCK
    venv = rotordrop_env.BatchedRotorDropVecEnv(env_id, n_envs, seed=seed, n_threads=threads,
                                                **kwargs)
    rng = np.random.default_rng(seed)
    shape = (n_envs,) + venv.action_space.shape
    acts = [rng.uniform(-1, 1, shape).astype(np.float32) for _ in range(64)]

    def run():
        venv.reset()
        t0 = clock()
        for k in range(steps):
            venv.step(acts[k % len(acts)])
        return steps * n_envs / (clock() - t0)
    return run


def default_vs_one_thread(env_id: str, kwargs: dict, n_envs: int, steps: int, repeats: int):
    """Wall-clock steps/s of the batch with its default threads over the same batch on one
    thread, runs interleaved: (median ratio, default rate, one-thread rate)."""
    wall = time.perf_counter
    auto = batched_rate(env_id, kwargs, n_envs, steps, None, clock=wall)
    one = batched_rate(env_id, kwargs, n_envs, steps, 1, clock=wall)
    auto(), one()                                      # warm-up
    pairs = [(auto(), one()) for _ in range(repeats)]
    return (statistics.median(a / o for a, o in pairs), statistics.median(a for a, _ in pairs),
            statistics.median(o for _, o in pairs))


#: the controller seat's environment (module doc): raw currents and dampers
SEAT_ENV = "RotorDrop-Full-v1"
PENDULUM = "Pendulum-v1"


def seat_kwargs(control_dt: float, overrides: dict | None = None) -> dict:
    """The env kwargs of a controller-seat row at ``control_dt``: raw currents, the robust
    suite's sensor noise and the middle of its sensor delay range, no transport latency;
    ``overrides``: scene keys (``--set``, e.g. a looser ``solver.rtol``)."""
    from agents.benchmarking.robust import SENSOR_DELAY_S, SENSOR_NOISE
    from agents.control.seats import CONTROLLER
    kw = dict(CONTROLLER.env_kwargs(control_dt), command="continuous", sensor_noise=SENSOR_NOISE,
              sensor_delay=0.5 * (SENSOR_DELAY_S[0] + SENSOR_DELAY_S[1]))
    return dict(kw, overrides=dict(overrides)) if overrides else kw


class Face(NamedTuple):
    """One way to step the seat's environment: what a designed law reads its plant from, the
    environments per step, the shape of one step's action (a batch's: a row per environment),
    a seeded reset (the same episodes every time; returns the observation) and one step
    (returns the next observation and where episodes start: reset as they end)."""
    env: object
    n: int
    shape: tuple
    reset: Callable[[], np.ndarray]
    step: Callable[[np.ndarray], tuple]


def single_face(env, seed: int = 0) -> Face:
    """A single env, ``gym.make``'d or unwrapped (reset by the caller as episodes end)."""
    def reset():
        return env.reset(seed=seed)[0]

    def step(a):
        obs, _, te, tr, _ = env.step(a)
        if te or tr:
            obs = env.reset()[0]
        return obs, te or tr
    return Face(env, 1, env.action_space.shape, reset, step)


def sb3_face(venv, seed: int = 0) -> Face:
    """The SB3 batch (environment i seeded ``seed + i``; auto-reset)."""
    def reset():
        venv.seed(seed)
        return venv.reset()

    def step(a):
        obs, _, dones, _ = venv.step(a)
        return obs, dones
    return Face(venv, venv.num_envs, (venv.num_envs,) + venv.action_space.shape, reset, step)


def vector_face(venv, seed: int = 0) -> Face:
    """The Gymnasium vector env (environment i seeded ``seed + i``; same-step autoreset)."""
    def reset():
        return venv.reset(seed=seed)[0]

    def step(a):
        obs, _, te, tr, _ = venv.step(a)
        return obs, te | tr
    return Face(venv, venv.num_envs, venv.action_space.shape, reset, step)


def face_actions(face: Face, steps: int, law: str | None = None, seed: int = 0) -> list:
    """``steps`` actions of ``face``: seeded uniform random ones, or the ones designed law
    ``law`` sends on the face's episodes from its reset (closed loop, recorded: replayed open
    loop they drive the same episodes again, the environment being deterministic given its
    seed and actions, without the law's own cost in the timing)."""
    if law is None:
        rng = np.random.default_rng(seed)
        return [rng.uniform(-1, 1, face.shape).astype(np.float32) for _ in range(steps)]
    from agents.control.controllers import make_baseline
    from agents.control.plant import Plant
    ctrl = make_baseline(law, Plant.from_env(face.env))
    obs, start, acts = face.reset(), np.ones(face.n, dtype=bool), []
    for _ in range(steps):
        a, _ = ctrl.predict(obs, episode_start=start)
        acts.append(np.asarray(a, dtype=np.float32))
        obs, start = face.step(acts[-1])
        start = np.atleast_1d(start)
    return acts


def face_rate(face: Face, acts: list):
    """Env steps per second of ``face`` over ``acts`` from its seeded reset (every run the
    same episodes)."""
    step = face.step

    def run():
        face.reset()
        t0 = CLOCK()
        for a in acts:
            step(a)
        return len(acts) * face.n / (CLOCK() - t0)
    return run


def seat_cases(control_dt: float, n_envs: int, steps: int, overrides: dict | None = None,
               law: str | None = None) -> dict:
    """The timed runs of the controller seat at ``control_dt`` (each returns steps/s), warmed
    up: Pendulum-v1 (4 x ``steps``), the single env (``gym.make``, unwrapped) over ``steps``
    steps, the SB3 batch and the vector env (``n_envs``, one thread), each of whose
    environments steps ``steps`` steps too (the same span of the same episodes as the single
    env: environment 0 of a batch is the single env); ``overrides``: scene keys; ``law``: every
    case but Pendulum-v1 driven by that designed law's actions (:func:`face_actions`), else
    by random ones."""
    kw = seat_kwargs(control_dt, overrides)
    faces = {"single (gym.make)": single_face(gym.make(SEAT_ENV, **kw)),
             "single (unwrapped)": single_face(gym.make(SEAT_ENV, **kw).unwrapped),
             f"SB3 batch N={n_envs}, per core": sb3_face(
                 rotordrop_env.BatchedRotorDropVecEnv(SEAT_ENV, n_envs, n_threads=1, **kw)),
             f"vector env N={n_envs}, per core": vector_face(
                 gym.make_vec(SEAT_ENV, num_envs=n_envs, vectorization_mode="vector_entry_point",
                              n_threads=1, **kw))}
    return timed_cases(faces, steps, law)


def timed_cases(faces: dict, steps: int, law: str | None = None) -> dict:
    """Each face's run over ``steps`` steps (:func:`face_rate`; ``law``: that designed law's
    actions, else random ones) after Pendulum-v1's over 4 x ``steps``, warmed up."""
    pendulum = single_face(gym.make(PENDULUM))
    cases = {PENDULUM: face_rate(pendulum, face_actions(pendulum, 4 * steps))}
    for name, face in faces.items():
        cases[name] = face_rate(face, face_actions(face, steps, law))
    for run in cases.values():                          # warm-up (JIT, scenario caches)
        run()
    return cases


def round_medians(cases: dict, repeats: int, over: dict | None = None) -> dict:
    """``repeats`` rounds that time every case once: each rate's median (``rates``) and the
    median of its per-round ratios to Pendulum-v1's (``ratio_to_pendulum``: the machine's speed
    cancels); ``over``: more ratios, ``{key: (reference case, [cases])}``."""
    rounds = [{name: run() for name, run in cases.items()} for _ in tqdm(
        range(repeats), desc="rounds", leave=False)]
    ratios = dict(ratio_to_pendulum=(PENDULUM, [n for n in cases if n != PENDULUM]), **(over or {}))
    out = {"rates": {n: statistics.median(r[n] for r in rounds) for n in cases}}
    for key, (ref, names) in ratios.items():
        out[key] = {n: statistics.median(r[n] / r[ref] for r in rounds) for n in names}
    return out


def seat_speed(control_dt: float, repeats: int, n_envs: int, steps: int,
               overrides: dict | None = None, law: str | None = None) -> dict:
    """The controller seat's rates at ``control_dt`` and their ratios to Pendulum-v1's, each
    the median over ``repeats`` rounds that time every case once (module doc); ``overrides``:
    scene keys for every case; ``law``: every case driven by that designed law's actions
    (recorded, replayed) instead of random ones."""
    kw = seat_kwargs(control_dt, overrides)
    acts = face_actions(single_face(gym.make(SEAT_ENV, **kw)), steps, law) if law else None
    cases = seat_cases(control_dt, n_envs, steps, overrides, law)
    out = {"control_dt_s": control_dt, "env_id": SEAT_ENV, "env_kwargs": kw, "repeats": repeats,
           "actions": law or "random", **round_medians(cases, repeats)}
    return dict(out, **split_of(SEAT_ENV, kw, 1, repeats, acts))


def split_of(env_id: str, kwargs: dict, episodes: int, repeats: int, acts: list | None = None
             ) -> dict:
    """The cost split of one step of ``env_id`` (:func:`cost_split`, each part the median of
    ``repeats``: ``per-step us``) and its integrator's work per step (``integrator per
    step``)."""
    stats: dict = {}
    split = {k: _median(fn, repeats)
             for k, fn in cost_split(env_id, kwargs, episodes, stats=stats, acts=acts).items()}
    return {"per-step us": split, "integrator per step": stats}


PASSIVE, DAMPING = "RotorDrop-Passive-v1", "RotorDrop-Damping-v1"
#: the 1 ms figures' scenes (module doc): label -> env kwargs of the paper scene's
SCENES = {"μ = 0.25": {},
          "μ = 0.5, backward whirl": {"overrides": {"contact.friction": 0.5},
                                      "terminate_on_failure": False}}
#: the single env the 1 ms batches are compared with (the same env, scene and actions)
SINGLE_CASE = f"Damping, {next(iter(SCENES))} (gym.make)"


def scene_kwargs(scene: str, overrides: dict | None = None) -> dict:
    """The env kwargs of a 1 ms scene (:data:`SCENES`) with the run's scene ``overrides``
    (``--set``; the scene's own win)."""
    kw = dict(SCENES[scene])
    o = dict(overrides or {}, **kw.get("overrides", {}))
    return dict(kw, overrides=o) if o else kw


def step_cases(n_envs: int, steps: int, overrides: dict | None = None) -> dict:
    """The timed runs of the 1 ms figures (each returns steps/s; :func:`timed_cases`): per
    scene the passive and the damping env, ``gym.make``'d and unwrapped; at mu = 0.25 the
    damping env's SB3 batch (``n_envs``, one thread and every numba thread) and vector env (one
    thread), each of whose environments steps ``steps`` steps like the single env."""
    faces = {}
    for scene in SCENES:
        kw = scene_kwargs(scene, overrides)
        for env_id in (PASSIVE, DAMPING):
            name = f"{env_id.split('-')[1]}, {scene}"
            faces[f"{name} (gym.make)"] = single_face(gym.make(env_id, **kw))
            faces[f"{name} (unwrapped)"] = single_face(gym.make(env_id, **kw).unwrapped)
    kw = scene_kwargs(next(iter(SCENES)), overrides)
    for threads in sorted({1, numba.config.NUMBA_NUM_THREADS}):
        faces[f"SB3 batch N={n_envs}, {threads} thread{'s' * (threads > 1)}, per core"] = \
            sb3_face(rotordrop_env.BatchedRotorDropVecEnv(DAMPING, n_envs, n_threads=threads, **kw))
    faces[f"vector env N={n_envs}, 1 thread, per core"] = vector_face(gym.make_vec(
        DAMPING, num_envs=n_envs, vectorization_mode="vector_entry_point", n_threads=1, **kw))
    return timed_cases(faces, steps)


def step_speed(repeats: int, n_envs: int, steps: int, overrides: dict | None = None) -> dict:
    """The 1 ms figures (module doc) with the scene ``overrides``: rates, ratios to
    Pendulum-v1 and of the batches to :data:`SINGLE_CASE` (medians of ``repeats`` rounds), the
    cost split of each single env (``steps`` per part and repeat), the batching bound it
    allows and the batch's default threads over one thread."""
    load = os.getloadavg()[0]
    cases = step_cases(n_envs, steps, overrides)
    batches = [n for n in cases if " N=" in n]
    out = {"overrides": dict(overrides or {}), "repeats": repeats,
           **round_medians(cases, repeats, {"ratio_to_single": (SINGLE_CASE, batches)})}
    episodes = max(1, steps // 300)                    # whole 0.3 s episodes
    out["splits"] = {f"{env_id.split('-')[1]}, {scene}": dict(
        split_of(env_id, scene_kwargs(scene, overrides), episodes, repeats), env_id=env_id)
        for scene in SCENES for env_id in (PASSIVE, DAMPING)}
    c = out["splits"][SINGLE_CASE.removesuffix(" (gym.make)")]["per-step us"]
    out["batching bound per core (Amdahl)"] = dict(physics=c["wrapped"] / c["physics"],
                                                   kernel=c["wrapped"] / c["kernel"])
    kw = scene_kwargs(next(iter(SCENES)), overrides)
    out["default over one thread (wall)"] = {
        f"N = {n}": default_vs_one_thread(DAMPING, kw, n, max(steps, 4800 // n), repeats)[0]
        for n in sorted({1, n_envs})}
    out["load average"] = {"start": load, "end": os.getloadavg()[0]}
    return out


def _settings_label(r: dict) -> str:
    """A 1 ms run's scene overrides (``--set``, ``--compare-set``), or the defaults."""
    return ", ".join(f"`{k}={v}`" for k, v in r["overrides"].items()) or "defaults"


def _print_rates(title: str, r: dict) -> None:
    print(f"{title} (median of {r['repeats']} rounds):")
    for name, rate in r["rates"].items():
        ratio = r["ratio_to_pendulum"].get(name)
        single = r.get("ratio_to_single", {}).get(name)
        print(f"  {name:40s} {rate:10.0f} steps/s"
              + ("" if ratio is None else f"   {ratio:.2f}x Pendulum-v1")
              + ("" if single is None else f"   {single:.2f}x the single env"))


def _print_step(r: dict) -> None:
    _print_rates(f"1 ms control step, paper scene, {_settings_label(r)}, random actions", r)
    for case, sp in r["splits"].items():
        _print_split(f"{sp['env_id']}, {case}", sp["per-step us"])
    b = r["batching bound per core (Amdahl)"]
    print(f"  batching bound per core (Amdahl, {SINGLE_CASE}'s split): nothing but the physics "
          f"left {b['physics']:.2f}x, the compiled kernel kept {b['kernel']:.2f}x")
    print("  batch with default threads over one thread, wall clock, runs interleaved: "
          + ", ".join(f"{n}: {v:.2f}x" for n, v in r["default over one thread (wall)"].items()))


def _print_seat(res: dict) -> None:
    _print_rates(f"controller seat, {res['env_id']} {res['env_kwargs']}, "
                 f"{res.get('actions', 'random')} actions, resets as episodes end", res)
    _print_split(res["env_id"], res["per-step us"])
    i = res["integrator per step"]
    print(f"    integrator per control step: {i['rhs']:.1f} right-hand sides, {i['steps']:.2f} "
          f"steps, {i['rejected']:.2f} rejected; a right-hand side costs {i['rhs_ns']:.0f} ns: "
          f"{100 * _rhs_share(res):.0f} % of the physics")
    ceiling = 1e6 / res["per-step us"]["physics"] / res["rates"][PENDULUM]
    print(f"    the physics alone steps at {ceiling:.2f}x Pendulum-v1 (the most any work outside "
          f"the integrator can reach, from the medians)")


def _rhs_share(res: dict) -> float:
    """The share of the physics alone that its right-hand sides take (their count per step x
    the cost of one at the episode's states); the rest is the integrator's own arithmetic."""
    i = res["integrator per step"]
    return i["rhs"] * i["rhs_ns"] * 1e-3 / res["per-step us"]["physics"]


def _seat_label(r: dict) -> str:
    """A seat run's control step, and its scene overrides if any (``--set``)."""
    extra = r["env_kwargs"].get("overrides") or {}
    law = r.get("actions", "random")
    return (f"{1e3 * r['control_dt_s']:g} ms" + "".join(f", `{k}={v}`" for k, v in extra.items())
            + ("" if law == "random" else f", `{law}`'s actions"))


#: the controller seat's speed targets, × Pendulum-v1's steps/s: a single environment, and a
#: batch per core (1.5 × the single environment's target)
SINGLE_TARGET = 0.5
BATCH_TARGET = 1.5 * SINGLE_TARGET


def target_of(case: str) -> float | None:
    """The speed target of a seat case (:data:`SINGLE_TARGET`, :data:`BATCH_TARGET`; None:
    Pendulum-v1, the reference)."""
    if case == PENDULUM:
        return None
    return SINGLE_TARGET if case.startswith("single") else BATCH_TARGET


def seat_table(res: dict) -> str:
    """The markdown table of a ``--control-dt`` run's JSON (docs/environments.md pastes it
    between its markers; ``--render JSON`` prints it)."""
    def verdict(r, name):
        ratio, target = r["ratio_to_pendulum"].get(name), target_of(name)
        return "" if target is None else f"≥ {target:g}: {'met' if ratio >= target else 'not met'}"
    runs = [(_seat_label(r), r) for r in res["seat"]]
    rows = _rate_rows("control step", runs, "target", verdict)
    rows += [""] + _split_rows("control step", [(label, r, r) for label, r in runs])
    kw = res["seat"][0]["env_kwargs"]
    rows += ["", f"{res['seat'][0]['env_id']}, "
             + ", ".join(f"`{k}={v!r}`" for k, v in kw.items() if k not in ("control_dt", "overrides"))
             + f"; {res['steps']} steps of every environment per case and round (a batch's "
             f"N = {res['n_envs']} each), {res['seat'][0]['repeats']} rounds, {res['clock']} "
             "clock."]
    return "\n".join(rows) + "\n"


def step_table(res: dict) -> str:
    """The markdown tables of a 1 ms run's JSON (docs/environments.md pastes them between its
    markers; ``--render JSON`` prints them): rates, the cost split, batching."""
    def over_single(r, name):
        ratio = r["ratio_to_single"].get(name)
        return "" if ratio is None else f"{ratio:.2f}"
    runs = [(_settings_label(r), r) for r in res["runs"]]
    rows = _rate_rows("settings", runs, f"× the single env ({SINGLE_CASE}, median of per-round "
                      "ratios)", over_single)
    rows += [""] + _split_rows("settings, case", [(f"{label}, {case}", split, r)
                                                  for label, r in runs
                                                  for case, split in r["splits"].items()])
    rows += ["", "| settings | batching bound per core: nothing but the physics left | the "
             "compiled kernel kept | default threads over one thread (wall clock, runs "
             "interleaved) | load average (1 min, this run included), start → end |",
             "|---|---|---|---|---|"]
    for label, r in runs:
        b, load = r["batching bound per core (Amdahl)"], r["load average"]
        auto = ", ".join(f"{n}: {v:.2f}" for n, v in r["default over one thread (wall)"].items())
        rows.append(f"| {label} | {b['physics']:.2f} | {b['kernel']:.2f} | {auto} | "
                    f"{load['start']:.1f} → {load['end']:.1f} |")
    rows += ["", f"Paper scene, 1 ms control step, random actions, resets as episodes end; "
             f"{res['steps']} steps of every environment per case and round (a batch's N = "
             f"{res['n_envs']} each), {res['repeats']} rounds, {res['clock']} clock, "
             f"{res['numba_threads']} numba threads, {res['cores']} cores."]
    return "\n".join(rows) + "\n"


def render(res: dict) -> str:
    """The table of a run's JSON: the controller seat's (``--control-dt``) or the 1 ms one."""
    return seat_table(res) if "seat" in res else step_table(res)


def _rate_rows(first: str, runs: list, last: str, last_cell: Callable[[dict, str], str]) -> list:
    """Rows of the rates table: per run (``(label, run)``) and case, the rate, its ratio to
    Pendulum-v1 and a last column (``last_cell(run, case)``)."""
    rows = [f"| {first} | case | env steps/s | × Pendulum-v1 (median of per-round ratios) "
            f"| {last} |", "|---|---|---|---|---|"]
    for label, r in runs:
        for name, rate in r["rates"].items():
            ratio = r["ratio_to_pendulum"].get(name)
            rows.append(f"| {label} | {name} | {rate:,.0f} | "
                        f"{'1 (reference)' if ratio is None else f'{ratio:.2f}'} | "
                        f"{last_cell(r, name)} |")
    return rows


def _split_rows(first: str, splits: list) -> list:
    """Rows of the cost-split table: per ``(label, split, run)`` the parts of one step
    (:func:`split_of`), the integrator's work and the physics alone over the run's
    Pendulum-v1 rate."""
    rows = [f"| {first} | physics | + monitors, reward, obs | + Python `step` | "
            "+ wrappers | `env.step` | physics share | integrator steps (rejected), "
            "right-hand sides | a right-hand side (share of the physics) | physics alone, × "
            "Pendulum-v1 |",
            "|---|---|---|---|---|---|---|---|---|---|"]
    for label, sp, r in splits:
        c, i = sp["per-step us"], sp["integrator per step"]
        rows.append(f"| {label} | {c['physics']:.1f} µs | "
                    f"{c['kernel'] - c['physics']:.1f} µs | {c['unwrapped'] - c['kernel']:.1f} µs | "
                    f"{c['wrapped'] - c['unwrapped']:.1f} µs | {c['wrapped']:.1f} µs | "
                    f"{100 * c['physics'] / c['wrapped']:.0f} % | "
                    f"{i['steps']:.1f} ({i['rejected']:.2f}), {i['rhs']:.0f} | "
                    f"{i['rhs_ns']:.0f} ns ({100 * _rhs_share(sp):.0f} %) | "
                    f"{1e6 / c['physics'] / r['rates'][PENDULUM]:.2f} |")
    return rows


def _print_split(env_id: str, split: dict) -> None:
    print(f"  cost split of one {env_id} step [µs] (same trajectory):")
    print(f"    physics (integrate_sensed)         {split['physics']:8.1f}")
    print(f"    + monitors, reward, obs (kernel)   {split['kernel'] - split['physics']:8.1f}"
          f"   (kernel call {split['kernel']:.1f})")
    print(f"    + Python step()                    {split['unwrapped'] - split['kernel']:8.1f}"
          f"   (env.unwrapped.step {split['unwrapped']:.1f})")
    print(f"    + Gymnasium wrappers               {split['wrapped'] - split['unwrapped']:8.1f}"
          f"   (gym.make env.step {split['wrapped']:.1f})")
    print(f"    physics share of env.step: {100 * split['physics'] / split['wrapped']:.0f} %, "
          f"compiled kernel share {100 * split['kernel'] / split['wrapped']:.0f} %")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--n-envs", type=int, default=16)
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="scene override for every env, e.g. solver.rtol=1e-4")
    p.add_argument("--json", default=None, help="write the figures to this JSON file")
    p.add_argument("--clock", choices=("cpu", "wall"), default="cpu",
                   help="process CPU time (per core; default) or wall-clock time")
    p.add_argument("--control-dt", type=float, action="append", default=[], metavar="SECONDS",
                   help="measure the controller seat at this control step (repeatable) against "
                        "Pendulum-v1 instead of the 1 ms figures")
    p.add_argument("--compare-set", action="append", default=[], metavar="KEY=VALUE",
                   help="one more run with this scene override (repeatable; with --control-dt "
                        "at the first control step), e.g. solver.rtol=1e-4: what a looser "
                        "tolerance buys")
    p.add_argument("--law", action="append", default=[], metavar="NAME",
                   help="with --control-dt: one more run at each control step whose cases "
                        "(single, batch, vector) replay the actions this designed law sent on "
                        "the same episodes (repeatable), e.g. whirl-brake: what a learner near "
                        "the law steps")
    p.add_argument("--steps", type=int, default=None,
                   help="env steps of every environment per case and round (default 3000 with "
                        "--control-dt, else 600: two 0.3 s episodes)")
    p.add_argument("--render", default=None, metavar="JSON",
                   help="print the tables of a run's JSON (--json) and exit")
    args = p.parse_args(argv)
    if args.render:
        with open(args.render) as fh:
            print(render(json.load(fh)), end="")
        return 0
    global CLOCK
    CLOCK = time.process_time if args.clock == "cpu" else time.perf_counter
    overrides = dict(parse_assignment(a) for a in args.overrides)
    if args.control_dt:
        args.steps = args.steps or 3000
        res = {"clock": args.clock, "n_envs": args.n_envs, "steps": args.steps,
               "seat": [seat_speed(dt, args.repeats, args.n_envs, args.steps, overrides)
                        for dt in args.control_dt]
               + [seat_speed(args.control_dt[0], args.repeats, args.n_envs, args.steps,
                             dict(overrides, **dict([parse_assignment(a)])))
                  for a in args.compare_set]
               + [seat_speed(dt, args.repeats, args.n_envs, args.steps, overrides, law)
                  for law in args.law for dt in args.control_dt]}
        for r in res["seat"]:
            _print_seat(r)
        _write(args.json, res)
        return 0
    runs = [overrides] + [dict(overrides, **dict([parse_assignment(a)])) for a in args.compare_set]
    res = {"clock": args.clock, "n_envs": args.n_envs, "steps": args.steps or 600,
           "repeats": args.repeats, "control_dt_s": 1e-3,
           "numba_threads": numba.config.NUMBA_NUM_THREADS, "cores": os.cpu_count(),
           "runs": [step_speed(args.repeats, args.n_envs, args.steps or 600, o) for o in runs]}
    for r in res["runs"]:
        _print_step(r)
    _write(args.json, res)
    return 0


def _write(path: str | None, res: dict) -> None:
    if path:
        with open(path, "w") as fh:
            json.dump(res, fh, indent=2)
        print(f"wrote {path}")


if __name__ == "__main__":
    raise SystemExit(main())
