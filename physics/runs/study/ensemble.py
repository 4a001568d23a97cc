"""Ensembles of equally plausible drops and the whirl-onset statistics computed from them.

Near the whirl threshold the outcome of one drop depends sensitively on details nobody
controls (where the unbalance points when the AMBs fail, when exactly they fail), so a single
run per friction coefficient is not a threshold. An ensemble member differs from the nominal
drop only through two ordinary scene keys, ``unbalance.angle_deg`` (the rotor's angular position
at the fault) and ``amb.off_time`` (fault-time jitter), so every member can be re-run with
``rotordrop drop --set ...``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from numbers import Integral
from typing import Sequence

import numpy as np

ENSEMBLE_KEYS = ("unbalance.angle_deg", "amb.off_time")    # the scene keys a member perturbs
JITTER_S = 0.5e-3      # fault-time jitter half-width [s]: a few unbalance revolutions at 10 krpm


def perturbations(n: int, t_off: float, seed: int = 0, jitter_s: float = JITTER_S) -> list[dict]:
    """``n`` ensemble members as scene overrides.

    Unbalance angles are stratified over the circle (one per 360/n sector, random within it) and
    fault times are stratified over [t_off - jitter, t_off + jitter] in a shuffled order, so even a
    small ensemble covers both ranges (Latin-hypercube design). Deterministic for a given seed.
    """
    if n < 1:
        raise ValueError(f"an ensemble needs at least one member, got n = {n}")
    if isinstance(seed, bool) or not isinstance(seed, Integral) or seed < 0:
        raise ValueError(f"the ensemble seed must be an integer >= 0, got {seed!r}")
    rng = np.random.default_rng(seed)
    angles = 360.0 * (np.arange(n) + rng.uniform(size=n)) / n
    slots = (np.arange(n) + rng.uniform(size=n)) / n
    times = t_off + jitter_s * (2.0 * slots[rng.permutation(n)] - 1.0)
    times = np.maximum(times, 0.0)
    return [{"unbalance.angle_deg": round(float(a), 3), "amb.off_time": round(float(t), 7)}
            for a, t in zip(angles, times)]


@dataclass(frozen=True)
class Onset:
    """Whirl-onset statistics of one probability curve p(mu)."""
    threshold: float | None         # mu where p crosses 50 % going up (linear interpolation),
                                    # only where p never falls along the grid (``monotone``)
    logistic_mu50: float | None     # mu50 of a maximum-likelihood logistic fit to all runs
    logistic_width: float | None    # its scale s in p = 1 / (1 + exp(-(mu - mu50) / s))
    lowest_whirl: float | None      # lowest mu at which any member whirled
    certain_from: float | None      # lowest mu from which every member whirls at every larger mu
    crossings: int                  # how often p crosses 50 % (> 1: interleaved onset)
    monotone: bool = True           # p never falls as mu grows: a threshold means something

    def to_dict(self) -> dict:
        return {k: (None if v is None else (round(v, 4) if isinstance(v, float) else v))
                for k, v in self.__dict__.items()}


def onset(mu: Sequence[float], p: Sequence[float], mu_runs: Sequence[float] | None = None,
          whirl_runs: Sequence[bool] | None = None) -> Onset:
    """Onset statistics from a probability curve (sorted by mu) and, optionally, the raw runs.
    The 50 % threshold is named only where the curve never falls (checked on the grid): where
    whirl comes and goes with mu, the curve itself, ``lowest_whirl`` and ``certain_from`` say it."""
    mu = np.asarray(mu, float)
    p = np.asarray(p, float)
    order = np.argsort(mu)
    mu, p = mu[order], p[order]
    above = p >= 0.5
    ups = np.flatnonzero(~above[:-1] & above[1:])
    threshold = None
    if above.size and above[0]:
        threshold = float(mu[0])
    elif ups.size:
        i = ups[0]
        threshold = float(mu[i] + (0.5 - p[i]) * (mu[i + 1] - mu[i]) / (p[i + 1] - p[i]))
    whirled = np.flatnonzero(p > 0)
    lowest = float(mu[whirled[0]]) if whirled.size else None
    certain = None
    if p.size and p[-1] >= 1.0:
        k = p.size - 1
        while k > 0 and p[k - 1] >= 1.0:
            k -= 1
        certain = float(mu[k])
    crossings = int(np.count_nonzero(above[:-1] != above[1:]))
    monotone = bool(np.all(np.diff(p) >= 0.0))
    if not monotone:             # whirl is a probability here, not a threshold: name none
        threshold = None
    mu50 = width = None
    if mu_runs is not None and whirl_runs is not None:
        fit = logistic_fit(mu_runs, whirl_runs)
        if fit is not None:
            mu50, width = fit
    return Onset(threshold, mu50, width, lowest, certain, crossings, monotone)


def logistic_fit(x: Sequence[float], y: Sequence[bool], iters: int = 100) -> tuple[float, float] | None:
    """Maximum-likelihood fit of p = 1/(1 + exp(-(x - x50)/s)) (Newton's method).

    Returns (x50, s), or None when the outcomes are all equal (no crossing to fit) or perfectly
    separated (the likelihood has no finite maximum: the midpoint of the gap is returned with
    s = 0).
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    if y.min() == y.max():
        return None
    lo, hi = x[y == 0].max(), x[y == 1].min()
    if lo < hi:                                  # perfectly separated
        return float(0.5 * (lo + hi)), 0.0
    xs = (x - x.mean()) / (x.std() or 1.0)
    beta = np.zeros(2)
    X = np.stack([np.ones_like(xs), xs], 1)
    for _ in range(iters):
        z = np.clip(X @ beta, -30.0, 30.0)
        q = 1.0 / (1.0 + np.exp(-z))
        g = X.T @ (y - q)
        H = (X * (q * (1 - q))[:, None]).T @ X + 1e-9 * np.eye(2)
        step = np.linalg.solve(H, g)
        beta += step
        if np.max(np.abs(step)) < 1e-10:
            break
    b0, b1 = beta
    if b1 <= 0.0 or not math.isfinite(b0 / b1):
        return None                              # probability falls with mu: no onset
    s_std = x.std() or 1.0
    return float(x.mean() - b0 / b1 * s_std), float(s_std / b1)


def probability_curve(values: Sequence[float], whirls: Sequence[bool]) -> list[dict]:
    """Group run outcomes by parameter value: [{"value", "probability", "runs", "whirls"}]."""
    groups: dict[float, list[bool]] = {}
    for v, w in zip(values, whirls):
        groups.setdefault(round(float(v), 6), []).append(bool(w))
    return [dict(value=v, probability=sum(ws) / len(ws), runs=len(ws), whirls=sum(ws))
            for v, ws in sorted(groups.items())]


Z95 = 1.959964                                  # two-sided 95 % normal quantile


def wilson(k: int, n: int) -> list[float]:
    """Wilson's 95 % score interval of a binomial fraction k / n (Wilson 1927): unlike p +- SE it
    stays in [0, 1] and is not empty at k = 0 or k = n (3 / n wide there, the 'rule of three').
    The studies' whirl fractions and the Recover benchmark's rates use it."""
    p, z2 = k / n, Z95 * Z95
    mid = (p + z2 / (2 * n)) / (1 + z2 / n)
    half = Z95 * math.sqrt(p * (1 - p) / n + z2 / (4 * n * n)) / (1 + z2 / n)
    return [float(max(mid - half, 0.0)), float(min(mid + half, 1.0))]     # a list, as in JSON
