"""``rotordrop tune``: tune a controller's gains for the benchmark score, on scenarios the
benchmark does not use.

A control engineer's controller class (``package.module:Class`` or ``file.py:Class``, or a
baseline) takes its gains as constructor keyword arguments (``Class(plant, kp=..., kd=...)``,
like :class:`agents.control.controllers.WhirlBrake`). A cross-entropy search (:mod:`agents.benchmarking.search`)
over the given ranges maximises the controller's **validation score**: the benchmark score
(:mod:`agents.benchmarking.score`) on the validation suite of the task (frictions 0.2/0.36/0.41/0.46/0.51 at
unbalance phases 45°/225°, :class:`agents.benchmarking.benchmark.Validator`), which shares no scenario with
the benchmark, so that ``rotordrop benchmark`` afterwards still measures the tuned controller on
unseen cases. The search starts from the class's ``GAINS`` defaults where it has them (clipped
into the range; else the middle of each range).

Outputs: ``tune.json`` (gains, validation score before and after, per-scenario rows of the
tuned controller and of the passive drop, each with its cost J, from which the validation score
is recomputed; the search history) and ``tune.png`` (best validation score per generation).
"""
from __future__ import annotations

import inspect
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from physics.runs.backend import Backend

from .benchmark import TASKS, Validator
from ..control.controllers import (BASELINES, Controller, controller_class, controller_env_kwargs,
                                   make_controller)
from .rollout import check_actor
from .score import write_json
from .ray_search import minimise


def parse_gain(text: str) -> tuple[str, float, float]:
    """``"kp=0:30"`` -> ``("kp", 0.0, 30.0)``."""
    name, _, rng = text.partition("=")
    parts = rng.split(":")
    try:
        lo, hi = (float(p) for p in parts)
    except ValueError:
        raise ValueError(f"--gain expects NAME=LO:HI, got {text!r}") from None
    if not name.strip().isidentifier() or not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
        raise ValueError(f"--gain {text!r}: needs a name and finite LO < HI")
    return name.strip(), lo, hi


def _controller(spec: str, env_id: str) -> type[Controller]:
    cls = controller_class(spec)
    if cls is None:
        raise ValueError(f"--policy {spec!r}: tune needs a controller class (a baseline: "
                         f"{', '.join(BASELINES)}; or package.module:Class or file.py:Class), "
                         f"not a learned policy")
    if env_id not in TASKS.values():
        raise ValueError(f"--env must be one of {', '.join(TASKS.values())}, got {env_id!r}")
    return cls


def _check_gains(cls: type[Controller], env_id: str, start: dict) -> dict:
    """Build the controller once with the start gains to fail early, naming what is wrong."""
    from ..control.plant import plant_of
    kw = controller_env_kwargs(cls, env_id)
    plant = plant_of(env_id, **kw)
    if not cls.supports(plant):
        make_controller(cls, plant)                      # raises, naming the missing channels
    known = gain_names(cls)
    unknown = [n for n in start if known is not None and n not in known]
    if unknown:
        raise ValueError(f"{cls.name} does not take the gains {unknown}; its gains: "
                         f"{', '.join(known) or 'none'}")
    try:
        cls(plant, **start)
    except TypeError as exc:
        raise ValueError(f"{cls.name} cannot be built with the gains {start} ({exc})") from None
    check_actor(env_id, lambda p: cls(p, **start), kw)          # fail fast: one step runs
    return kw


def _portable(spec: str) -> str:
    """``spec`` with a ``file.py`` made absolute (a Ray Tune trial runs in its own directory)."""
    path, sep, name = spec.rpartition(":")
    if sep and path.endswith(".py"):
        return f"{Path(path).resolve()}:{name}"
    return spec


def gain_names(cls: type[Controller]) -> list[str] | None:
    """The keyword arguments a controller class takes after ``plant`` (its ``GAINS`` when it
    takes ``**gains``); None when that cannot be told."""
    params = list(inspect.signature(cls.__init__).parameters.values())[2:]    # self, plant
    if any(p.kind is p.VAR_KEYWORD for p in params):
        return list(getattr(cls, "GAINS", {})) or None
    return [p.name for p in params if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]


@dataclass
class GainObjective:
    """Minus the validation score of the controller ``spec`` with the gains ``theta`` (picklable:
    a Ray Tune trial rebuilds the class from ``spec``)."""
    spec: str
    env_id: str
    env_kwargs: dict
    names: list[str]
    validator: Validator

    def score(self, theta) -> tuple[float, list[dict]]:
        cls = controller_class(self.spec)
        g = dict(zip(self.names, map(float, theta)))
        return self.validator.score(lambda plant: cls(plant, **g), self.env_kwargs)

    def __call__(self, theta) -> float:
        return -self.score(theta)[0]


def tune(spec: str, env_id: str, gains: list[str], out, iterations: int = 12,
         population: int = 24, elite: int = 6, seed: int = 0, progress: bool = True,
         plots: bool = True, backend: Backend = Backend(), suite: str = "nominal",
         registry=None) -> dict:
    """Run the search (module doc) and write ``tune.json`` / ``tune.png`` into ``out``; on
    ``--backend ray`` Ray Tune evaluates the candidates (:mod:`agents.benchmarking.ray_search`, its trials
    under ``out/ray_tune``), with the same result. ``suite="robust"``: on the robust
    validation set (:func:`agents.benchmarking.robust.robust_validator`, Full task only) instead:
    the suite named ``suite`` in ``registry`` (default :data:`agents.benchmarking.suites.SUITES`)
    gives the validation set (:meth:`~agents.benchmarking.suites.Suite.validator`)."""
    from .suites import SUITES
    chosen = (registry or SUITES).get(suite, "tune")
    if not gains:
        raise ValueError("--gain is required (NAME=LO:HI, repeatable)")
    ranges = [parse_gain(g) for g in gains]
    names = [n for n, _, _ in ranges]
    if len(set(names)) != len(names):
        raise ValueError(f"--gain names must differ, got {names}")
    for what, v, lo in (("--iterations", iterations, 0), ("--population", population, 1),
                        ("--elite", elite, 1)):
        if v < lo:
            raise ValueError(f"{what} must be >= {lo}, got {v}")
    if elite > population:
        raise ValueError(f"--elite = {elite} must be <= --population = {population}")
    cls = _controller(spec, env_id)
    low = np.array([lo for _, lo, _ in ranges])
    high = np.array([hi for _, _, hi in ranges])
    defaults = getattr(cls, "GAINS", {})
    start = np.clip([defaults.get(n, 0.5 * (lo + hi)) for n, lo, hi in ranges], low, high)
    env_kwargs = _check_gains(cls, env_id, dict(zip(names, start.tolist())))
    validator = chosen.validator(env_id)
    objective = GainObjective(_portable(spec), env_id, env_kwargs, names, validator)
    score = objective.score

    t0 = time.perf_counter()
    best_cost, best, history = minimise(
        objective, names, iterations, backend, Path(out) / "ray_tune", progress=progress,
        desc=f"tuning {cls.name}", mean=start, std=0.15 * (high - low), low=low, high=high,
        population=population, elite=elite, rng=np.random.default_rng(seed),
        min_std=0.01 * (high - low))
    final, rows = score(best)
    report = dict(controller=cls.name, spec=spec, env_id=env_id, suite=suite, backend=backend.name,
                  ranges={n: [lo, hi] for n, lo, hi in ranges},
                  start=dict(zip(names, start.tolist())), start_validation_score=-history[0]["best_cost"],
                  gains=dict(zip(names, best.tolist())), validation_score=final, rows=rows,
                  passive_rows=objective.validator.passive,
                  history=[dict(iteration=h["iteration"], best_validation_score=-h["best_cost"],
                                generation_best=-h["generation_best"],
                                gains=dict(zip(names, h["best"].tolist()))) for h in history],
                  search=dict(iterations=iterations, population=population, elite=elite, seed=seed),
                  wall_time_s=time.perf_counter() - t0)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "tune.json", report)
    report["files"] = ["tune.json"]
    if plots:
        from .plots import plot_tuning
        report["files"].append(plot_tuning(report, out).name)
    return report
