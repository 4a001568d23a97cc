"""The rewards an environment is given (env kwarg ``reward``: an object, or its shorthand name
with ``reward_kwargs``): :class:`TermReward` (``"default"``) and :class:`KpiPotentialReward`
(``"kpi"``), looked up in :data:`REWARDS`.

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
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from physics.metrics import WHIRL_MIN_REVOLUTIONS

from . import kernels as K
from .info import PEAK_KEYS  # noqa: F401  (the info entries the potential is built from)

#: the ``reward_kwargs`` of ``reward="kpi"`` and their defaults
KPI_WEIGHTS = dict(w_whirl=0.5, w_verdict=0.0, w_severity=0.5, w_force=0.5, w_disp=0.5,
                   force_ref=1e4, disp_ref_um=800.0, whirl_ref_revs=20.0, w_relevitate=1.0,
                   w_time=1.0)
REFERENCES = ("force_ref", "disp_ref_um", "whirl_ref_revs")


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


# ------------------------------------------------------------------ the reward objects --
class Reward:
    """A reward of the environments: ``name`` (its shorthand for ``gym.make(id, reward=name)``)
    and :meth:`step`, the rewards of the step just taken from the kernel arrays of a batch
    (2-D, a row per environment; :meth:`one`: of one environment, 1-D). The per-step terms of
    ``info`` (``reward_whirl``...) are the kernel's, whatever the reward."""
    name = ""

    def step(self, out: np.ndarray, M: np.ndarray, C: np.ndarray, relevitate: bool) -> np.ndarray:
        raise NotImplementedError

    def one(self, out: np.ndarray, M: np.ndarray, C: np.ndarray, relevitate: bool) -> float:
        return float(self.step(out, M, C, relevitate))


@dataclass(frozen=True)
class TermReward(Reward):
    """``reward="default"``: the sum of the per-step terms the kernel computes with the
    environment's weights ``w_whirl``... (settable on the environment at any time).

    The terms (each also in ``info["reward_<term>"]``, whatever the reward):

    =============  ========================================================================
    term           value per control step
    =============  ========================================================================
    whirl          -w_whirl x backward orbit revolutions in the step (rotor relative to the
                   sleeve, counted beyond half the clearance; mean of the two planes)
    contact        -w_contact x peak contact force in the step / static weight share [N/N]
    displacement   -w_displacement x peak radial displacement at the retainer planes / clearance
    effort         -w_effort x mean squared normalised command (damper (C-C_min)/(C_max-C_min),
                   AMB control currents / current limit)
    success        +w_success once, when re-levitation is achieved (re-levitation envs)
    failure        -w_failure x remaining control steps, on termination (failing never pays:
                   10 per step is above the per-step cost of riding out a whirl, about 3)
    =============  ========================================================================
    """
    name = "default"

    def step(self, out, M, C, relevitate):
        return out[..., K.O_REWARD].copy()

    def one(self, out, M, C, relevitate):
        return float(out[K.O_REWARD])


@dataclass(frozen=True)
class KpiPotentialReward(Reward):
    """``reward="kpi"``: the decrease of the KPI potential (module docstring); ``weights``
    over ``KPI_WEIGHTS`` (``reward_kwargs``), checked by :func:`check_kpi_weights`."""
    weights: Mapping[str, float] = field(default_factory=dict)
    name = "kpi"

    def __post_init__(self):
        object.__setattr__(self, "weights", check_kpi_weights(self.weights))

    def step(self, out, M, C, relevitate):
        return kpi_step(out, M, C, self.weights, relevitate)


#: the rewards by shorthand name (``gym.make(id, reward="kpi", reward_kwargs={...})``)
REWARDS: dict[str, type[Reward]] = {"default": TermReward, "kpi": KpiPotentialReward}


def make_reward(reward: str | Reward, reward_kwargs: Mapping | None) -> Reward:
    """The reward object of the env kwargs ``reward`` (a :class:`Reward`, or a name of
    :data:`REWARDS`) and ``reward_kwargs`` (the named reward's weights); ValueError naming the
    rewards for an unknown name, and for ``reward_kwargs`` that would be dropped."""
    if reward_kwargs is not None and not isinstance(reward_kwargs, Mapping):
        raise ValueError(f"reward_kwargs = {reward_kwargs!r} must be a dict")
    if isinstance(reward, Reward):
        if reward_kwargs:
            raise ValueError(f"reward_kwargs are the weights of a reward given by name; the "
                             f"reward object {reward!r} has its own")
        return reward
    if not isinstance(reward, str) or reward not in REWARDS:
        raise ValueError(f"reward = {reward!r} is not a reward; the rewards are "
                         + ", ".join(repr(r) for r in REWARDS) + " or a rotordrop_env.reward.Reward")
    if reward == "kpi":
        return KpiPotentialReward(dict(reward_kwargs or {}))
    if reward_kwargs:
        raise ValueError(f"reward_kwargs are the weights of reward='kpi'; pass reward='kpi' "
                         f"or leave them out (reward={reward!r})")
    return REWARDS[reward]()
