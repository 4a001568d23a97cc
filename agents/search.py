"""Cross-entropy search (CEM): the derivative-free optimiser behind the gain tuning of
``whirl-brake`` (:mod:`agents.research.tune_whirl_brake`) and the open-loop whirl bound
(:mod:`agents.research.whirl_bound`). Deterministic for a given ``rng``."""
from __future__ import annotations

from typing import Callable

import numpy as np


def cross_entropy(cost: Callable[[np.ndarray], float], mean, std, low, high, iterations: int,
                  population: int, elite: int, rng: np.random.Generator, min_std=0.0,
                  progress: bool = True, desc: str = "cross-entropy search", batch: bool = False):
    """Minimise ``cost`` over the box [low, high] (arrays of ``mean``'s shape).

    Each generation samples ``population`` candidates from N(mean, std²) (clipped to the box),
    refits mean and std to the ``elite`` best, and adds ``min_std`` to the refitted std (so the
    search never collapses below it). With ``batch=True`` ``cost`` takes a stack of candidates
    (k, ...) and returns their k costs (a generation in one call, e.g. one batched rollout).
    Returns
    ``(best cost, best candidate, history)``; ``history[i]`` holds the best cost so far, the
    generation's best cost and the best candidate after generation i (i = 0: ``mean``)."""
    from tqdm.auto import tqdm
    if not 1 <= elite <= population:
        raise ValueError(f"elite = {elite} must be in [1, population = {population}]")
    mean, std = np.asarray(mean, dtype=float).copy(), np.asarray(std, dtype=float).copy()
    low, high = np.broadcast_to(low, mean.shape), np.broadcast_to(high, mean.shape)
    costs_of = (lambda xs: np.asarray(cost(xs), dtype=float)) if batch else \
        (lambda xs: np.array([cost(x) for x in xs]))
    best = (float(costs_of(mean[None])[0]), mean.copy())
    history = [dict(iteration=0, best_cost=best[0], generation_best=best[0], best=best[1].copy())]
    for it in tqdm(range(1, iterations + 1), desc=desc, unit="gen", disable=not progress):
        pop = np.clip(mean + std * rng.standard_normal((population, *mean.shape)), low, high)
        costs = costs_of(pop)
        if costs.min() < best[0]:
            best = (float(costs.min()), pop[np.argmin(costs)].copy())
        top = pop[np.argsort(costs)[:elite]]
        mean, std = top.mean(0), top.std(0) + min_std
        history.append(dict(iteration=it, best_cost=best[0], generation_best=float(costs.min()),
                            best=best[1].copy()))
    return best[0], best[1], history
