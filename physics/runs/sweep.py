"""Many drops at once: threads of one process, a progress bar that never drops a failed run.

A :class:`Run` is a preset (or TOML path) plus dotted overrides, exactly what ``rotordrop drop
--scene ... --set ...`` takes, so every point of a sweep can be re-run by hand
(:func:`reproduce_command`). :func:`run_chunk` is the unit of work of every ensemble
(``rotordrop study paper``, ``study sweep``, the accuracy study) and of every backend that
distributes them: picklable runs in, one :class:`Outcome` per run out, in order; a run that
raises (bad scene, integration failure, anything else) comes back with ``ok = False`` and the
error text instead of being skipped. :func:`run_sweep` is it with a progress bar.

The drops of a chunk run on threads of this process: the numba kernels release the GIL
(``nogil=True``, :mod:`physics._jit`), so one drop integrates while another thread builds the
next model or reduces a finished drop to its metrics; one kernel warm-up per chunk, no process
start-up, no pickling of results between processes. Each drop runs
:func:`physics.simulate.run_model`, the code of a single ``rotordrop drop``, so every per-drop
metric equals the single drop's bit for bit (only the timings differ). Only about ``threads``
drops' time series are alive at once.
"""
from __future__ import annotations

import ctypes
import functools
import os
import shlex
import traceback
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from numbers import Integral
from typing import Any, Callable, Iterable, Sequence

from ..metrics import compute_metrics
from ..results import Result


@dataclass(frozen=True)
class Run:
    """One drop: scene source, dotted overrides and free-form labels used to group results;
    ``observe = False``: the batch's ``evaluate`` hook is skipped for it (a drop whose extra
    numbers nobody reads, e.g. the paper study's sensitivity drops: only metrics come back)."""
    scene: str = "paper"
    overrides: tuple[tuple[str, Any], ...] = ()
    labels: tuple[tuple[str, Any], ...] = ()
    observe: bool = True

    @classmethod
    def of(cls, scene: str = "paper", overrides: dict | None = None, *, observe: bool = True,
           **labels) -> "Run":
        return cls(scene, tuple(sorted((overrides or {}).items())), tuple(labels.items()), observe)

    @property
    def settings(self) -> dict[str, Any]:
        return dict(self.overrides)

    @property
    def label(self) -> dict[str, Any]:
        return dict(self.labels)

    def to_scene(self):
        """The :class:`physics.scene.Scene` this run simulates."""
        from ..scene import load_scene
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

    @classmethod
    def from_dict(cls, d: dict) -> "Outcome":
        """The outcome :meth:`to_dict` wrote (e.g. read back from JSON)."""
        run = Run.of(d["scene"], d["overrides"], **d["labels"])
        return cls(run, d["ok"], d["metrics"], d["extra"], d["error"])


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
    keeps the full result, e.g. to draw it); ``evaluate`` fills ``extra`` unless the run says
    ``observe = False``."""
    metrics = compute_metrics(result)
    extra = evaluate(result) if evaluate is not None and run.observe else {}
    return Outcome(run, True, metrics, extra)


def failed_outcome(run: Run, exc: Exception) -> Outcome:
    """The failed :class:`Outcome` of ``run`` stopped by ``exc``: the message of an expected
    error (bad scene, integration failure), a short traceback with anything else."""
    detail = "" if _expected(exc) else "\n" + traceback.format_exc(limit=3)
    return Outcome(run, False, error=f"{type(exc).__name__}: {exc}{detail}")


def _expected(exc: Exception) -> bool:
    from ..scene import SceneError
    from ..simulate import IntegrationError
    return isinstance(exc, (SceneError, IntegrationError))


def plan_jobs(jobs: int | None, runs: int) -> tuple[int, str]:
    """Threads for ``runs`` drops: ``jobs`` (>= 1; None: all available cores) capped at the CPU
    count and at the number of drops, and a note saying so when ``jobs`` was capped ("" else)."""
    if jobs is not None and (isinstance(jobs, bool) or not isinstance(jobs, Integral) or jobs < 1):
        from . import UsageError
        raise UsageError(f"--jobs must be an integer >= 1, got {jobs!r}")
    cpus = available_cores()
    used = max(1, min(cpus if jobs is None else jobs, cpus, runs))
    if jobs is None or used == jobs:
        return used, ""
    return used, (f"--jobs {jobs} capped at {used} thread(s) "
                  f"({cpus} CPU(s), {runs} drop(s) to run)")


def run_sweep(runs: Sequence[Run] | Iterable[Run], evaluate: Evaluate | None = None,
              jobs: int | None = None, desc: str = "sweep", progress: bool = True) -> list[Outcome]:
    """Simulate ``runs`` in this process on ``jobs`` threads (default: all available cores; at
    most one per CPU and per run, :func:`plan_jobs`) with :func:`run_chunk`;
    outcomes in input order.

    ``evaluate(result) -> dict`` (a module-level function) computes extra numbers from the full
    result as each drop finishes; only the small dicts are kept.
    """
    runs = list(runs)
    jobs = plan_jobs(jobs, len(runs))[0]
    bar = _bar(progress, len(runs), desc)
    try:
        return run_chunk(runs, evaluate, threads=jobs,
                         on_outcome=None if bar is None else (lambda i, o: _tick(bar, o)))
    finally:
        if bar is not None:
            bar.close()


OnOutcome = Callable[[int, Outcome], None]


def available_cores() -> int:
    """CPUs this process may run on (its affinity mask; all CPUs where that is unknown)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:                                     # not on Linux
        return max(1, os.cpu_count() or 1)


# glibc's mallopt parameters (malloc.h)
M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
KEEP_FREED_BYTES = 256 << 20        # free memory the allocator may keep at the top of its heaps
HEAP_ARRAY_BYTES = 32 << 20         # arrays up to this size come from the heap (glibc's maximum)


@functools.cache
def keep_freed_memory() -> bool:
    """Let this process's C allocator keep the memory a finished drop frees for the next drop
    (glibc: arrays up to ``HEAP_ARRAY_BYTES`` from the heap, whose free top is returned to the
    system only beyond ``KEEP_FREED_BYTES``). Otherwise each drop's output arrays (its states
    twice and its diagnostics, ≈ 13 MB at 20 kHz for 1 s) go back to the system and are faulted
    in again page by page: ≈ 1 700 page faults and 4 ms of system time per drop, a third of the
    output samples' diagnostics. Changes no number; the process keeps up to its peak memory.
    Once per process; False where the C library has no ``mallopt`` (not glibc)."""
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return bool(mallopt(M_MMAP_THRESHOLD, HEAP_ARRAY_BYTES)
                and mallopt(M_TRIM_THRESHOLD, KEEP_FREED_BYTES))


def run_chunk(runs: Sequence[Run], evaluate: Evaluate | None = None, threads: int | None = None,
              on_outcome: OnOutcome | None = None) -> list[Outcome]:
    """Simulate ``runs`` in this process on ``threads`` threads (default: the available cores,
    at most one per run); outcomes in input order.

    ``evaluate(result) -> dict`` (a module-level function) adds numbers computed from the full
    result to ``Outcome.extra``. ``on_outcome(i, outcome)`` is called in the calling thread as
    drop ``runs[i]`` finishes (progress bars, writing results to disk). A drop that fails comes
    back with ``ok = False`` and its error; nothing is raised for it.
    """
    runs = list(runs)
    if threads is not None and (isinstance(threads, bool) or not isinstance(threads, Integral)
                                or threads < 1):
        raise ValueError(f"threads must be an integer >= 1, got {threads!r}")
    if not runs:
        return []
    n = max(1, min(threads or available_cores(), len(runs)))
    keep_freed_memory()
    compile_s = _warm_up(runs[0])
    bases = _base_scenes(runs)
    out: list[Outcome | None] = [None] * len(runs)
    if n == 1:
        for i, run in enumerate(runs):
            out[i] = simulate_drop(run, evaluate, compile_s if i == 0 else 0.0, bases)
            if on_outcome is not None:
                on_outcome(i, out[i])
        return out
    with ThreadPoolExecutor(n, thread_name_prefix="drop") as pool:
        pending = {pool.submit(simulate_drop, run, evaluate, compile_s if i == 0 else 0.0, bases): i
                   for i, run in enumerate(runs)}
        while pending:
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                i = pending.pop(future)
                out[i] = future.result()
                if on_outcome is not None:
                    on_outcome(i, out[i])
    return out


def simulate_drop(run: Run, evaluate: Evaluate | None = None, compile_s: float = 0.0,
                  bases: dict | None = None) -> Outcome:
    """One drop of a chunk whose kernels are loaded (``compile_s``: its share of the warm-up;
    ``bases``: the chunk's scenes without overrides by source, :func:`_base_scenes`)."""
    from ..model import build_model
    from ..simulate import run_model
    try:
        base = (bases or {}).get(run.scene)
        scene = base.with_overrides(run.settings) if base is not None else run.to_scene()
        return outcome_of(run, run_model(build_model(scene), compile_s), evaluate)
    except Exception as exc:                                   # reported, never dropped
        return failed_outcome(run, exc)


def _base_scenes(runs: Sequence[Run]) -> dict:
    """Each scene source of ``runs`` loaded once (``load_scene(source, overrides)`` is
    ``load_scene(source).with_overrides(overrides)``; parsing the TOML per drop cost more than
    the metrics). A source that fails to load is left out: its drops report the error."""
    from ..scene import load_scene
    bases = {}
    for source in {run.scene for run in runs}:
        try:
            bases[source] = load_scene(source)
        except Exception:                                      # the drops report it
            pass
    return bases


def _warm_up(run: Run) -> float:
    """Load the kernels once before the threads start (seconds; 0 when the scene is bad: its
    drop reports the error)."""
    from ..model import build_model
    from ..simulate import warm_up
    try:
        return warm_up(build_model(run.to_scene()))
    except Exception:                                          # the drop itself reports it
        return 0.0


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
