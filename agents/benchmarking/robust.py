"""The robust suite (``rotordrop benchmark --suite robust``): the Full task under imperfect
sensing, actuator spread and plant variation that the controller does not observe.

Every scenario is one drop of ``RotorDrop-Full-v1`` drawn from :data:`ROBUST_RANGES` (friction,
unbalance mass and phase, housing stiffness ± 30 %, spin speed, power return, coil current limit
and coil lag; the support's initial damping from the environments' default range), under the one
sensing model of physics/sensor.py that every controller, the built-in PID included, sees:
displacement-sensor noise :data:`SENSOR_NOISE` (one sample per axis at every sensor sample,
:data:`SENSOR_SAMPLE_RATE`, held in between, whatever the controller's step) and a sensor delay
drawn per scenario from :data:`SENSOR_DELAY_S` (the scene key ``sensor.delay``). On top of that
a row in the ``supervisor`` seat (:mod:`agents.control.seats`) gets a transport latency of 0 or
1 ms (:data:`LATENCY_MS`, drawn per scenario: one transfer to a supervisory computer, or none);
a row in the ``controller`` seat (inside the AMB controller, 0.2 ms step) gets none. The latency
is physical time: a controller with control step Δt sees the newest measurement that has
arrived, ⌈latency / Δt⌉ steps old (0-1 steps at 1 ms and at 5 ms), see
:func:`agents.benchmarking.benchmark.latency_steps`. The suites built on these draws
(``robust``, ``robust-legacy``) are registered in :mod:`agents.benchmarking.suites`.

Sensing ranges from AMB practice: eddy-current and inductive position sensors resolve 0.1-1 µm
RMS over the controller's bandwidth (the suite takes the upper end); a digital AMB controller
sampling at 10-20 kHz has 1-2 samples of delay from sampling, conversion and computation, with
the sensor's demodulation filter 0.05-0.2 ms in all. The power return is rounded up to the 5 ms grid so that
every row sees the power at the same instant.

Seeds: the suite's test scenarios are drawn with seeds ``SUITE_SEED`` + i (i < 200; ``--quick``:
the first ``QUICK_SCENARIOS``), the robust validation set (model selection in training, tuning
of ``whirl-brake-robust``) with ``VALIDATION_SEED`` + i; training environments draw from streams
seeded 0-99 and 10 000-10 099 (evaluation). No scenario is shared. ``--suite robust-legacy``
draws the earlier test set (``LEGACY_SUITE_SEED`` + i), on which the shipped policies and
designed variants were compared while they were chosen: its numbers are reproducible, but
they are not a held-out test.
"""
from __future__ import annotations


import numpy as np

from physics.scene import Sensor

from .benchmark import TASKS, Scenario, Validator, round_up

ENV_ID = TASKS["full"]
#: the robust distribution: key -> (low, high), uniform (the training config copies it)
ROBUST_RANGES: dict[str, tuple[float, float]] = {
    "contact.friction": (0.3, 0.6),
    "unbalance.mass": (0.5e-3, 2e-3),
    "unbalance.angle_deg": (0.0, 360.0),
    "support.stiffness": (3.5e7, 6.5e7),            # the paper's 5e7 N/m +- 30 %
    "rotor.speed_rpm": (8000.0, 12000.0),
    "power_return_time": (0.03, 0.07),
    "amb.current_limit": (2.4, 3.0),                # the paper's 3 A (= bias current) - 20 %
    "amb.coil_time_constant": (2e-4, 1e-3),         # coil lag L/R (the paper: none)
}
SENSOR_NOISE = 1e-6                 # std of the displacement noise [m] (sensor.noise)
SENSOR_DELAY_S = (5e-5, 2e-4)       # sensor delay [s] (sensor.delay), uniform per scenario
SENSOR_SAMPLE_RATE = Sensor().sample_rate   # the sensors' sample rate [Hz] (sensor.sample_rate:
                                            # the scene's default, which the suite's drops keep)
LATENCY_MS = (0, 1)                 # the agent's own observation latency [ms], an integer
                                    # drawn per scenario
POWER_GRID = 0.005                  # the power return is rounded up to this grid [s]
SUITE_SEED = 50_000                 # the test set (fresh: no choice was made on it)
LEGACY_SUITE_SEED = 30_000          # the earlier test set (--suite robust-legacy)
SUITE_SCENARIOS = 200
QUICK_SCENARIOS = 40
VALIDATION_SEED = 40_000
VALIDATION_SCENARIOS = 20


def is_robust(env_kwargs: dict) -> bool:
    """Whether environments made with ``env_kwargs`` sense imperfectly (noise or latency)."""
    lat = env_kwargs.get("obs_latency_steps") or 0
    return (bool(env_kwargs.get("sensor_noise")) or bool(env_kwargs.get("sensor_delay"))
            or "sensor.delay" in (env_kwargs.get("randomization") or {})
            or bool(max(np.atleast_1d(lat))))


def draw_scenario(seed: int, name: str | None = None) -> Scenario:
    """One scenario of the robust distribution, drawn from ``seed`` (module doc)."""
    from rotordrop_env.scenario import draw
    values, rng = draw(ROBUST_RANGES, seed)
    latency_ms = int(rng.integers(LATENCY_MS[0], LATENCY_MS[1] + 1))
    values["sensor.delay"] = float(rng.uniform(*SENSOR_DELAY_S))   # last: the rest as before
    pr = round_up(values.pop("power_return_time"), POWER_GRID)
    friction = values.pop("contact.friction")
    return Scenario(name or f"#{seed}", float(friction), values, group="in-distribution",
                    env_kwargs={"power_return_time": pr}, tasks=("full",),
                    sensor_noise=SENSOR_NOISE, latency_s=1e-3 * latency_ms, seed=seed)


def robust_scenarios(n: int, seed: int = SUITE_SEED) -> list[Scenario]:
    return [draw_scenario(seed + i, f"#{i}") for i in range(n)]


def robust_validator(env_id: str = ENV_ID) -> Validator:
    """The robust validation set (``VALIDATION_SCENARIOS`` drops from ``VALIDATION_SEED``): the
    ``robust`` suite's (:meth:`agents.benchmarking.suites.DrawnSuite.validator`)."""
    if env_id != ENV_ID:
        raise ValueError(f"the robust validation set is for {ENV_ID}, not {env_id}")
    return Validator(env_id, robust_scenarios(VALIDATION_SCENARIOS, VALIDATION_SEED), (0.0,))


def distribution(suite, n: int) -> dict:
    """The robust distribution as benchmark.json records it (``n`` drops from the suite's seed)."""
    return dict(ranges={k: list(v) for k, v in ROBUST_RANGES.items()}, sensor_noise_m=SENSOR_NOISE,
                latency_ms=list(LATENCY_MS), sensor_delay_s=list(SENSOR_DELAY_S),
                sensor_sample_rate_hz=SENSOR_SAMPLE_RATE, power_grid_s=suite.power_grid, scenario_seeds=[suite.seed, suite.seed + n - 1])


def validator_for(env_id: str, env_kwargs: dict | None = None) -> Validator:
    """The validation suite of a training run: the robust one when its environments have
    sensor noise or observation latency, else the nominal one."""
    if is_robust(env_kwargs or {}):
        return robust_validator(env_id)
    return Validator(env_id)


def training_env_kwargs(control_dt: float = 0.005) -> dict:
    """The env kwargs that train on the robust distribution at control step ``control_dt``
    (the latency's steps as the suite rounds them: the suite's shortest latency, 1 ms, and
    longest, 3 ms, give the range)."""
    from .benchmark import latency_steps
    lo, hi = (latency_steps(1e-3 * m, control_dt) for m in LATENCY_MS)
    ranges = {k: list(v) for k, v in ROBUST_RANGES.items()}
    ranges["sensor.delay"] = list(SENSOR_DELAY_S)
    return dict(randomize=True, randomization=ranges,
                sensor_noise=SENSOR_NOISE, obs_latency_steps=lo if lo == hi else [lo, hi],
                control_dt=control_dt)


def robust_benchmark(out, quick: bool = False, policies: list[str] | None = None,
                     max_scenarios: int | None = None, progress: bool = True, plots: bool = True,
                     backend=None, env_id: str | None = None, names: list[str] | None = None,
                     score: str | None = None, only: list[str] | None = None, *,
                     suite) -> dict:
    """``rotordrop benchmark --suite robust``: every row of the suite's task (baselines, shipped
    and ``--policy`` policies), each in its seat (:mod:`agents.control.seats`), on the drawn
    scenarios of ``suite`` (a :class:`~agents.benchmarking.suites.DrawnSuite`, default the
    robust one; module doc); ``only``: a subset of the rows
    (:func:`agents.benchmarking.benchmark.robust_entries`); writes benchmark.json, leaderboard.md and the plots into ``out``
    in the nominal benchmark's format."""
    import time
    from pathlib import Path

    from physics.runs.backend import Backend
    from tqdm.auto import tqdm

    from .benchmark import EPISODE_TIME, entry_rows, leaderboard, robust_entries
    from .benchmark import bootstrap_record
    from .score import DEFAULT_SCORE, check_score, seed_groups, target, write_json
    score = check_score(score if score is not None else DEFAULT_SCORE)
    backend = backend if backend is not None else Backend()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    n = suite.quick_size if quick else suite.size
    if max_scenarios is not None:
        n = max(1, min(n, max_scenarios))
    scenarios = suite.scenarios(n)
    entries, learned = robust_entries(policies, env_id, names, suite=suite, quick=quick,
                                      only=only)
    with backend.session() as session:
        bar = tqdm(total=len(entries) * n, desc="robust suite", unit="ep", disable=not progress)
        rows = entry_rows(session, entries, scenarios, (0.0,), bar)
        bar.close()
        where = session.describe()
    for r in rows:
        r["group"] = "robust"
    board = leaderboard(rows, scenarios, None, any_friction=True, score=score)
    for e in board:
        e["kind"] = "learned" if e["controller"] in learned else "designed"
    groups = seed_groups(board, learned)
    report = dict(suite=suite.name, quick=quick, partial=max_scenarios is not None,
                  only=sorted(only) if only else None,
                  score=score, bootstrap=bootstrap_record(), episode_time_s=EPISODE_TIME,
                  distribution=suite.describe(suite, n),
                  scenarios=[scenario_record(s) for s in scenarios], rows=rows, leaderboard=board,
                  seed_groups=groups, target=target(board, groups), backend=where,
                  wall_time_s=time.perf_counter() - t0)
    write_json(out / "benchmark.json", report)
    (out / "leaderboard.md").write_text(robust_markdown(report))
    if plots:
        from .plots import plot_robust
        report["figures"] = [p.name for p in plot_robust(report, out)]
    print(robust_markdown(report, scenario_rows=False))
    print(f"wrote {out / 'benchmark.json'}, {out / 'leaderboard.md'}"
          + "".join(f", {f}" for f in report.get("figures", []))
          + f" in {report['wall_time_s']:.0f} s")
    return report


def scenario_record(s: Scenario) -> dict:
    return dict(name=s.name, seed=s.seed, friction=s.friction, overrides=s.overrides,
                env_kwargs=s.env_kwargs, sensor_noise_m=s.sensor_noise,
                latency_ms=round(1e3 * s.latency_s, 9))


def robust_markdown(report: dict, scenario_rows: bool = True) -> str:
    from .benchmark import leaderboard_tables, score_sentence
    from .results import sample_rate_phrase
    from .score import target_sentence
    d = report["distribution"]
    ranges = ", ".join(f"{k} {lo:g}-{hi:g}" for k, (lo, hi) in d["ranges"].items())
    lines = [f"# rotordrop benchmark --suite {report.get('suite', 'robust')}"
             f"{' (quick)' if report['quick'] else ''}", "",
             f"{len(report['scenarios'])} drops of RotorDrop-Full-v1 (scenario seeds "
             f"{d['scenario_seeds'][0]}-{d['scenario_seeds'][1]}) drawn from: {ranges}; "
             f"displacement-sensor noise {1e6 * d['sensor_noise_m']:g} µm and delay "
             f"{'-'.join(f'{1e3 * v:g}' for v in d.get('sensor_delay_s', [0.0]))} ms"
             f"{sample_rate_phrase(d)} (every "
             f"controller, the built-in PID included), transport latency "
             f"{d['latency_ms'][0]}-{d['latency_ms'][1]} ms for supervisor-seat rows (whole "
             f"control steps, rounded up; none in the controller seat); "
             f"power return on the {1e3 * d['power_grid_s']:g} ms grid. "
             f"{score_sentence(report)}", ""]
    lines += leaderboard_tables(report, scenario_rows)
    if report["seed_groups"]:
        lines += ["| learned configuration (seeds) | scores | mean | std | mean - std |",
                  "|---|---|---:|---:|---:|"]
        for g in report["seed_groups"]:
            lines.append(f"| {', '.join(g['members'])} | {', '.join(f'{s:.2f}' for s in g['scores'])} | "
                         f"{g['mean']:.2f} | {g['std']:.2f} | {g['mean_minus_std']:.2f} |")
        lines.append("")
    lines.append(target_sentence(report["target"]))
    return "\n".join(lines) + "\n"
