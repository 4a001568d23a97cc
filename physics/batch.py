"""Many drops in one process: the numba kernels on every core, metrics as each drop finishes.

:func:`run_chunk` is the unit of work of every ensemble (``rotordrop study paper``, ``study
sweep``, the accuracy study) and of every backend that distributes them: it takes picklable
:class:`physics.sweep.Run` s and returns one :class:`physics.sweep.Outcome` per run, in order.
The drops run on ``threads`` threads of this process. The kernels release the GIL
(``nogil=True``, :mod:`physics._jit`), so the integration of one drop proceeds while another
thread builds the next model or reduces a finished drop to its metrics: one warm-up per chunk,
no process start-up, no pickling of results between processes.

Each drop runs :func:`physics.simulate.run_model`, the very code of a single ``rotordrop drop``,
so every per-drop metric equals the single drop's, bit for bit (only the timings differ). Only
about ``threads`` drops' time series are alive at once.
"""
from __future__ import annotations

import os
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from numbers import Integral
from typing import Callable, Sequence

from .sweep import Evaluate, Outcome, Run, failed_outcome, outcome_of

OnOutcome = Callable[[int, Outcome], None]


def available_cores() -> int:
    """CPUs this process may run on (its affinity mask; all CPUs where that is unknown)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:                                     # not on Linux
        return max(1, os.cpu_count() or 1)


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
    from .model import build_model
    from .simulate import run_model
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
    from .scene import load_scene
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
    from .model import build_model
    from .simulate import warm_up
    try:
        return warm_up(build_model(run.to_scene()))
    except Exception:                                          # the drop itself reports it
        return 0.0
