"""``rotordrop benchmark``: every baseline and every shipped policy on a fixed, seeded suite.

1. **Passive threshold.** The passive drop (``RotorDrop-Passive-v1``, paper scene) is run on a
   friction grid (``THRESHOLD_GRID``) for each unbalance phase of the suite; the threshold μ* is
   the lowest grid friction from which on the passive drop whirls in at least half of the phases
   at every grid point. Between the first whirl and μ* the outcome depends on the phase
   (the drop is chaotic there), above μ* the passive drop whirls.
2. **Scenarios** (:func:`scenario_suite`): frictions μ* + 0.05, + 0.10, + 0.15 (passive whirls),
   0.10 (passive rests: a controller must do no harm), 0.25 (the paper's base case) and 0.6; at
   μ* + 0.05: support stiffness 2e6 and 1e9 N/m, spin speed 6000 and 15000 rpm, a 5 g
   unbalance, the paper's slip law (eq. 19 as printed: a model-form change), and (re-levitation tasks) power back at 0.15 s. A
   scenario is in-distribution when all its values lie inside the environments' default
   randomisation ranges (the training distribution of the shipped policies), else out of it.
   Each scenario runs once per unbalance phase (``PHASES``): the episodes are deterministic.
3. **Tasks.** ``damping`` (``RotorDrop-Damping-v1``), ``relevitate``
   (``RotorDrop-Relevitate-v1``) and ``full`` (``RotorDrop-Full-v1``, both channels): every
   baseline (and user controller, ``--policy module:Class``) that has its channels in the task
   (:func:`controller_env_kwargs` picks the re-levitation command its channels need), the passive reference with the AMBs left off, learned policies with the command
   they were trained with.
   Episodes last ``EPISODE_TIME`` and are not cut short at the stator (``terminate_on_failure =
   False``) so that whirl is measured as ``rotordrop drop`` measures it.
4. **Score** (:mod:`agents.benchmarking.score`): per task, 100 (1 − Σ J / Σ J_passive) over the suite;
   ``score`` picks J (``severity``, the default, or ``legacy``). Every leaderboard row carries
   a paired bootstrap over the drops (scenario × phase episodes, the same for every row) of its
   score and of its difference to the best designed row of its task (:func:`add_uncertainty`).

Outputs: ``benchmark.json`` (threshold sweep, scenarios, one row per controller and scenario,
leaderboard), ``leaderboard.md``, ``score.png``, ``whirl_map.png``, ``peak_force.png``.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..control.controllers import BASELINES, Passive, controller_class, controller_env_kwargs, make_controller
from ..control.plant import task_flags
from ..control.seats import check_seat
from ..learning.policies import LearnedPolicy, load_shipped, policy_label
from .rollout import check_actor, monitor_kwargs, run_episodes
from .score import (BOOTSTRAP_RESAMPLES, BOOTSTRAP_SEED, DEFAULT_SCORE, attach_bootstrap,
                    check_score, drop_costs, fmt_or_dash, overall_score, row_cost, summarize,
                    write_json)

EPISODE_TIME = 0.3
EVAL_KWARGS = dict(episode_time=EPISODE_TIME, terminate_on_failure=False, randomize=False)
PHASES = (0.0, 90.0, 180.0, 270.0)
QUICK_PHASES = (0.0, 180.0)
THRESHOLD_GRID = tuple(round(0.10 + 0.02 * i, 2) for i in range(21))     # 0.10 ... 0.50
WHIRL_MARGINS = (0.05, 0.10, 0.15)


def _env_tasks() -> tuple[dict[str, str], tuple[str, ...]]:
    """The benchmark tasks as the environments declare them (:func:`agents.control.plant.task_flags`):
    every registered drop task whose env controls something, keyed by the task in the id
    (``RotorDrop-Full-v1``: ``full``), and the ids whose env re-levitates. A task whose AMBs
    stay on (Recover) is no drop: its own suites score it (:mod:`agents.benchmarking.recover`)."""
    from rotordrop_env import ENV_IDS
    from rotordrop_env.tasks import TASKS as DECLARED
    flags = {env_id: task_flags(env_id) for env_id in ENV_IDS if not DECLARED[env_id].amb_on}
    return ({env_id.split("-")[1].lower(): env_id for env_id, f in flags.items() if any(f)},
            tuple(env_id for env_id, (_, relevitate) in flags.items() if relevitate))


#: task -> env id (``damping``, ``relevitate``, ``full``) and the re-levitation env ids
TASKS, RELEVITATION_ENVS = _env_tasks()


def round_up(t: float, grid: float) -> float:
    """``t`` [s] rounded up to the ``grid`` [s] (so that every row sees the power return at
    the same control instant), to 12 decimals: a suite's power-return rounding."""
    return round(math.ceil(t / grid - 1e-9) * grid, 12)


def task_of(env_id: str) -> str:
    """The benchmark task (key of ``TASKS``) of an environment id."""
    for task, task_env in TASKS.items():
        if task_env == env_id:
            return task
    raise ValueError(f"{env_id!r} is not the environment of a benchmark task "
                     f"({', '.join(TASKS.values())})")


@dataclass(frozen=True)
class Scenario:
    name: str
    friction: float
    overrides: dict = field(default_factory=dict)
    group: str = "in-distribution"                      # in the re-levitation tasks (_group)
    env_kwargs: dict = field(default_factory=dict)      # relevitation envs only
    tasks: tuple[str, ...] = tuple(TASKS)
    sensor_noise: float = 0.0       # std of the displacement sensors' noise [m]
    latency_s: float = 0.0          # observation latency [s], in whole control steps (rounded up)
    seed: int = 0                   # episode seed (the noise's draws)

    def scene_overrides(self, phase: float) -> dict:
        return {"contact.friction": self.friction, "unbalance.angle_deg": phase, **self.overrides}


def passive_threshold(phases=PHASES, grid=THRESHOLD_GRID, progress=None, session=None) -> dict:
    """Whirl fraction of the passive drop on the friction grid and the threshold μ* (module doc);
    one task per friction on ``session`` (default: one after the other here)."""
    from physics.runs.backend import Session
    session = session if session is not None else Session()
    fractions = [0.0] * len(grid)
    bar = progress if session.name == "local" else None
    for i, whirls in session.imap(passive_whirls, [(mu, phases, bar) for mu in grid]):
        fractions[i] = float(np.mean(whirls))
        if progress is not None and bar is None:
            progress.update(len(phases))
    threshold = None
    for i in range(len(grid)):
        if all(f >= 0.5 for f in fractions[i:]):
            threshold = grid[i]
            break
    return dict(grid=list(grid), phases=list(phases), whirl_fraction=fractions, threshold=threshold,
                rule="lowest grid friction from which the passive drop whirls in >= half of the "
                     "phases at every grid point")


def passive_whirls(mu: float, phases, progress=None) -> list[bool]:
    """Whether the passive drop at friction ``mu`` whirls, per unbalance phase."""
    whirls = []
    for ph in phases:
        ep = run_episodes("RotorDrop-Passive-v1", Passive, [0], dict(
            EVAL_KWARGS, overrides={"contact.friction": mu, "unbalance.angle_deg": ph},
            **monitor_kwargs({})))[0]
        whirls.append(bool(ep.kpis["backward_whirl"]))
        if progress is not None:
            progress.update(1)
    return whirls


def scenario_suite(threshold: float | None, quick: bool = False,
                   power_return: float | None = None) -> list[Scenario]:
    """The suite (module doc); ``power_return`` [s] replaces the environments' default power
    return (50 ms) in every re-levitation scenario that does not set its own."""
    ref = threshold if threshold is not None else THRESHOLD_GRID[-1]
    whirl = [round(ref + m, 2) for m in WHIRL_MARGINS]
    mu = round(ref + WHIRL_MARGINS[0], 2)
    relev = ("relevitate", "full")
    suite = [Scenario(f"mu={m:g} (mu*+{d:g})", m) for m, d in zip(whirl, WHIRL_MARGINS)]
    suite += [Scenario("mu=0.1 (passive rests)", 0.10), Scenario("mu=0.25 (paper base case)", 0.25),
              Scenario("mu=0.6", 0.6),
              Scenario("K_s=2e6 N/m", mu, {"support.stiffness": 2e6}),
              Scenario("K_s=1e9 N/m", mu, {"support.stiffness": 1e9}),
              Scenario("6000 rpm", mu, {"rotor.speed_rpm": 6000.0}),
              Scenario("15000 rpm", mu, {"rotor.speed_rpm": 15000.0}),
              Scenario("unbalance 5 g", mu, {"unbalance.mass": 5e-3}),
              Scenario("paper slip law", mu, {"effects.friction": "paper"}),
              Scenario("power back at 0.15 s", mu, env_kwargs={"power_return_time": 0.15},
                       tasks=relev)]
    if power_return is not None:
        suite = [Scenario(s.name, s.friction, s.overrides, s.group,
                          {"power_return_time": power_return, **s.env_kwargs}, s.tasks) for s in suite]
    suite = [Scenario(s.name, s.friction, s.overrides, _group(s), s.env_kwargs, s.tasks) for s in suite]
    if quick:
        keep = (0, 2, 3, 5, 9)
        return [suite[i] for i in keep]
    return suite


def _group(sc: Scenario, task: str | None = None) -> str:
    """``in-distribution`` when every value lies inside the environments' default
    randomisation ranges (what the shipped policies were trained on), else out of it. The
    scenario's env kwargs (power return) do not count in the ``damping`` task, which does not
    use them (:func:`episode_kwargs`)."""
    from rotordrop_env.scenario import DEFAULT_RANGES
    values = {"contact.friction": sc.friction, **sc.overrides,
              **(sc.env_kwargs if task != "damping" else {})}
    for key, v in values.items():
        if key in DEFAULT_RANGES:
            _, lo, hi = DEFAULT_RANGES[key]
            if not lo <= float(v) <= hi:
                return "out-of-distribution"
        elif key != "unbalance.angle_deg":
            return "out-of-distribution"
    return "in-distribution"


@dataclass
class Entry:
    """A controller in the benchmark: display name, task, how to build it, env kwargs, and
    its seat (:data:`agents.control.seats.SEATS`; default: the one its env kwargs put it in)."""
    name: str
    task: str
    make: object
    env_kwargs: dict
    seat: str | None = None
    strict: bool = True             # False: a row no seat admits runs unseated (model selection)

    def __post_init__(self):
        from ..control.seats import seat_for_kwargs
        try:
            want = seat_for_kwargs(self.env_kwargs)
        except ValueError:
            if self.strict or self.seat is not None:
                raise
            return
        if self.seat is None:
            self.seat = want.name
        elif check_seat(self.seat) is not want:
            raise ValueError(f"{self.name}: its env kwargs (control_dt, command) run it in the "
                             f"{want.name} seat, not in the {self.seat} seat it declares")


def _entries(policies: list[LearnedPolicy], controllers=(), tasks=None, suite=None) -> list[Entry]:
    """Every controller class (the baselines, then ``controllers``) in each task (of ``tasks``,
    default all) that has its channels, with the constants tuned for ``suite``
    (:mod:`agents.benchmarking.tuned`) where it has them, and every policy in the task it was
    trained for."""
    from ..control.plant import plant_of
    out = []
    for task, env_id in TASKS.items():
        if tasks is not None and task not in tasks:
            continue
        plants = {}                                  # per re-levitation command
        for cls in [*BASELINES.values(), *controllers]:
            entry = controller_entry(cls, env_id, suite)
            command = entry.env_kwargs.get("command")
            if command not in plants:
                plants[command] = plant_of(env_id, **entry.env_kwargs)
            if cls.supports(plants[command]):
                out.append(entry)
        out += [Entry(p.name, task, p.bound, dict(p.env_kwargs)) for p in policies if p.env_id == env_id]
    return out


def robust_entries(policies: list[str] | None, env_id: str | None = None,
                   names: list[str] | None = None, suite=None,
                   quick: bool = False, only: list[str] | None = None) -> tuple[list[Entry], dict]:
    """The Full-task entries of a drawn suite: every baseline with channels there (with its
    constants tuned on ``suite``, if it has a record; none without a suite), the shipped Full policies
    (with ``quick`` and ``policies`` given: only those asked for), the ``--policy`` extras (see
    :func:`extras` for ``env_id`` and ``names``); and the learned ones by name. ``only``
    (``--only NAME``): of the baselines and shipped policies just those named (the ``--policy``
    extras and ``passive``, the score's reference, always run); a name that is neither is a
    ValueError naming the rows."""
    extra, custom = extras(policies or [], env_id, names)
    loaded = [p for p in [load_shipped(n) for n in shipped_names(policies, quick)] + extra
              if p.env_id == TASKS["full"]]
    entries = check_unique_names([e for e in _entries(loaded, custom, ("full",), suite)
                                  if e.task == "full"])
    if only:
        kept = {"passive", *only, *(p.name for p in extra), *(c.name for c in custom)}
        unknown = sorted(set(only) - {e.name for e in entries})
        if unknown:
            raise ValueError(f"--only {', '.join(unknown)}: not a row of the suite (rows: "
                             f"{', '.join(e.name for e in entries)})")
        loaded = [p for p in loaded if p.name in kept]
        entries = [e for e in entries if e.name in kept]
    for e in [e for e in entries if e.name in {c.name for c in custom}]:
        check_actor(TASKS[e.task], e.make, e.env_kwargs)
    return entries, {p.name: p for p in loaded}


def controller_entry(cls, env_id: str, suite=None) -> Entry:
    """The benchmark entry of a controller class in the task of ``env_id``, in its seat, with
    the constants tuned for ``suite`` where a record has them (:func:`agents.benchmarking.tuned.tuned_gains`)."""
    from ..control.seats import seat_of
    from .tuned import tuned_gains
    gains = tuned_gains(suite, cls.name, env_id) if suite is not None else None
    make = ((lambda plant: make_controller(cls, plant)) if not gains else
            (lambda plant: cls(plant, **gains)))
    return Entry(cls.name, task_of(env_id), make, controller_env_kwargs(cls, env_id),
                 seat_of(cls).name)


def shipped_names(policies: list[str] | None = None, quick: bool = False) -> list[str]:
    """The shipped policies a benchmark runs: all of them, or with ``quick`` and ``policies``
    given, only the shipped ones among ``policies`` (``--quick --policy NAME``)."""
    from ..learning.policies import shipped_names as every
    if quick and policies:
        return [n for n in every() if n in policies]
    return every()


def extras(specs: list[str], env_id: str | None = None,
           names: list[str] | None = None) -> tuple[list[LearnedPolicy], list]:
    """The ``--policy`` extras: learned policies given by path, named ``name@run``
    (:func:`policy_label`, as in evaluate and ride-through) or by ``names`` (``--name``, one per
    path, in order), and controller classes; the baselines and shipped policies are in already.
    ``env_id`` (``--env``): the environment of a path that records none (a plain SB3 zip)."""
    policies, classes = [], []
    for spec in dict.fromkeys(specs):
        if spec in shipped_names() or spec in BASELINES:
            continue
        cls = controller_class(spec)
        if cls is not None:
            classes.append(cls)
            continue
        policy = LearnedPolicy.load(spec, env_id=env_id)
        policy.name = policy_label(spec, policy)
        policies.append(policy)
    if names:
        if len(names) != len(policies):
            raise ValueError(f"--name: {len(names)} name(s) for {len(policies)} --policy model(s) "
                             f"given by path; give one --name per model, in the same order")
        for policy, name in zip(policies, names):
            if not name.strip() or any(c.isspace() or c in "|`" for c in name):
                raise ValueError(f"--name {name!r}: a leaderboard name without spaces, '|' or '`'")
            policy.name = name
    return policies, classes


def quick_tasks(policies, quick: bool, loaded, custom, env_id=None) -> tuple[str, ...] | None:
    """The tasks a ``--quick`` benchmark with ``--policy`` runs: those of the given policies and
    controllers (with their references, the baselines of the task); None (every task) else."""
    if not (quick and policies):
        return None
    from ..control.plant import plant_of
    tasks = {task_of(p.env_id) for p in loaded}
    for cls in custom:
        tasks |= {t for t, e in TASKS.items()
                  if cls.supports(plant_of(e, **controller_env_kwargs(cls, e)))}
    tasks |= {t for t, e in TASKS.items() for n in policies
              if n in BASELINES and BASELINES[n].supports(plant_of(e, **controller_env_kwargs(BASELINES[n], e)))}
    return tuple(t for t in TASKS if t in tasks)


def check_power_return(seconds: float, flag: str, episode_time: float = EPISODE_TIME) -> None:
    """The power must return inside the episode: ``seconds`` in [0, episode_time)."""
    if not (np.isfinite(seconds) and 0.0 <= seconds < episode_time):
        raise ValueError(f"{flag} = {1e3 * seconds:g} ms must be in [0, {1e3 * episode_time:g}) ms: "
                         f"the power has to return within the {1e3 * episode_time:g} ms episode")


def check_unique_names(entries: list[Entry]) -> list[Entry]:
    """``entries``, after checking that no two of a task share a name (the reports key the
    controllers by name)."""
    keys = [(e.task, e.name) for e in entries]
    twice = sorted({name for task, name in keys if keys.count((task, name)) > 1})
    if twice:
        raise ValueError(f"--policy: two controllers are named {', '.join(twice)}; give each "
                         f"its own name")
    return entries


#: a policy's training env kwargs that are its training distribution and sensing, not its
#: interface: a benchmark replaces them with its suite's
TRAINING_KEYS = ("randomize", "randomization", "overrides", "terminate_on_failure", "episode_time",
                 "samples_per_step", "sensor_noise", "obs_latency_steps", "sensor_delay", "events")


def interface_kwargs(env_kwargs: dict) -> dict:
    """A policy's env kwargs without :data:`TRAINING_KEYS`: what it acts through (its command,
    control step...), kept when a benchmark runs it on its own suite."""
    return {k: v for k, v in env_kwargs.items() if k not in TRAINING_KEYS}


def episode_kwargs(entry: Entry, scenario: Scenario, phase: float) -> dict:
    """The env kwargs of one episode: the entry's (its command, control step...) without its
    training distribution and sensing, the scenario's scene values, power return and sensing
    (the latency as whole control steps of the entry's, rounded up: the newest measurement
    that has arrived)."""
    kw = interface_kwargs(entry.env_kwargs)
    kw.update(EVAL_KWARGS)
    kw.update(monitor_kwargs(kw))
    kw["overrides"] = {**(entry.env_kwargs.get("overrides") or {}), **scenario.scene_overrides(phase)}
    if entry.task != "damping":
        kw.update(scenario.env_kwargs)
    if scenario.sensor_noise:
        kw["sensor_noise"] = scenario.sensor_noise
    if scenario.latency_s and (entry.seat is None or check_seat(entry.seat).transport_latency):
        kw["obs_latency_steps"] = latency_steps(scenario.latency_s, kw.get("control_dt", 1e-3))
    return kw


def latency_steps(latency_s: float, control_dt: float) -> int:
    """A latency [s] in whole control steps, rounded up (at least one step for any latency)."""
    return int(math.ceil(latency_s / control_dt - 1e-9))


def benchmark(out: str | Path, quick: bool = False, policies: list[str] | None = None,
              max_scenarios: int | None = None, episodes: int | None = None,
              progress: bool = True, plots: bool = True, power_return: float | None = None,
              backend=None, env_id: str | None = None, names: list[str] | None = None,
              score: str = DEFAULT_SCORE) -> dict:
    """Run the suite and write benchmark.json, leaderboard.md and the plots into ``out``;
    ``power_return`` [s]: see :func:`scenario_suite`; ``score``: :data:`agents.benchmarking.score.SCORES`.
    On ``backend`` ray every friction of the threshold sweep and every controller is one Ray
    task (learned policies travel as their paths and are loaded again on the node). The robust
    suite: :mod:`agents.benchmarking.robust`."""
    from physics.runs.backend import Backend
    backend = backend if backend is not None else Backend()
    check_score(score)
    if power_return is not None:
        check_power_return(power_return, "--power-return-ms")
    from tqdm.auto import tqdm
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    phases = QUICK_PHASES if quick else PHASES
    if episodes is not None:
        phases = PHASES[:max(1, min(episodes, len(PHASES)))]
    extra, custom = extras(policies or [], env_id, names)
    loaded = [load_shipped(n) for n in shipped_names(policies, quick)] + extra
    entries = check_unique_names(_entries(loaded, custom, quick_tasks(policies, quick, loaded,
                                                                      custom, env_id)))
    users = {c.name for c in custom}
    for e in [e for e in entries if e.name in users]:       # fail fast, before the sweep
        check_actor(TASKS[e.task], e.make, e.env_kwargs)

    sweep_phases = PHASES if episodes is None else phases     # --quick: the full threshold sweep
    with backend.session() as session:
        bar = tqdm(total=len(THRESHOLD_GRID) * len(sweep_phases), desc="passive threshold",
                   unit="ep", disable=not progress)
        sweep = passive_threshold(sweep_phases, THRESHOLD_GRID, bar, session)
        bar.close()
        scenarios = scenario_suite(sweep["threshold"], quick, power_return)
        if max_scenarios is not None:
            scenarios = scenarios[:max(1, max_scenarios)]
        bar = tqdm(total=sum(e.task in s.tasks for e in entries for s in scenarios) * len(phases),
                   desc="benchmark", unit="ep", disable=not progress)
        rows = entry_rows(session, entries, scenarios, phases, bar)
        bar.close()
        where = session.describe()
    board = leaderboard(rows, scenarios, sweep["threshold"], score=score)
    learned = {p.name: p for p in loaded}
    for e in board:
        e["kind"] = "learned" if e["controller"] in learned else "designed"
    from .score import seed_groups
    from rotordrop_env.env import DEFAULT_POWER_RETURN
    report = dict(quick=quick, partial=max_scenarios is not None or episodes is not None,
                  score=score, bootstrap=bootstrap_record(),
                  seed_groups=seed_groups(board, learned),
                  episode_time_s=EPISODE_TIME, phases_deg=list(phases),
                  power_return_s=DEFAULT_POWER_RETURN if power_return is None else power_return,
                  threshold_sweep=sweep, passive_threshold=sweep["threshold"],
                  scenarios=[dict(name=s.name, friction=s.friction, overrides=s.overrides,
                                  group=s.group, env_kwargs=s.env_kwargs, tasks=list(s.tasks))
                             for s in scenarios],
                  rows=rows, leaderboard=board, backend=where,
                  wall_time_s=time.perf_counter() - t0)
    write_json(out / "benchmark.json", report)
    (out / "leaderboard.md").write_text(leaderboard_markdown(report))
    if plots:
        from .plots import plot_benchmark
        report["figures"] = [p.name for p in plot_benchmark(report, out)]
    print(leaderboard_markdown(report))
    print(f"wrote {out / 'benchmark.json'}, {out / 'leaderboard.md'}"
          + "".join(f", {f}" for f in report.get("figures", []))
          + f" in {report['wall_time_s']:.0f} s")
    return report


def entry_rows(session, entries: list[Entry], scenarios: list[Scenario], phases, bar) -> list[dict]:
    """Every entry's :func:`suite_rows`, one task per entry on ``session``, in entry order."""
    local = session.name == "local"
    done: dict[int, list[dict]] = {}
    for i, rows in session.imap(suite_rows, [(e, scenarios, phases, bar if local else None)
                                             for e in entries]):
        done[i] = rows
        if not local:
            bar.update(len(rows) * len(phases))
    return [r for i in range(len(entries)) for r in done[i]]


def suite_rows(entry: Entry, scenarios: list[Scenario], phases, progress=None) -> list[dict]:
    """One row per scenario of the entry's task: its KPIs averaged over the unbalance phases."""
    rows = []
    for sc in [s for s in scenarios if entry.task in s.tasks]:
        eps = []
        for ph in phases:
            eps += run_episodes(TASKS[entry.task], entry.make, [sc.seed], episode_kwargs(entry, sc, ph))
            if progress is not None:
                progress.update(1)
        rows.append(_row(entry, sc, eps))
    return rows


#: model selection during training (``rotordrop train``, config key ``validation: true``):
#: nominal scene, frictions and unbalance phases that the benchmark suite does not use
VALIDATION_FRICTIONS = (0.2, 0.36, 0.41, 0.46, 0.51)
VALIDATION_PHASES = (45.0, 225.0)


class Validator:
    """The benchmark score of one policy on the validation suite (``VALIDATION_*``) of a task,
    against the passive drop on the same suite (computed once); or on given ``scenarios``
    and ``phases`` (the robust validation set, :func:`agents.benchmarking.robust.robust_validator`)."""

    def __init__(self, env_id: str, scenarios: list[Scenario] | None = None,
                 phases=VALIDATION_PHASES):
        self.task = task_of(env_id)
        self.scenarios = scenarios or [Scenario(f"mu={m:g}", m) for m in VALIDATION_FRICTIONS]
        self.phases = tuple(phases)
        self.passive = suite_rows(Entry("passive", self.task, Passive, {}), self.scenarios,
                                  self.phases)

    @property
    def episodes(self) -> int:
        """Validation episodes per score."""
        return len(self.scenarios) * len(self.phases)

    def score(self, make_actor, env_kwargs: dict) -> tuple[float, list[dict]]:
        rows = suite_rows(Entry("candidate", self.task, make_actor, env_kwargs, strict=False),
                          self.scenarios, self.phases)
        board = leaderboard(self.passive + rows, self.scenarios, None)
        return next(e["score"] for e in board if e["controller"] == "candidate"), rows


def _row(entry: Entry, sc: Scenario, eps) -> dict:
    s = summarize(eps)
    k = [e.kpis for e in eps]
    return dict(controller=entry.name, seat=entry.seat, task=entry.task, env_id=TASKS[entry.task],
                scenario=sc.name,
                group=_group(sc, entry.task), friction=sc.friction,
                backward_whirl=s["backward_whirl_rate"],
                whirl_revolutions=float(np.mean([d["whirl_revolutions"] for d in k])),
                peak_whirl_revolutions=float(np.mean([d["peak_whirl_revolutions"] for d in k])),
                peak_contact_force_N=s["peak_contact_force_N"],
                max_displacement_um=s["max_displacement_um"],
                max_contact_pressure_MPa=s["max_contact_pressure_MPa"],
                relevitated=s["relevitation_success_rate"],
                relevitation_time_s=s["relevitation_time_s"],
                control_effort=s["control_effort"],
                stator_contact=float(np.mean([bool(d.get("stator_contact")) for d in k])),
                episodes=len(eps),
                # per-episode KPIs (in phase order): the drops of the leaderboard's bootstrap
                drops={key: [_plain(d.get(key)) for d in k] for key in DROP_KEYS})


#: the per-episode KPIs a row keeps (``drops``) for :func:`agents.benchmarking.score.drop_costs`
DROP_KEYS = ("backward_whirl", "peak_whirl_revolutions", "peak_contact_force_N",
             "max_displacement_um", "relevitated", "relevitation_time_s")


def _plain(v):
    if v is None:
        return None
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    return float(v)


def bootstrap_record() -> dict:
    """How the leaderboard's uncertainties were computed (recorded in benchmark.json)."""
    return dict(method="paired bootstrap over scenarios (all unbalance phases of a drawn "
                       "scenario together)",
                resamples=BOOTSTRAP_RESAMPLES, seed=BOOTSTRAP_SEED, interval="95 % percentile",
                reference="the best designed row (baseline controller, not passive) of the task "
                          "by point score")


def leaderboard(rows: list[dict], scenarios: list[Scenario], threshold,
                any_friction: bool = False, score: str = DEFAULT_SCORE) -> list[dict]:
    """Per task and controller: overall score (``score``: :data:`agents.benchmarking.score.SCORES`) with its
    bootstrap uncertainty (:func:`add_uncertainty`), whirl and force criteria (see agents.benchmarking.score).
    The whirl rate "where passive whirls" counts the scenarios where the passive drop whirls
    at μ* + 0.05 or above (``threshold`` = μ*), or at any friction with ``any_friction``
    (the robust suite's drawn scenarios)."""
    board = []
    for task in dict.fromkeys(r["task"] for r in rows):
        passive = {r["scenario"]: r for r in rows if r["task"] == task and r["controller"] == "passive"}
        relev = task != "damping"
        p_costs = {n: row_cost(r, r, EPISODE_TIME, relev, score) for n, r in passive.items()}
        for name in dict.fromkeys(r["controller"] for r in rows if r["task"] == task):
            mine = [r for r in rows if r["task"] == task and r["controller"] == name]
            costs = {r["scenario"]: row_cost(r, passive[r["scenario"]], EPISODE_TIME, relev, score)
                     for r in mine}
            for r in mine:
                r["cost"] = costs[r["scenario"]]
            whirl_sc = [r for r in mine if passive[r["scenario"]]["backward_whirl"] >= 0.5
                        and (any_friction or threshold is not None
                             and r["friction"] >= threshold + 0.05 - 1e-9)]
            entry = dict(task=task, controller=name, seat=mine[0].get("seat"),
                         score=overall_score(list(costs.values()), [p_costs[n] for n in costs]),
                         in_distribution_score=_group_score(mine, costs, p_costs, "in-distribution"),
                         out_of_distribution_score=_group_score(mine, costs, p_costs,
                                                                "out-of-distribution"),
                         whirl_rate=float(np.mean([r["backward_whirl"] for r in mine])),
                         whirl_rate_where_passive_whirls=(float(np.mean([r["backward_whirl"]
                                                                         for r in whirl_sc]))
                                                          if whirl_sc else None),
                         force_ratio=float(np.mean([r["peak_contact_force_N"] /
                                                    passive[r["scenario"]]["peak_contact_force_N"]
                                                    for r in mine])),
                         max_force_ratio=float(max(r["peak_contact_force_N"] /
                                                   passive[r["scenario"]]["peak_contact_force_N"]
                                                   for r in mine)),
                         displacement_ratio=float(np.mean([r["max_displacement_um"] /
                                                           passive[r["scenario"]]["max_displacement_um"]
                                                           for r in mine])),
                         relevitation_rate=(float(np.mean([r["relevitated"] or 0.0 for r in mine]))
                                            if relev else None),
                         stator_contact_rate=float(np.mean([r["stator_contact"] for r in mine])))
            board.append(entry)
        add_uncertainty([e for e in board if e["task"] == task],
                        [r for r in rows if r["task"] == task], passive, relev, score)
    board.sort(key=lambda e: (list(TASKS).index(e["task"]), -e["score"]))
    return board


def add_uncertainty(entries: list[dict], rows: list[dict], passive: dict, relev: bool,
                    score: str = DEFAULT_SCORE) -> None:
    """Add to the leaderboard entries of one task the paired bootstrap over its drops
    (:func:`agents.benchmarking.score.bootstrap_scores`): ``score_se``, ``reference`` (the best designed
    row: a baseline of agents.control.controllers other than passive, by point score),
    ``diff_vs_reference``, ``diff_se`` and ``diff_ci95``. Rows without per-episode KPIs, or
    that did not run the passive row's drops, get none."""
    names = [e["controller"] for e in entries]
    by = {(r["controller"], r["scenario"]): r for r in rows}
    order = list(passive)
    try:
        p_cost = np.concatenate([drop_costs(passive[s]["drops"], passive[s], EPISODE_TIME, relev,
                                            score) for s in order])
        costs = np.array([np.concatenate([drop_costs(by[(n, s)]["drops"], passive[s],
                                                     EPISODE_TIME, relev, score) for s in order])
                          for n in names])
    except (KeyError, ValueError):
        return
    if costs.ndim != 2 or costs.shape[1] != p_cost.size:
        return
    designed = [i for i, n in enumerate(names) if n in BASELINES and n != "passive"]
    pool = designed if designed else ([names.index("passive")] if "passive" in names else [])
    if not pool:
        return
    clusters = np.concatenate([np.full(len(passive[s]["drops"]["backward_whirl"]), i)
                               for i, s in enumerate(order)])       # the scenario of each drop
    attach_bootstrap(entries, costs, p_cost, max(pool, key=lambda i: entries[i]["score"]),
                     clusters)


def _group_score(mine, costs, p_costs, group):
    names = [r["scenario"] for r in mine if r["group"] == group]
    if not names:
        return None
    return overall_score([costs[n] for n in names], [p_costs[n] for n in names])



def leaderboard_markdown(report: dict) -> str:
    thr = report["passive_threshold"]
    lines = [f"# rotordrop benchmark{' (quick)' if report['quick'] else ''}", "",
             f"Passive whirl threshold mu* = {fmt_or_dash(thr, 'g')} (paper scene, {len(report['phases_deg'])} "
             f"unbalance phases, {report['episode_time_s']:g} s after the fault; re-levitation "
             f"tasks: power back {1e3 * report['power_return_s']:g} ms after the fault unless "
             f"the scenario says otherwise). "
             f"{score_sentence(report)}", ""]
    return "\n".join(lines + leaderboard_tables(report))


def score_sentence(report: dict) -> str:
    """What the leaderboard's score and uncertainty columns are (one markdown paragraph)."""
    b = report.get("bootstrap") or {}
    text = (f"Score ({report.get('score', 'legacy')}): 100 (1 - sum J / sum J_passive), see "
            "docs/agents.md.")
    if b:
        text += (f" SE: {b.get('method', 'paired bootstrap over the drops')} ({b['resamples']} resamples, seed "
                 f"{b['seed']}); Δ: score minus the best designed row's of the task, with its SE "
                 "and 95 % interval.")
    return text


def uncertainty_cells(e: dict) -> list[str]:
    """The SE of the score and the difference to the reference row (± SE, [95 % interval])."""
    if e.get("score_se") is None:
        return ["-", "-"]
    lo, hi = e["diff_ci95"]
    return [f"{e['score_se']:.2f}", f"{e['diff_vs_reference']:+.2f} ± {e['diff_se']:.2f} "
                                    f"[{lo:+.2f}, {hi:+.2f}]"]


def leaderboard_tables(report: dict, scenario_rows: bool = True) -> list[str]:
    """The markdown leaderboard per task (and, with ``scenario_rows``, every row's KPIs)."""
    lines = []
    for task in dict.fromkeys(e["task"] for e in report["leaderboard"]):
        ref = next((e.get("reference") for e in report["leaderboard"]
                    if e["task"] == task and e.get("reference")), None)
        lines += [f"## {task}", "",
                  f"| rank | controller | seat | score | SE | Δ vs {ref or 'best designed'} ± SE [95 %] | "
                  "in-dist. | out-of-dist. | whirl rate | whirl where "
                  "passive whirls | peak F / passive (mean, max) | disp. / passive | relevitated | "
                  "stator contact |",
                  "|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
        for i, e in enumerate([e for e in report["leaderboard"] if e["task"] == task], 1):
            lines.append(f"| {i} | {e['controller']} | {e.get('seat') or '-'} | {e['score']:.2f} | "
                         f"{' | '.join(uncertainty_cells(e))} | "
                         f"{fmt_or_dash(e['in_distribution_score'], '.2f')} | "
                         f"{fmt_or_dash(e['out_of_distribution_score'], '.2f')} | {e['whirl_rate']:.2f} | "
                         f"{fmt_or_dash(e['whirl_rate_where_passive_whirls'], '.2f')} | "
                         f"{e['force_ratio']:.2f}, {e['max_force_ratio']:.2f} | "
                         f"{e['displacement_ratio']:.2f} | {fmt_or_dash(e['relevitation_rate'], '.2f')} | "
                         f"{e['stator_contact_rate']:.2f} |")
        groups = [g for g in report.get("seed_groups") or []
                  if any(e["task"] == task and e["controller"] in g["members"]
                         for e in report["leaderboard"])]
        if groups and report.get("suite") is None:        # the robust report lists its own
            lines += ["", "| learned configuration (seeds) | scores | mean ± std |",
                      "|---|---|---:|"]
            lines += [f"| {', '.join(g['members'])} | {', '.join(f'{x:.2f}' for x in g['scores'])} "
                      f"| {g['mean']:.2f} ± {g['std']:.2f} |" for g in groups]
        if not scenario_rows:
            lines.append("")
            continue
        lines += ["", "| controller | scenario | mu | whirl | peak revs | peak F [N] | max disp [µm] | "
                      "stator | relevitated | t_relev [ms] | J |",
                  "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
        for r in [r for r in report["rows"] if r["task"] == task]:
            t = r["relevitation_time_s"]
            lines.append(f"| {r['controller']} | {r['scenario']} | {r['friction']:g} | "
                         f"{r['backward_whirl']:.2f} | {r['peak_whirl_revolutions']:.1f} | "
                         f"{r['peak_contact_force_N']:.0f} | {r['max_displacement_um']:.0f} | "
                         f"{r['stator_contact']:.2f} | {fmt_or_dash(r['relevitated'], '.2f')} | {fmt_or_dash(t * 1e3 if t is not None else None, '.0f')} | "
                         f"{r.get('cost', float('nan')):.2f} |")
        lines.append("")
    return lines

