"""The cross-entropy search (:class:`agents.benchmarking.search.CrossEntropy`) on a backend: locally, or
driven by Ray Tune (:func:`minimise`).

Every candidate is one Ray Tune trial (``objective(theta)`` -> ``{"cost": ...}``), scheduled on
the cluster as Tune schedules trials (one CPU each, retried when a node dies, its results under
``storage``); a Tune ``Searcher`` hands out each generation's candidates and refits the search
when the generation's costs are all in. The candidates and their order are the local search's,
so the same costs give the same gains on both backends. Ray is imported only here.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np

from .search import CrossEntropy, cross_entropy


def minimise(objective: Callable[[np.ndarray], float], names: list[str], iterations: int,
             backend, storage: Path, progress: bool = True, desc: str = "cross-entropy search",
             **search):
    """The cross-entropy search (``search``: :class:`CrossEntropy`'s arguments) of
    ``objective`` on ``backend`` (:class:`physics.runs.backend.Backend`): here one candidate after the
    other, or on Ray Tune (trials under ``storage``); the same result either way."""
    if backend.name != "ray":
        return cross_entropy(objective, iterations=iterations, progress=progress, desc=desc,
                             **search)
    with backend.session():
        return ray_cross_entropy(objective, CrossEntropy(**search), names, iterations, storage,
                                 progress=progress, desc=f"{desc} (Ray Tune)")


def ray_cross_entropy(objective: Callable[[np.ndarray], float], search: CrossEntropy,
                      names: list[str], iterations: int, storage: Path, progress: bool = True,
                      desc: str = "cross-entropy search"):
    """Minimise ``objective`` (picklable, module level) with ``search`` as Ray Tune trials;
    returns ``(best cost, best candidate, history)`` as :func:`agents.benchmarking.search.cross_entropy`."""
    from ray import tune
    from tqdm.auto import tqdm
    bar = tqdm(total=iterations, desc=desc, unit="gen", disable=not progress)
    searcher = _searcher_class()(search, names, iterations, bar)
    tuner = tune.Tuner(
        tune.with_parameters(_trial, objective=objective, names=names),
        tune_config=tune.TuneConfig(search_alg=searcher, metric="cost", mode="min",
                                    num_samples=1 + iterations * search.population),
        run_config=tune.RunConfig(storage_path=str(Path(storage).resolve()), name="search",
                                  verbose=0))
    try:
        results = tuner.fit()
    finally:
        bar.close()
    failed = [r.error for r in results if r.error is not None]
    if failed:
        raise ValueError(f"{len(failed)} trial(s) failed; the first: {failed[0]}")
    return search.best[0], search.best[1], search.history


def _trial(config: dict, objective, names: list[str]) -> dict:
    """One candidate (a Ray Tune function trainable)."""
    return {"cost": float(objective(np.array([config[n] for n in names])))}


def _searcher_class():
    from ray.tune.search import Searcher

    class CrossEntropySearcher(Searcher):
        """Hands out a generation's candidates, waits for their costs, refits, repeats."""

        def __init__(self, search: CrossEntropy, names, iterations: int, bar):
            super().__init__(metric="cost", mode="min")
            self.search, self.names, self.iterations, self.bar = search, names, iterations, bar
            self.queue = [(-1, search.start())]          # (index in the generation, candidate)
            self.running: dict[str, int] = {}
            self.costs: dict[int, float] = {}
            self.size, self.generation_done = 1, False

        def __getstate__(self):                          # Tune saves the searcher: no bar
            return {**self.__dict__, "bar": None}

        def suggest(self, trial_id: str):
            if not self.queue:
                if not self.generation_done:
                    return None                           # its candidates are still running
                if len(self.search.history) > self.iterations:
                    return Searcher.FINISHED
                self.queue = list(enumerate(self.search.ask()))
                self.size, self.costs, self.generation_done = len(self.queue), {}, False
            k, theta = self.queue.pop(0)
            self.running[trial_id] = k
            return {n: float(v) for n, v in zip(self.names, np.ravel(theta))}

        def on_trial_complete(self, trial_id: str, result=None, error: bool = False):
            k = self.running.pop(trial_id)
            self.costs[k] = float("inf") if error or not result else float(result["cost"])
            if len(self.costs) < self.size:
                return
            if k == -1:
                self.search.tell_start(self.costs[-1])
            else:
                self.search.tell([self.costs[i] for i in range(self.size)])
                if self.bar is not None:
                    self.bar.update(1)
            self.generation_done = True

    return CrossEntropySearcher
