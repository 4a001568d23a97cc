"""``rotordrop oracle``: a searched open-loop command sequence of the supervisor interface per
scenario, scored beside learned and designed controllers on the same scenarios. Its score is
reachable on each drop (a lower bound on what the interface can reach), not a ceiling: the
search is local, over a few open-loop segments, and cannot express raw coil currents.

For each of ``--scenarios`` drops drawn where whirl is decided (``ORACLE_RANGES``: friction
0.38-0.6 unless ``--friction LO:HI`` says otherwise, power back 30-70 ms rounded up to the 5 ms control grid, any unbalance phase, the
environments' default ranges for the rest; seeds from ``SCENARIO_SEED``, disjoint from training
and evaluation seeds) a
cross-entropy search (:mod:`agents.benchmarking.search`) optimises an open-loop command sequence of
``RotorDrop-Full-v1`` with ``command="supervisor"``: piecewise constant over the segments
``SEGMENT_EDGES_MS`` after the fault, per segment both damper commands, the PID gain scale and
the four orbit-frame reference offsets, plus one delay after the power return before the
built-in PID is switched on. The search knows the scenario in advance, which no controller
does, and starts from the ``inner-loop`` commands (C_max, switch on at once, zero offsets), so
it never ends worse than that row. Because the offsets act in the frame of the sensed orbit,
inside the physics step, the "open-loop" sequence is still a feedback law of the inner loop.

Cost of an episode: the benchmark's J (:func:`agents.benchmarking.score.row_cost`, against the passive drop
of the same scenario); the search adds ``SHAPING`` x min(peak backward revolutions / 3, 1) so
that it sees progress towards a whirl-free drop before the whirl verdict flips; the oracle's
sequence is the rollout of lowest J among all the search ran. Every row
(baselines, shipped and ``--policy`` policies, the oracle) is scored on the same scenarios with
the benchmark's formula, score = 100 (1 - sum J / sum J_passive).

Outputs in ``--out``: ``oracle.json`` (settings, scenarios, per-scenario KPIs and J of every row,
the oracle's command sequence and search history, the summary table), ``oracle.png``, and the
whirl rate per friction bin as ``whirl_by_friction.png`` and ``whirl_by_friction.csv``. The
search is written after every scenario; a rerun with the same settings continues where it
stopped and re-scores the rows (add ``--policy`` runs without searching again). ``--no-search``
scores the rows alone, e.g. on 200 scenarios from another ``--scenario-seed``. The whirl
rate per friction bin (``whirl_by_friction``, ``whirl_by_friction.png``) uses
``--friction-bins`` edges, by default :data:`FRICTION_BINS` on the default range and 0.05-wide
bins on any other (:func:`friction_edges`). ``--constant GAIN:OFFSET_R`` adds designed rows
that need no knowledge of the scenario: the inner loop with a constant gain scale and radial
reference offset, the law of the baseline ``inner-loop-lift`` with other constants, at its
5 ms control step (:func:`constant_entry`);
``--start-from-constants`` starts each scenario's search from the best of ``inner-loop`` and
those rows there.

``--suite robust`` runs the same search and rows on the robust suite's scenarios instead
(:mod:`agents.benchmarking.robust`: the first ``--scenarios`` drops of ``rotordrop benchmark --suite robust``,
seeds from ``SUITE_SEED``, the robust plant spread, sensor noise and observation latency), each
built by the benchmark's own :func:`agents.benchmarking.benchmark.episode_kwargs` from the robust
:class:`Scenario` and scored as that suite scores it. Noise and latency act on the
observations only (:mod:`rotordrop_env.sensors`), so they change the rows that read the sensors
and not the oracle's open-loop sequence over the built-in PID, which knows the plant in advance.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from ..benchmarking.suites import SUITES
from ..benchmarking.benchmark import (EPISODE_TIME, TASKS, Entry, Scenario,
                                      controller_entry, episode_kwargs)
from ..control.controllers import BASELINES, Passive
from ..control.plant import plant_of
from ..benchmarking.rollout import final_kpis, run_episodes
from ..benchmarking.score import DEFAULT_SCORE, attach_bootstrap, overall_score, row_cost, write_json

ENV_ID = TASKS["full"]
COMMAND = "supervisor"
ORACLE_RANGES = {"contact.friction": (0.38, 0.6), "power_return_time": (0.03, 0.07),
                 "unbalance.angle_deg": (0.0, 360.0)}
SCENARIO_SEED = SUITES.get("full", "oracle").seed
SEGMENT_EDGES_MS = (0, 10, 20, 30, 45, 60, 90, 300)
SEGMENT_ACTIONS = ("damping1", "damping2", "gain", "offset_r1", "offset_t1", "offset_r2",
                   "offset_t2")
MAX_DELAY = 0.04            # switch-on delay after the power return: (theta + 1) / 2 x this [s]
CONTROL_DT = 0.005          # the commands are piecewise constant over >= 10 ms segments
SHAPING = 0.25
WHIRL_REVOLUTIONS = 3.0
#: ``--interface``: what the search commands (supervisor sequences, or raw-current corrections)
INTERFACES = ("supervisor", "currents")
#: the raw-current search: open-loop corrections of ``CURRENT_BASELINE``'s coil currents,
#: piecewise constant over ``CURRENT_SEGMENTS`` x ``CURRENT_STEPS`` control steps from the
#: power return (its 1 ms step), in [-2, 2] current limits (so it can override the baseline)
CURRENT_BASELINE = "whirl-brake"
CURRENT_SEGMENTS = 16
CURRENT_STEPS = 2


def check_interface(interface: str) -> str:
    if interface not in INTERFACES:
        raise ValueError(f"--interface = {interface!r} must be one of {', '.join(INTERFACES)}")
    return interface


def suite_scenarios(suite: str, n: int, seed: int,
                    friction: tuple[float, float] | None = None) -> list[tuple[Scenario, float, dict]]:
    """The first ``n`` scenarios of ``suite`` from ``seed``: (benchmark :class:`Scenario`,
    unbalance phase, the record written to oracle.json). ``robust``: the robust suite's own
    scenarios (:func:`agents.benchmarking.robust.robust_scenarios`; their unbalance phase is in the scene
    overrides, the phase argument is the benchmark's 0). A suite without its own draw (``full``)
    draws from ``ORACLE_RANGES``."""
    chosen = SUITES.get(suite, "oracle")
    if chosen.draw is not None:
        return [(sc, 0.0, robust_record(sc)) for sc in chosen.scenarios(n, seed)]
    return [(*as_benchmark(v, f"#{i}"), v) for i, v in enumerate(draw_scenarios(n, seed, friction))]


def robust_record(sc: Scenario) -> dict:
    """A robust scenario as the flat dict of the oracle's records (scene keys, power return)
    with its sensing and episode seed."""
    return {"contact.friction": sc.friction, **sc.overrides, **sc.env_kwargs,
            "sensor_noise": sc.sensor_noise, "latency_ms": round(1e3 * sc.latency_s, 9),
            "seed": sc.seed}


def draw_scenarios(n: int, seed: int = SCENARIO_SEED,
                   friction: tuple[float, float] | None = None) -> list[dict]:
    """``n`` scenario dicts (dotted scene keys and ``power_return_time``): what the Full
    environment draws from ``ORACLE_RANGES`` (friction from ``friction`` if given) and the default
    ranges at ``reset(seed=seed + i)`` (:func:`rotordrop_env.scenario.draw`)."""
    from rotordrop_env.scenario import draw
    ranges = oracle_ranges(friction)
    scenarios = []
    for i in range(n):
        values = draw(ranges, seed + i)[0]
        pr = values.pop("power_return_time")            # last, as the environment lists it
        scenarios.append(on_grid({**values, "power_return_time": pr}))
    return scenarios


def oracle_ranges(friction: tuple[float, float] | None = None) -> dict:
    """``ORACLE_RANGES`` with the friction range ``friction`` (checked: 0 <= LO < HI <= 1)."""
    ranges = dict(ORACLE_RANGES)
    if friction is not None:
        ranges["contact.friction"] = check_friction(friction)
    return ranges


def check_friction(friction) -> tuple[float, float]:
    """``(lo, hi)`` as floats; ValueError unless 0 <= lo < hi <= 1 (the scene's range of mu)."""
    try:
        lo, hi = (float(v) for v in friction)
    except (TypeError, ValueError):
        raise ValueError(f"--friction must be LO:HI, got {friction!r}") from None
    if not (0.0 <= lo < hi <= 1.0):
        raise ValueError(f"--friction must be LO:HI with 0 <= LO < HI <= 1, got {lo:g}:{hi:g}")
    return lo, hi


def friction_edges(friction: tuple[float, float], edges=None) -> tuple[float, ...]:
    """Bin edges of ``whirl_by_friction`` over the range ``friction``: ``edges`` (checked:
    increasing, from LO to HI), else :data:`FRICTION_BINS` on the default range and bins on
    the 0.05 grid (cut at LO and HI) on any other."""
    lo, hi = friction
    if edges is None:
        if (lo, hi) == (FRICTION_BINS[0], FRICTION_BINS[-1]):
            return FRICTION_BINS
        inner = np.arange(np.floor(lo / 0.05 + 1e-9) + 1, np.ceil(hi / 0.05 - 1e-9)) * 0.05
        return tuple(round(float(e), 6) for e in (lo, *inner, hi))
    edges = tuple(float(e) for e in edges)
    if len(edges) < 2 or any(b <= a for a, b in zip(edges, edges[1:])) \
            or not (np.isclose(edges[0], lo) and np.isclose(edges[-1], hi)):
        raise ValueError(f"--friction-bins must be increasing edges from {lo:g} to {hi:g} "
                         f"(the --friction range), got {','.join(f'{e:g}' for e in edges)}")
    return edges


def as_benchmark(values: dict, name: str) -> tuple[Scenario, float]:
    """The benchmark :class:`Scenario` and unbalance phase of a drawn scenario."""
    rest = {k: v for k, v in values.items()
            if k not in ("contact.friction", "unbalance.angle_deg", "power_return_time")}
    sc = Scenario(name, float(values["contact.friction"]), rest,
                  env_kwargs={"power_return_time": float(values["power_return_time"])})
    return sc, float(values["unbalance.angle_deg"])


def on_grid(values: dict) -> dict:
    """``values`` with the power return rounded up to the oracle's control grid (``CONTROL_DT``),
    as the environment rounds it: every row then sees the power at the same instant, whatever
    its control step (the ``full`` suite's rounding, :meth:`agents.benchmarking.suites.Suite.round_power`)."""
    return {**values, "power_return_time": SUITES.get("full", "oracle").round_power(
        values["power_return_time"])}


def n_params() -> int:
    return (len(SEGMENT_EDGES_MS) - 1) * len(SEGMENT_ACTIONS) + 1


def inner_loop_theta() -> np.ndarray:
    """The ``inner-loop`` row as a command sequence: C_max, nominal gain, no offsets, no delay."""
    seg = np.zeros((len(SEGMENT_EDGES_MS) - 1, len(SEGMENT_ACTIONS)))
    seg[:, :2] = 1.0
    return np.concatenate([seg.ravel(), [-1.0]])


def constant_theta(gain: float, offset_r: float) -> np.ndarray:
    """The law of :func:`constant_entry` (``InnerLoop(plant, gain, offset_r)``: C_max, the PID
    on at the power return, a constant gain action ``gain`` and radial reference offset
    ``offset_r`` on both planes) as a command sequence of the search: its start with
    ``--start-from-constants`` (tests/agents/research/test_oracle.py checks that both run the same drop)."""
    seg = inner_loop_theta()[:-1].reshape(len(SEGMENT_EDGES_MS) - 1, len(SEGMENT_ACTIONS))
    for name, value in (("gain", gain), ("offset_r1", offset_r), ("offset_r2", offset_r)):
        seg[:, SEGMENT_ACTIONS.index(name)] = value
    return np.concatenate([seg.ravel(), [-1.0]])


def check_constants(constants) -> list[tuple[float, float]]:
    """``--constant GAIN:OFFSET_R`` pairs as floats; ValueError unless both are in [-1, 1]."""
    out = []
    for pair in constants or []:
        g, r = (float(v) for v in pair)
        if not (-1.0 <= g <= 1.0 and -1.0 <= r <= 1.0):
            raise ValueError(f"--constant GAIN:OFFSET_R must have both in [-1, 1] (supervisor "
                             f"actions), got {g:g}:{r:g}")
        out.append((g, r))
    return out


def constant_name(gain: float, offset_r: float) -> str:
    return f"constant g={gain:g} r={offset_r:g}"


def constant_entry(gain: float, offset_r: float) -> Entry:
    """The ``--constant GAIN:OFFSET_R`` row: the designed law of ``inner-loop-lift``
    (:class:`agents.control.controllers.InnerLoop` with these constants, a causal law that does not know
    the scenario and reads no sensor) at ``inner-loop-lift``'s control step, run and scored as
    every other row; ``--constant 0.5:-0.5`` is ``inner-loop-lift`` itself."""
    from ..control.controllers import InnerLoop, InnerLoopLift, controller_env_kwargs
    return Entry(constant_name(gain, offset_r), "full",
                 lambda plant: InnerLoop(plant, gain, offset_r),
                 controller_env_kwargs(InnerLoopLift, ENV_ID))


def sequence_actions(thetas: np.ndarray, t: float, power_return: float,
                     action_names: list[str]) -> np.ndarray:
    """(n, n_actions) actions at time ``t`` after the fault for the command sequences
    ``thetas`` (n, :func:`n_params`)."""
    n_seg = len(SEGMENT_EDGES_MS) - 1
    seg = min(int(np.searchsorted(SEGMENT_EDGES_MS, 1e3 * t + 1e-9, side="right")) - 1, n_seg - 1)
    body = thetas[:, :-1].reshape(len(thetas), n_seg, len(SEGMENT_ACTIONS))[:, seg]
    delay = 0.5 * (thetas[:, -1] + 1.0) * MAX_DELAY
    a = np.zeros((len(thetas), len(action_names)), dtype=np.float32)
    for j, name in enumerate(SEGMENT_ACTIONS):
        a[:, action_names.index(name)] = body[:, j]
    a[:, action_names.index("levitate")] = np.where(t >= power_return + delay - 1e-9, 1.0, -1.0)
    return np.clip(a, -1.0, 1.0)


def rollout(venv, thetas: np.ndarray, power_return: float, seed: int) -> list[dict]:
    """Episode KPIs of each command sequence on the (identical) environments of ``venv``, each
    reset with ``seed``: the benchmark's episode seed of the drop, so every candidate meets the
    sensor noise the benchmark's rows meet there (common random numbers)."""
    names = list(venv.envs[0].action_names)
    n_steps = venv.envs[0].n_steps
    dt = venv.envs[0].dt
    for e in range(venv.num_envs):
        venv.batch.reset_env(e, int(seed))
    kpis: list[dict] = []
    for k in range(n_steps):
        _, _, dones, infos = venv.step(sequence_actions(thetas, k * dt, power_return, names))
        if k == n_steps - 1:
            if not dones.all():
                raise RuntimeError("oracle rollouts must all end at the time limit")
            kpis = [final_kpis(info) for info in infos]
    return kpis


def kpi_row(k: dict) -> dict:
    """The benchmark row fields of one episode's KPIs."""
    return dict(backward_whirl=float(bool(k["backward_whirl"])),
                peak_contact_force_N=float(k["peak_contact_force_N"]),
                max_displacement_um=float(k["max_displacement_um"]),
                relevitated=float(bool(k.get("relevitated"))),
                relevitation_time_s=(k.get("relevitation_time_s") if k.get("relevitated")
                                     else None),
                peak_whirl_revolutions=float(k["peak_whirl_revolutions"]))


def episode_cost(row: dict, passive: dict) -> float:
    return row_cost(row, passive, EPISODE_TIME, True)


def search_kwargs(sc: Scenario, phase: float) -> dict:
    """The env kwargs of the oracle's rollouts of one scenario: the benchmark's
    :func:`episode_kwargs` of a supervisor entry at ``CONTROL_DT`` (the scenario's scene,
    power return, sensor noise and latency)."""
    entry = Entry("oracle", "full", None, {"command": COMMAND, "control_dt": CONTROL_DT})
    return episode_kwargs(entry, sc, phase)


def search_scenario(sc: Scenario, phase: float, passive: dict, population: int, iterations: int,
                    seed: int, progress: bool, start: np.ndarray | None = None,
                    copies: tuple = ()) -> dict:
    """Cross-entropy search of the command sequence of one scenario (module doc), from the
    ``inner-loop`` sequence or ``start``; each generation is one batched rollout of
    ``population`` identical environments (per drop). ``copies``: further ``(scenario, phase,
    passive)`` drops the sequence must suit as well: a candidate's cost is its mean over the
    scenario and its copies (a search blind to what tells them apart, e.g. a friction change
    no sensor resolves); J is then that mean and ``kpis`` the scenario's own."""
    import warnings
    from rotordrop_env import BatchedRotorDropVecEnv
    from rotordrop_env.vec_env import TorchThreadsWarning
    from ..benchmarking.search import cross_entropy
    drops = [(sc, phase, passive), *copies]
    venvs: dict[tuple[int, int], object] = {}
    seen: dict[bytes, tuple[float, dict]] = {}

    def costs(thetas: np.ndarray) -> list[float]:
        n = len(thetas)
        shaped, true = np.zeros(n), np.zeros(n)
        own: list[dict] = []
        for c, (drop, drop_phase, drop_passive) in enumerate(drops):
            if (c, n) not in venvs:
                with warnings.catch_warnings():     # no network here: torch's threads are idle
                    warnings.simplefilter("ignore", TorchThreadsWarning)
                    venvs[c, n] = BatchedRotorDropVecEnv(ENV_ID, n, seed=0,
                                                         **search_kwargs(drop, drop_phase))
            kpis = rollout(venvs[c, n], thetas, drop.env_kwargs["power_return_time"], drop.seed)
            for m, k in enumerate(kpis):
                row = kpi_row(k)
                j = episode_cost(row, drop_passive)
                true[m] += j / len(drops)
                shaped[m] += (j + SHAPING * min(row["peak_whirl_revolutions"] / WHIRL_REVOLUTIONS,
                                                1.0)) / len(drops)
                if c == 0:
                    own.append(row)
        for th, j, row in zip(thetas, true, own):
            seen[th.tobytes()] = (float(j), row)
        return shaped.tolist()

    mean = inner_loop_theta() if start is None else np.asarray(start, dtype=float)
    t0 = time.perf_counter()
    best, theta, history = cross_entropy(
        costs, mean, np.full(mean.shape, 0.5), -1.0, 1.0, iterations, population,
        max(2, population // 5), np.random.default_rng(seed), min_std=0.05, progress=progress,
        desc=f"oracle {sc.name}", batch=True)
    for v in venvs.values():
        v.close()
    key = min(seen, key=lambda k: seen[k][0])           # the lowest true J of every rollout
    j, row = seen[key]
    theta = np.frombuffer(key, dtype=float)
    return dict(theta=theta.tolist(), search_cost=best, J=j, kpis=row,
                start_J=seen[mean.tobytes()][0], start=mean.tolist(),
                rollouts=1 + iterations * population, wall_time_s=time.perf_counter() - t0,
                history=[dict(iteration=h["iteration"], best_cost=h["best_cost"],
                              generation_best=h["generation_best"]) for h in history])


def search_currents(sc: Scenario, phase: float, passive: dict, population: int, iterations: int,
                    seed: int, progress: bool) -> dict:
    """Cross-entropy search of an open-loop correction of ``CURRENT_BASELINE``'s coil currents
    on one drop (``--interface currents``; the correction of
    :class:`agents.control.open_loop.OpenLoopCorrection`), for the benchmark's J with the
    supervisor search's shaping; starts from no correction (the baseline itself), so its J is
    never above the baseline's on the drop. One episode per candidate (no batching)."""
    from rotordrop_env.layout import CURRENT_ACTIONS
    from ..benchmarking.benchmark import controller_entry
    from ..control.controllers import controller_class
    from ..control.open_loop import OpenLoopCorrection
    from ..benchmarking.search import cross_entropy
    entry = controller_entry(controller_class(CURRENT_BASELINE), ENV_ID)
    kw = episode_kwargs(entry, sc, phase)
    seen: dict[bytes, tuple[float, dict]] = {}

    def cost(theta: np.ndarray) -> float:
        kpis = run_episodes(ENV_ID, lambda plant: OpenLoopCorrection(
            plant, CURRENT_BASELINE, CURRENT_STEPS, theta), [sc.seed], kw)[0].kpis
        row = kpi_row(kpis)
        j = episode_cost(row, passive)
        seen[np.asarray(theta, dtype=float).tobytes()] = (float(j), row)
        return j + SHAPING * min(row["peak_whirl_revolutions"] / WHIRL_REVOLUTIONS, 1.0)

    mean = np.zeros((CURRENT_SEGMENTS, len(CURRENT_ACTIONS)))
    t0 = time.perf_counter()
    best, theta, history = cross_entropy(
        cost, mean, np.full(mean.shape, 0.5), -2.0, 2.0, iterations, population,
        max(2, population // 5), np.random.default_rng(seed), min_std=0.05, progress=progress,
        desc=f"oracle currents {sc.name}")
    key = min(seen, key=lambda k: seen[k][0])
    j, row = seen[key]
    return dict(theta=np.frombuffer(key, dtype=float).reshape(mean.shape).tolist(),
                search_cost=best, J=j, kpis=row, start_J=seen[mean.tobytes()][0],
                start=mean.tolist(), rollouts=len(seen), wall_time_s=time.perf_counter() - t0,
                history=[dict(iteration=h["iteration"], best_cost=h["best_cost"],
                              generation_best=h["generation_best"]) for h in history])


def row_entries(policies: list[str] | None, suite: str = "full") -> list[Entry]:
    """Every baseline with channels in the Full task, the shipped Full policies and the
    ``--policy`` extras (paths or controller classes), as the benchmark builds them (with
    as the benchmark's drawn suites do, :func:`agents.benchmarking.benchmark.robust_entries`: each
    in its seat, with the constants tuned for ``suite``)."""
    from ..benchmarking.benchmark import robust_entries
    return robust_entries(policies, suite=SUITES.get(suite, "oracle"))[0]


def score_rows(per_scenario: list[dict], names: list[str]) -> list[dict]:
    """Summary per row (benchmark score over the scenarios, whirl and re-levitation rates)."""
    passive = [s["rows"]["passive"] for s in per_scenario]
    p_costs = [r["J"] for r in passive]
    whirls = [r["backward_whirl"] >= 0.5 for r in passive]
    table = []
    for name in names:
        rows = [s["rows"][name] for s in per_scenario]
        where = [r["backward_whirl"] for r, w in zip(rows, whirls) if w]
        table.append(dict(controller=name, score=overall_score([r["J"] for r in rows], p_costs),
                          whirl_rate=float(np.mean([r["backward_whirl"] for r in rows])),
                          whirl_rate_where_passive_whirls=float(np.mean(where)) if where else None,
                          relevitation_rate=float(np.mean([r["relevitated"] for r in rows])),
                          mean_J=float(np.mean([r["J"] for r in rows]))))
    table.sort(key=lambda e: -e["score"])
    return table


def add_bootstrap(summary: list[dict], per_scenario: list[dict], reference: str) -> None:
    """Each summary row gains its paired-bootstrap SE over the drops and its difference to the
    ``reference`` row (:func:`agents.benchmarking.score.attach_bootstrap`, the leaderboards'
    resamples, seed and fields)."""
    names = [e["controller"] for e in summary]
    costs = np.array([[s["rows"][n]["J"] for s in per_scenario] for n in names])
    passive = np.array([s["rows"]["passive"]["J"] for s in per_scenario])
    attach_bootstrap(summary, costs, passive, names.index(reference))


def oracle(out: str | Path, scenarios: int = 20, population: int = 24, iterations: int = 10,
           seed: int = 0, policies: list[str] | None = None, progress: bool = True,
           plots: bool = True, search: bool = True, scenario_seed: int | None = None,
           friction: tuple[float, float] | None = None, friction_bins=None,
           suite: str = "full", constants=None, start_from_constants: bool = False,
           interface: str = "supervisor") -> dict:
    """Search the command sequence of each scenario, score every row on the same scenarios and
    write ``oracle.json`` (and ``oracle.png``) into ``out`` (module doc). ``search=False``
    scores the rows only (no oracle row): the same comparison on many more scenarios.
    ``friction``: the (LO, HI) range of mu the scenarios are drawn from (default 0.38-0.6);
    ``friction_bins``: the edges of the per-friction whirl table (:func:`friction_edges`);
    ``suite``: ``full`` (the drops above) or ``robust`` (the robust suite's, module doc;
    ``scenario_seed`` defaults to its ``SUITE_SEED``); ``constants``: (gain, radial offset)
    pairs scored as extra designed rows (:func:`constant_entry`, ``--constant``); with
    ``start_from_constants`` each scenario's search starts from the best of ``inner-loop`` and
    these rows there (so that the oracle is never worse than any of them); ``interface``
    ``currents``: search open-loop corrections of whirl-brake's coil currents instead
    (:func:`search_currents`)."""
    from tqdm.auto import tqdm
    from ..benchmarking.score import fmt_or_dash
    if scenarios < 1 or population < 2 or iterations < 0:
        raise ValueError(f"need --scenarios >= 1, --population >= 2, --iterations >= 0 (got "
                         f"{scenarios}, {population}, {iterations})")
    constants = check_constants(constants)
    if check_interface(interface) == "currents" and start_from_constants:
        raise ValueError("--start-from-constants applies to --interface supervisor only (the "
                         "current search starts from whirl-brake)")
    settings, ranges = suite_settings(suite, friction, scenario_seed)
    if interface == "currents":
        settings.update(interface=interface, current_baseline=CURRENT_BASELINE,
                        current_segments=CURRENT_SEGMENTS, current_steps=CURRENT_STEPS)
    edges = friction_edges(ranges["contact.friction"], friction_bins)
    settings.update(scenarios=scenarios, population=population, iterations=iterations, seed=seed)
    if start_from_constants:
        if not constants:
            raise ValueError("--start-from-constants needs at least one --constant GAIN:OFFSET_R")
        settings["search_start"] = ["inner-loop", *(list(c) for c in constants)]
    settings = {k: settings[k] for k in SETTINGS_ORDER if k in settings}
    drawn = suite_scenarios(suite, scenarios, settings["scenario_seed"], ranges["contact.friction"])
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    done = _previous(out / "oracle.json", settings)
    entries = row_entries(policies, suite)
    const_entries = [constant_entry(g, r) for g, r in constants]
    t0 = time.perf_counter()
    per_scenario = []
    if not search:
        done = {}
    bar = tqdm(total=scenarios, desc="oracle scenarios", unit="sc", disable=not progress)
    for i, (sc, phase, values) in enumerate(drawn):
        rows = {}
        for entry in entries + const_entries:
            kpis = run_episodes(ENV_ID, entry.make, [sc.seed],
                                episode_kwargs(entry, sc, phase))[0].kpis
            rows[entry.name] = kpi_row(kpis)
        for row in rows.values():
            row["J"] = episode_cost(row, rows["passive"])
        found = None
        if search:
            if interface == "currents":
                found = done.get(i) or search_currents(sc, phase, rows["passive"], population,
                                                       iterations, seed + i, progress)
            else:
                found = done.get(i) or search_scenario(
                    sc, phase, rows["passive"], population, iterations, seed + i, progress,
                    best_start(rows, constants) if start_from_constants else None)
            rows["oracle"] = dict(found["kpis"], J=found["J"])
        per_scenario.append(dict(index=i, scenario=values, rows=rows, search=found))
        report = _report(settings, per_scenario, [e.name for e in entries], t0, search,
                         [e.name for e in const_entries])
        write_json(out / "oracle.json", report)              # after every scenario: resumable
        bar.update(1)
    bar.close()
    report["whirl_by_friction"] = whirl_by_friction(report, edges)
    write_whirl_csv(report["whirl_by_friction"], out / "whirl_by_friction.csv")
    if plots:
        report["figures"] = [plot_oracle(report, out / "oracle.png").name,
                             plot_whirl_by_friction(report, out / "whirl_by_friction.png").name]
    write_json(out / "oracle.json", report)
    lo, hi = ranges["contact.friction"]
    where = SUITES.get(suite, "oracle").about
    print(f"{f'oracle (searched {interface} plans)' if search else 'rows'}, {ENV_ID}, {scenarios} scenarios "
          f"({where}, friction {lo:g}-{hi:g}, seeds from {settings['scenario_seed']}):")
    print("| controller | score | whirl rate | whirl where passive whirls | re-levitated |")
    print("|---|---:|---:|---:|---:|")
    for e in report["summary"]:
        print(f"| {e['controller']} | {e['score']:.2f} | {e['whirl_rate']:.2f} | "
              f"{fmt_or_dash(e['whirl_rate_where_passive_whirls'], '.2f')} | "
              f"{e['relevitation_rate']:.2f} |")
    print_whirl_by_friction(report["whirl_by_friction"])
    return report


#: key order of ``settings`` in oracle.json (``suite`` and the sensing only with --suite robust,
#: so that the full suite's settings, and the runs they resume, are as before)
SETTINGS_ORDER = ("env_id", "command", "suite", "scenarios", "population", "iterations", "seed",
                  "scenario_seed", "ranges", "sensor_noise_m", "latency_ms", "segment_edges_ms",
                  "segment_actions", "max_delay_s", "control_dt", "shaping", "episode_time_s",
                  "search_start", "score", "interface", "current_baseline", "current_segments",
                  "current_steps")


def best_start(rows: dict, constants: list[tuple[float, float]]) -> np.ndarray:
    """The sequence of lowest J on this scenario among ``inner-loop`` and the constant laws."""
    options = [(rows["inner-loop"]["J"], inner_loop_theta())]
    options += [(rows[constant_name(g, r)]["J"], constant_theta(g, r)) for g, r in constants]
    return min(options, key=lambda o: o[0])[1]


def suite_settings(suite: str, friction, scenario_seed: int | None) -> tuple[dict, dict]:
    """The suite's part of oracle.json's settings and its ranges (checked: ``friction`` only
    with the full suite, whose range it sets)."""
    settings = dict(env_id=ENV_ID, command=COMMAND, segment_edges_ms=list(SEGMENT_EDGES_MS),
                    segment_actions=list(SEGMENT_ACTIONS), max_delay_s=MAX_DELAY,
                    control_dt=CONTROL_DT, shaping=SHAPING, episode_time_s=EPISODE_TIME,
                    score=DEFAULT_SCORE)
    chosen = SUITES.get(suite, "oracle")
    if chosen.draw is not None:                     # drawn with its sensing (robust)
        from ..benchmarking.robust import LATENCY_MS, ROBUST_RANGES, SENSOR_NOISE
        if friction is not None:
            raise ValueError("--friction does not apply to --suite robust (its scenarios are the "
                             "robust suite's, friction 0.3-0.6)")
        ranges = dict(ROBUST_RANGES)
        settings.update(suite=suite, sensor_noise_m=SENSOR_NOISE, latency_ms=list(LATENCY_MS))
    else:
        ranges = oracle_ranges(friction)
    default_seed = chosen.seed
    settings.update(ranges={k: list(v) for k, v in ranges.items()},
                    scenario_seed=default_seed if scenario_seed is None else scenario_seed)
    return settings, ranges


def write_whirl_csv(table: dict, path: Path) -> Path:
    """The per-friction whirl table as CSV: one line per row and bin (controller, bin edges,
    drops, whirling drops, whirl rate; empty where the bin has no drop)."""
    import csv
    edges = table["edges"]
    with Path(path).open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["controller", "mu_lo", "mu_hi", "drops", "whirls", "whirl_rate"])
        for name, rates in table["rates"].items():
            for lo, hi, n, r in zip(edges[:-1], edges[1:], table["counts"], rates):
                w.writerow([name, lo, hi, n, "" if r is None else round(r * n),
                            "" if r is None else f"{r:.4f}"])
    return Path(path)


def print_whirl_by_friction(table: dict) -> None:
    """The per-friction whirl table as markdown (rows: controllers; columns: bins)."""
    edges = table["edges"]
    bins = [f"{a:.2f}-{b:.2f}" for a, b in zip(edges[:-1], edges[1:])]
    print("| whirl rate per friction bin | " + " | ".join(bins) + " |")
    print("|---|" + "---:|" * len(bins))
    print("| drops | " + " | ".join(str(c) for c in table["counts"]) + " |")
    for name, rates in table["rates"].items():
        print(f"| {name} | " + " | ".join("-" if r is None else f"{r:.2f}" for r in rates) + " |")


def _report(settings: dict, per_scenario: list[dict], names: list[str], t0: float,
            search: bool = True, constants: list[str] = ()) -> dict:
    """The summary of the rows so far; ``best_designed`` and the oracle's gain over it count
    the baselines only, the ``constants`` rows are listed beside them (:func:`constant_entry`)."""
    summary = score_rows(per_scenario, names + list(constants) + (["oracle"] if search else []))
    learned = {n for n in names if n not in BASELINES}
    designed = [e for e in summary if e["controller"] in BASELINES and e["controller"] != "passive"]
    best = designed[0] if designed else None
    orc = next((e for e in summary if e["controller"] == "oracle"), None)
    if best is not None and per_scenario:
        add_bootstrap(summary, per_scenario, best["controller"])
    return dict(settings=settings, per_scenario=per_scenario, summary=summary,
                learned=sorted(learned), constant_rows=list(constants),
                best_designed=best["controller"] if best else None,
                oracle_gain_over_best_designed=(orc["score"] - best["score"]
                                                if best and orc else None),
                wall_time_s=time.perf_counter() - t0)


def _previous(path: Path, settings: dict) -> dict[int, dict]:
    """The searches of an earlier run with the same settings, by scenario index."""
    import json
    if not path.is_file():
        return {}
    try:
        old = json.loads(path.read_text())
    except ValueError:
        return {}
    if old.get("settings") != settings:
        return {}
    return {s["index"]: s["search"] for s in old.get("per_scenario", []) if s.get("search")}


def plot_oracle(report: dict, path: Path) -> Path:
    """Score and whirl rate of every row on the oracle's scenarios (oracle and best designed
    highlighted), and each scenario's J for passive, best designed, oracle and learned rows."""
    import matplotlib.pyplot as plt
    summary = report["summary"]
    names = [e["controller"] for e in summary]
    colors = ["tab:red" if n == "oracle" else "tab:green" if n in report["learned"] else
              "tab:blue" for n in names]
    fig, axes = plt.subplots(1, 3, figsize=(16, 0.35 * len(names) + 2.5))
    y = np.arange(len(names))[::-1]
    axes[0].barh(y, [e["score"] for e in summary], color=colors)
    suite = report["settings"].get("suite", "full")
    axes[0].set(yticks=y, yticklabels=names, xlabel="score (benchmark formula)",
                title=f"{len(report['per_scenario'])} scenarios, RotorDrop-Full-v1"
                      + (f", {suite} suite" if "suite" in report["settings"] else ""))
    axes[1].barh(y, [e["whirl_rate"] for e in summary], color=colors)
    axes[1].set(yticks=y, yticklabels=[], xlabel="backward-whirl rate", xlim=(0, 1))
    idx = np.arange(len(report["per_scenario"]))
    show = ["passive", report["best_designed"], *(["oracle"] if "oracle" in names else []),
            *report.get("constant_rows", []), *report["learned"]]
    for name in dict.fromkeys(n for n in show if n):
        axes[2].plot(idx, [s["rows"][name]["J"] for s in report["per_scenario"]], "o-", ms=3,
                     label=name)
    axes[2].set(xlabel="scenario", ylabel="J (lower is better)", title="cost per scenario")
    axes[2].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


FRICTION_BINS = (0.38, 0.44, 0.50, 0.55, 0.60)


def whirl_by_friction(report: dict, edges=FRICTION_BINS) -> dict:
    """Backward-whirl rate of every row per friction bin of the scenarios: {"edges", "counts",
    "rates": {row: [rate per bin, None where the bin is empty]}}."""
    mu = np.array([s["scenario"]["contact.friction"] for s in report["per_scenario"]])
    which = np.clip(np.searchsorted(edges, mu, side="right") - 1, 0, len(edges) - 2)
    counts = [int(np.sum(which == b)) for b in range(len(edges) - 1)]
    rates = {}
    for e in report["summary"]:
        w = np.array([s["rows"][e["controller"]]["backward_whirl"] for s in report["per_scenario"]])
        rates[e["controller"]] = [float(w[which == b].mean()) if counts[b] else None
                                  for b in range(len(edges) - 1)]
    return dict(edges=list(edges), counts=counts, rates=rates)


def plot_whirl_by_friction(report: dict, path: Path) -> Path:
    """Whirl rate per friction bin of passive, the best designed row, the oracle (if searched)
    and the learned rows."""
    import matplotlib.pyplot as plt
    table = report.get("whirl_by_friction") or whirl_by_friction(report)
    edges = table["edges"]
    mid = [0.5 * (a + b) for a, b in zip(edges[:-1], edges[1:])]
    fig, ax = plt.subplots(figsize=(7, 4))
    show = ["passive", report["best_designed"], "inner-loop", "oracle", *report["learned"]]
    for name in dict.fromkeys(n for n in show if n in table["rates"]):
        rates = [np.nan if r is None else r for r in table["rates"][name]]
        ax.plot(mid, rates, "o-", label=name)
    ax.set(xlabel="friction coefficient (bin centre)", ylabel="backward-whirl rate",
           ylim=(-0.02, 1.02), title="drops per bin: " + ", ".join(str(c) for c in table["counts"]))
    ax.axhline(0.05, color="k", lw=0.8, ls=":", label="goal: 5 %")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
