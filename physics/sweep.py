"""Many drops at once: a process pool with a progress bar that never drops a failed run.

A :class:`Run` is a preset (or TOML path) plus dotted overrides, exactly what ``rotordrop drop
--scene ... --set ...`` takes, so every point of a sweep can be re-run by hand
(:func:`reproduce_command`). :func:`run_sweep` simulates the runs on all cores and returns one
:class:`Outcome` per run, in order; a run that raises (bad scene, integration failure, anything
else) comes back with ``ok = False`` and the error text instead of being skipped.

Each worker loads the numba kernels once (:func:`physics.simulate.warm_up` in the pool
initializer); every scene shares the same compiled kernel.
"""
from __future__ import annotations

import multiprocessing
import os
import shlex
import traceback
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from numbers import Integral
from typing import Any, Callable, Iterable, Sequence

from .metrics import compute_metrics
from .results import Result


@dataclass(frozen=True)
class Run:
    """One drop: scene source, dotted overrides and free-form labels used to group results."""
    scene: str = "paper"
    overrides: tuple[tuple[str, Any], ...] = ()
    labels: tuple[tuple[str, Any], ...] = ()

    @classmethod
    def of(cls, scene: str = "paper", overrides: dict | None = None, **labels) -> "Run":
        return cls(scene, tuple(sorted((overrides or {}).items())), tuple(labels.items()))

    @property
    def settings(self) -> dict[str, Any]:
        return dict(self.overrides)

    @property
    def label(self) -> dict[str, Any]:
        return dict(self.labels)

    def to_scene(self):
        """The :class:`physics.scene.Scene` this run simulates."""
        from .scene import load_scene
        return load_scene(self.scene, self.settings)

    def to_dict(self) -> dict:
        return dict(scene=self.scene, overrides=self.settings, labels=self.label,
                    command=reproduce_command(self))


@dataclass
class Outcome:
    """What came back from one run: metrics and extra numbers, or the error that stopped it."""
    run: Run
    ok: bool
    metrics: dict = field(default_factory=dict)
    extra: dict = field(default_factory=dict)
    error: str | None = None

    def to_dict(self) -> dict:
        d = self.run.to_dict()
        d.update(ok=self.ok, error=self.error, metrics=self.metrics, extra=self.extra)
        return d


def reproduce_command(run: Run) -> str:
    """The ``rotordrop drop`` command line that re-runs ``run`` exactly."""
    parts = ["rotordrop", "drop", "--scene", run.scene]
    for key, value in run.overrides:
        text = ("true" if value else "false") if isinstance(value, bool) else (
            repr(value) if isinstance(value, float) else str(value))
        parts += ["--set", f"{key}={text}"]
    return " ".join(shlex.quote(p) for p in parts)


def changes(scene, overrides: dict) -> bool:
    """Whether ``overrides`` change any value of ``scene``: a variant that does not would only
    repeat the scene's own run (a sweep skips it)."""
    return any(scene.get(k) != v for k, v in overrides.items())


Evaluate = Callable[[Result], dict]


def outcome_of(run: Run, result: Result, evaluate: Evaluate | None = None) -> Outcome:
    """The :class:`Outcome` of ``run`` from its simulated ``result`` (for a caller that also
    keeps the full result, e.g. to draw it)."""
    metrics = compute_metrics(result)
    extra = evaluate(result) if evaluate is not None else {}
    return Outcome(run, True, metrics, extra)


def simulate_run(run: Run, evaluate: Evaluate | None = None) -> Outcome:
    """Simulate one run; every exception becomes a failed :class:`Outcome` with its message."""
    from .simulate import simulate
    try:
        return outcome_of(run, simulate(run.to_scene()), evaluate)
    except Exception as exc:                                   # reported, never dropped
        detail = "" if _expected(exc) else "\n" + traceback.format_exc(limit=3)
        return Outcome(run, False, error=f"{type(exc).__name__}: {exc}{detail}")


def _expected(exc: Exception) -> bool:
    from .scene import SceneError
    from .simulate import IntegrationError
    return isinstance(exc, (SceneError, IntegrationError))


def _init_worker(scene: str) -> None:
    """Pool initializer: load the compiled kernels once per worker process."""
    from .model import build_model
    from .scene import load_scene
    from .simulate import warm_up
    os.environ.setdefault("MPLBACKEND", "Agg")
    warm_up(build_model(load_scene(scene)))


def _call(args):
    run, evaluate = args
    return simulate_run(run, evaluate)


def default_jobs() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:                                     # not on Linux
        return max(1, os.cpu_count() or 1)


def plan_jobs(jobs: int | None, runs: int) -> tuple[int, str]:
    """Worker processes for ``runs`` drops: ``jobs`` (>= 1; None: all cores) capped at the CPU
    count and at the number of drops, and a note saying so when ``jobs`` was capped ("" else)."""
    if jobs is not None and (isinstance(jobs, bool) or not isinstance(jobs, Integral) or jobs < 1):
        from .cli import UsageError
        raise UsageError(f"--jobs must be an integer >= 1, got {jobs!r}")
    cpus = default_jobs()
    used = max(1, min(cpus if jobs is None else jobs, cpus, runs))
    if jobs is None or used == jobs:
        return used, ""
    return used, (f"--jobs {jobs} capped at {used} worker process(es) "
                  f"({cpus} CPU(s), {runs} drop(s) to run)")


def run_sweep(runs: Sequence[Run] | Iterable[Run], evaluate: Evaluate | None = None,
              jobs: int | None = None, desc: str = "sweep", progress: bool = True) -> list[Outcome]:
    """Simulate ``runs`` on ``jobs`` processes (default: all cores; at most one per CPU and per
    run, :func:`plan_jobs`); outcomes in input order.

    ``evaluate(result) -> dict`` (a module-level function, so it can be pickled) computes extra
    numbers from the full result inside the worker; only the small dicts travel back.
    """
    runs = list(runs)
    jobs = plan_jobs(jobs, len(runs))[0]
    bar = _bar(progress, len(runs), desc)
    out: list[Outcome] = []
    try:
        if jobs == 1 or len(runs) <= 1:
            if runs:
                _init_worker(runs[0].scene)
            for run in runs:
                out.append(simulate_run(run, evaluate))
                _tick(bar, out[-1])
        else:
            ctx = multiprocessing.get_context("fork" if os.name == "posix" else "spawn")
            with ProcessPoolExecutor(jobs, mp_context=ctx, initializer=_init_worker,
                                     initargs=(runs[0].scene,)) as pool:
                chunk = max(1, min(8, len(runs) // (4 * jobs)))
                for outcome in pool.map(_call, ((r, evaluate) for r in runs), chunksize=chunk):
                    out.append(outcome)
                    _tick(bar, outcome)
    finally:
        if bar is not None:
            bar.close()
    return out


def _bar(enabled: bool, total: int, desc: str):
    if not enabled:
        return None
    from tqdm.auto import tqdm
    return tqdm(total=total, desc=desc, unit="run")


def _tick(bar, outcome: Outcome) -> None:
    if bar is None:
        return
    bar.update(1)
    if not outcome.ok:
        bar.failed = getattr(bar, "failed", 0) + 1
        bar.set_postfix_str(f"{bar.failed} failed (reported, not dropped)", refresh=False)
