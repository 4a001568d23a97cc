"""Cross-entropy search (CEM): the derivative-free optimiser behind the gain tuning of
``whirl-brake`` (:mod:`agents.research.tune_whirl_brake`) and the open-loop whirl bound
(:mod:`agents.research.whirl_bound`) and of ``rotordrop tune`` (there on Ray Tune with
``--backend ray``, :mod:`agents.benchmarking.ray_search`). Deterministic for a given ``rng``."""
from __future__ import annotations

from typing import Callable

import numpy as np


class CrossEntropy:
    """The state of a cross-entropy search over the box [low, high]: :meth:`start` gives the
    first candidate (``mean``), :meth:`ask` a generation, :meth:`tell` their costs.

    Each generation samples ``population`` candidates from N(mean, std²) (clipped to the box),
    refits mean and std to the ``elite`` best, and adds ``min_std`` to the refitted std (so the
    search never collapses below it). ``history[i]`` holds the best cost so far, the generation's
    best cost and the best candidate after generation i (i = 0: ``mean``). Whoever evaluates
    the candidates (a loop here, Ray Tune in :mod:`agents.benchmarking.ray_search`), the same costs give the
    same search."""

    def __init__(self, mean, std, low, high, population: int, elite: int,
                 rng: np.random.Generator, min_std=0.0):
        if not 1 <= elite <= population:
            raise ValueError(f"elite = {elite} must be in [1, population = {population}]")
        self.mean = np.asarray(mean, dtype=float).copy()
        self.std = np.asarray(std, dtype=float).copy()
        self.low = np.broadcast_to(low, self.mean.shape)
        self.high = np.broadcast_to(high, self.mean.shape)
        self.population, self.elite, self.rng, self.min_std = population, elite, rng, min_std
        self.best: tuple[float, np.ndarray] | None = None
        self.history: list[dict] = []
        self._pop: np.ndarray | None = None

    def start(self) -> np.ndarray:
        return self.mean.copy()

    def tell_start(self, cost: float) -> None:
        self.best = (float(cost), self.mean.copy())
        self.history.append(dict(iteration=0, best_cost=self.best[0], generation_best=self.best[0],
                                 best=self.best[1].copy()))

    def ask(self) -> np.ndarray:
        self._pop = np.clip(self.mean + self.std * self.rng.standard_normal(
            (self.population, *self.mean.shape)), self.low, self.high)
        return self._pop

    def tell(self, costs) -> None:
        costs, pop = np.asarray(costs, dtype=float), self._pop
        if costs.min() < self.best[0]:
            self.best = (float(costs.min()), pop[np.argmin(costs)].copy())
        top = pop[np.argsort(costs)[:self.elite]]
        self.mean, self.std = top.mean(0), top.std(0) + self.min_std
        self.history.append(dict(iteration=len(self.history), best_cost=self.best[0],
                                 generation_best=float(costs.min()), best=self.best[1].copy()))


def cross_entropy(cost: Callable[[np.ndarray], float], mean, std, low, high, iterations: int,
                  population: int, elite: int, rng: np.random.Generator, min_std=0.0,
                  progress: bool = True, desc: str = "cross-entropy search", batch: bool = False):
    """Minimise ``cost`` over the box [low, high] (arrays of ``mean``'s shape) with
    :class:`CrossEntropy`, evaluating the candidates one after the other, or with
    ``batch=True`` a generation in one call (``cost`` takes a stack of k candidates and returns
    their k costs, e.g. one batched rollout). Returns ``(best cost, best candidate, history)``."""
    from tqdm.auto import tqdm
    costs_of = (lambda xs: np.asarray(cost(xs), dtype=float)) if batch else \
        (lambda xs: np.array([cost(x) for x in xs]))
    search = CrossEntropy(mean, std, low, high, population, elite, rng, min_std)
    search.tell_start(costs_of(search.start()[None])[0])
    for _ in tqdm(range(1, iterations + 1), desc=desc, unit="gen", disable=not progress):
        search.tell(costs_of(search.ask()))
    return search.best[0], search.best[1], search.history
