"""The KPI reward (env kwarg ``reward="kpi"``): a reward aligned with the benchmark's KPIs.

The default reward sums per-step penalties (whirl revolutions, contact force, displacement,
effort). The benchmark scores episode *maxima* instead: the whirl verdict, the peak contact
force and the maximum displacement. The KPI reward is the decrease of a potential built from
the running episode KPIs,

    Φ_t = w_whirl · min(n*_t, 3) / 3 + w_verdict · [n*_t ≥ 3] + w_severity · n*_t / whirl_ref_revs
          + w_force · F*_t / force_ref + w_disp · D*_t / disp_ref_um,
    r_t = −(Φ_t − Φ_{t−1}),   Φ_0 = 0,

with n*_t the peak net backward orbit revolutions (3 make a backward whirl), F*_t the peak
contact force [N] and D*_t the maximum displacement [µm] so far. The first two terms are the
whirl's onset (a ramp to the verdict, and the verdict), the third its severity: it does not
saturate, so a whirl stopped after a few revolutions pays far less than one that lasts the
episode, as in the benchmark's default score (``whirl_ref_revs`` stands in for the passive
drop's revolutions, about 20 in the paper scene's 0.3 s episode). An episode's return is −Φ_T:
minus the benchmark cost of its KPIs, and the reward is dense (it arrives in the step in which a
new peak or a backward revolution happens). Re-levitation tasks add ``w_relevitate`` once, in
the step of re-levitation, and ``−w_time · control_dt / episode_time`` in every step before it
(re-levitating sooner pays).

The environments compute it from their kernel arrays (:func:`kpi_step`); the SB3 wrapper
``agents.learning.reward.KpiReward`` computes the same from the ``info`` entries with
:func:`kpi_potential` and :func:`kpi_reward`.
"""
from __future__ import annotations

import difflib
import math
import numbers

import numpy as np

from physics.metrics import WHIRL_MIN_REVOLUTIONS

from . import kernels as K
from .info import PEAK_KEYS  # noqa: F401  (the info entries the potential is built from)

#: the ``reward_kwargs`` of ``reward="kpi"`` and their defaults
KPI_WEIGHTS = dict(w_whirl=0.5, w_verdict=0.0, w_severity=0.5, w_force=0.5, w_disp=0.5,
                   force_ref=1e4, disp_ref_um=800.0, whirl_ref_revs=20.0, w_relevitate=1.0,
                   w_time=1.0)
REFERENCES = ("force_ref", "disp_ref_um", "whirl_ref_revs")
REWARDS = ("default", "kpi")


def check_kpi_weights(kwargs: dict | None) -> dict:
    """The full weights of ``reward="kpi"``: ``KPI_WEIGHTS`` updated by ``kwargs``; ValueError
    for an unknown key (naming a close match), a negative weight or a reference <= 0."""
    kwargs = dict(kwargs or {})
    for key, value in kwargs.items():
        if key not in KPI_WEIGHTS:
            close = difflib.get_close_matches(str(key), list(KPI_WEIGHTS), n=1)
            hint = f" (did you mean {close[0]}?)" if close else ""
            raise ValueError(f"reward_kwargs: unknown key {key!r}{hint}; allowed: "
                             f"{', '.join(KPI_WEIGHTS)}")
        positive = key in REFERENCES
        real = isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))
        if not (real and math.isfinite(value) and (value > 0.0 if positive else value >= 0.0)):
            raise ValueError(f"reward_kwargs.{key} must be a finite number "
                             f"{'> 0' if positive else '>= 0'}, got {value!r}")
    return {**KPI_WEIGHTS, **{k: float(v) for k, v in kwargs.items()}}


def kpi_potential(revs, force_N, disp_um, w_whirl: float, w_force: float, w_disp: float,
                  force_ref: float, disp_ref_um: float, w_verdict: float = 0.0,
                  w_severity: float = 0.0, whirl_ref_revs: float = 20.0, **_):
    """Φ of the module docstring from the peak net backward revolutions, the peak contact force
    [N] and the maximum displacement [µm] (floats or arrays; other weights are ignored; the
    environments pass every weight, the defaults here are those of a bare call)."""
    revs = np.asarray(revs, dtype=float)
    return (w_whirl * np.minimum(revs, WHIRL_MIN_REVOLUTIONS) / WHIRL_MIN_REVOLUTIONS
            + w_verdict * (revs >= WHIRL_MIN_REVOLUTIONS)
            + w_severity * revs / whirl_ref_revs
            + w_force * np.asarray(force_N) / force_ref + w_disp * np.asarray(disp_um) / disp_ref_um)


def kpi_reward(phi_before, phi, relevitated_now, pending, w_relevitate: float, time_cost):
    """r_t = Φ_{t−1} − Φ_t, plus ``w_relevitate`` in the step of re-levitation, minus
    ``time_cost`` (w_time · dt / episode_time) in each step before it (``pending``)."""
    return (phi_before - phi + w_relevitate * np.asarray(relevitated_now, dtype=float)
            - time_cost * np.asarray(pending, dtype=float))


def kpi_step(out: np.ndarray, M: np.ndarray, C: np.ndarray, weights: dict, relevitate: bool):
    """The KPI reward of the step just taken by one environment (1-D kernel arrays) or a batch
    (2-D, one row each), from the running KPIs in ``M``; advances the potential kept in
    ``M[..., M_PHI]``."""
    phi = kpi_potential(M[..., K.M_REV_PEAK], M[..., K.M_PEAK_F], M[..., K.M_MAX_DISP] * 1e6,
                        **weights)
    before = M[..., K.M_PHI].copy()
    M[..., K.M_PHI] = phi
    if not relevitate:
        return before - phi
    horizon = C[..., K.C_T_END] - C[..., K.C_T_FAULT]
    time_cost = weights["w_time"] * C[..., K.C_DT] / horizon
    return kpi_reward(before, phi, out[..., K.O_RELEV] > 0.0, M[..., K.M_RELEV] == 0.0,
                      weights["w_relevitate"], time_cost)
