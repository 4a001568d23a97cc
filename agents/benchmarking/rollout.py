"""Run a controller or a learned policy for whole episodes and collect the episode KPIs.

``run_episodes`` is what ``evaluate`` and ``benchmark`` use: one environment per scenario,
episodes seeded ``seeds[i]``, the KPIs taken from the final step's ``info`` (``kpi_*``), and,
when asked, the time series needed for the orbit and force plots. A controller is built afresh
for every episode (so state it keeps outside ``reset`` cannot leak into the next one); a
learned policy is built once. ``check_actor`` fails fast on a broken actor before long runs.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np


from ..control.controllers import Controller, check_controller
from ..control.plant import POSITIONS, Plant, make_env

MONITOR_DT = 2e-4            # KPI sampling interval of every benchmark episode [s]


def monitor_kwargs(kw: dict) -> dict:
    """``samples_per_step`` so that the KPI monitor samples every 0.2 ms whatever the control
    step (the environments' default: 5 samples per 1 ms step). Peak forces of impacts lasting
    about a millisecond are under-read at coarser sampling, which would favour controllers
    with longer control steps."""
    dt = float(kw.get("control_dt", 1e-3))
    return {"samples_per_step": max(5, int(round(dt / MONITOR_DT)))}


def merge_env_kwargs(base: dict, user: dict, randomize: bool) -> dict:
    """Env kwargs: the policy's training kwargs, then the user's; scene keys (and the power
    return) the user sets are taken out of the randomisation so that they stay at the given
    value."""
    kw = dict(base)
    for k, v in user.items():
        if k == "overrides":
            kw["overrides"] = {**(kw.get("overrides") or {}), **v}
        else:
            kw[k] = v
    kw["randomize"] = randomize
    kw.setdefault("terminate_on_failure", False)
    kw.update(monitor_kwargs(kw))              # KPI sampling every 0.2 ms at any control step
    if not randomize:
        kw.pop("randomization", None)          # the env refuses ranges it would not draw from
        return kw
    fixed = [*(kw.get("overrides") or {}), *(["power_return_time"] if "power_return_time" in user else [])]
    if fixed:
        kw["randomization"] = {**(kw.get("randomization") or {}), **{k: None for k in fixed}}
    return kw


@dataclass
class Episode:
    """One finished episode: KPIs (``kpi_`` prefix removed), return, and optional time series."""
    seed: int
    kpis: dict
    reward: float
    length: int
    t: np.ndarray | None = None                 # time since the fault [s]
    obs: np.ndarray | None = None               # physical (SI) observations, (steps, n_obs)
    actions: np.ndarray | None = None
    contact_force: np.ndarray | None = None     # per step, (steps, n) [N]
    obs_names: tuple[str, ...] = ()             # + x1, y1, x2, y2 for a full_state env
    action_names: tuple[str, ...] = ()
    scenario: dict | None = None                # the scenario drawn at reset (env.unwrapped.scenario)


#: KPIs whose info value is the sentinel ``rotordrop_env.info.MISSING`` when they do not exist
#: (no re-levitation, no ball model): None in an Episode's KPIs (JSON null, skipped by means)
OPTIONAL_KPIS = ("relevitation_time_s", "max_ball_load_N", "max_contact_pressure_MPa")


def final_kpis(info: dict) -> dict:
    """The ``kpi_*`` entries of a final step's ``info`` as Python values, prefix removed; the
    sentinel of a KPI that does not exist becomes None."""
    kpis = {k[4:]: (v.item() if isinstance(v, np.generic) else v)
            for k, v in info.items() if k.startswith("kpi_")}
    for k in OPTIONAL_KPIS:
        if k in kpis and (kpis[k] < 0.0 or (k == "relevitation_time_s" and not kpis["relevitated"])):
            kpis[k] = None
    return kpis


def run_episodes(env_id: str, make_actor: Callable[[Plant], object], seeds, env_kwargs=None,
                 record: bool = False, frames: list | None = None) -> list[Episode]:
    """Run one episode per seed with the actor built by ``make_actor(plant)`` (a controller
    anew for each episode). ``frames``: a list that gets ``env.render()`` after the reset and
    after every step (the env kwargs must set ``render_mode="rgb_array"``)."""
    env = make_env(env_id, **(env_kwargs or {}))
    try:
        plant = Plant.from_env(env)
        actor = make_actor(plant)
        episodes = []
        for i, s in enumerate(seeds):
            if i and isinstance(actor, Controller):
                actor = make_actor(plant)
            episodes.append(_episode(env, plant, actor, int(s), record, frames))
        return episodes
    finally:
        env.close()


def check_actor(env_id: str, make_actor: Callable[[Plant], object], env_kwargs=None) -> None:
    """Build the actor for ``gym.make(env_id, **env_kwargs)`` and run
    :func:`~agents.control.controllers.check_controller` on its first observation (seed 0): raises
    ``ControllerError`` (a ValueError) naming the actor if it cannot act."""
    env = make_env(env_id, **(env_kwargs or {}))
    try:
        plant = Plant.from_env(env)
        obs, _ = env.reset(seed=0)
        check_controller(make_actor(plant), plant, obs)
    finally:
        env.close()


def _episode(env, plant: Plant, actor, seed: int, record: bool, frames: list | None = None) -> Episode:
    obs, info = env.reset(seed=seed)
    if frames is not None:
        frames.append(env.render())
    scenario = env.unwrapped.scenario
    total, steps = 0.0, 0
    rec_obs, rec_act, rec_f = [], [], []
    start, running = np.ones(1, dtype=bool), np.zeros(1, dtype=bool)
    extra = () if not record or set(POSITIONS) <= set(plant.obs_names) else POSITIONS
    while True:
        action, _ = actor.predict(obs[None, :], episode_start=start, deterministic=True)
        start = running
        a = action[0]
        if record:
            row = obs.astype(np.float64) * plant.obs_scale
            rec_obs.append(np.concatenate([row, sensor_positions(env)]) if extra else row)
            rec_act.append(np.atleast_1d(np.asarray(a, dtype=np.float64)))
        obs, reward, terminated, truncated, info = env.step(a)
        if frames is not None:
            frames.append(env.render())
        if record:
            rec_f.append(np.atleast_1d(np.asarray(info.get("contact_force_N", np.nan), dtype=float)))
        total += float(reward)
        steps += 1
        if terminated or truncated:
            break
    ep = Episode(seed, final_kpis(info), total, steps, obs_names=plant.obs_names + extra,
                 action_names=plant.action_names, scenario=scenario)
    if record:
        ep.t = np.arange(steps) * plant.control_dt
        ep.obs = np.array(rec_obs)
        ep.actions = np.array(rec_act)
        ep.contact_force = np.array(rec_f)
    return ep


def sensor_positions(env) -> np.ndarray:
    """(4,) x1, y1, x2, y2 [m]: the rotor axis at the AMB (sensor) planes from the env's state,
    for the orbit plots of a ``full_state=True`` environment, which does not observe them."""
    u = env.unwrapped
    return u.model.sensor_positions(u.state)
