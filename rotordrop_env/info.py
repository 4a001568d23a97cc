"""The ``info`` of the environments, built from the kernel arrays of one environment or of a
batch (the single environment, the Gymnasium vector environment and the SB3 VecEnv all use
:func:`info_columns`).

The contract, which any RL library can rely on:

* the same keys at reset and at every step (for a given environment and its settings);
* every value a numpy scalar (single environment) or a numpy array with one entry per
  environment (batches): ``np.float64``, ``np.bool_`` or ``np.int64``, never a Python object;
* no NaN anywhere: a value that does not exist is the sentinel ``MISSING`` (-1.0), next to a
  boolean that says whether it exists (``kpi_relevitated`` for ``kpi_relevitation_time_s``),
  or a fixed property of the scene (``kpi_max_ball_load_N`` without Sopanen-Mikkola balls).

The ``kpi_*`` entries are the episode's KPIs so far: at the final step (terminated or
truncated, also by a ``TimeLimit``) they are the episode's KPIs.
"""
from __future__ import annotations

import numpy as np

from . import kernels as K

#: the value of an info entry that does not exist (no re-levitation, no ball model)
MISSING = -1.0
REWARD_TERMS = ("whirl", "contact", "displacement", "effort", "success", "failure")
_O_TERMS = (K.O_R_WHIRL, K.O_R_CONTACT, K.O_R_DISP, K.O_R_EFFORT, K.O_R_SUCCESS, K.O_R_FAILURE)
#: the running KPIs the KPI reward's potential is built from (rotordrop_env.reward)
PEAK_KEYS = ("kpi_peak_whirl_revolutions", "kpi_peak_contact_force_N", "kpi_max_displacement_um")
#: the components of ``info["cost"]`` (Safety-Gymnasium convention: a cost >= 0 per step);
#: ``cost_contact_validity`` is reserved for the contact law's validity and 0 for now
COST_TERMS = ("cost_stator_contact", "cost_bearing_overload", "cost_contact_validity")


def info_columns(out: np.ndarray, M: np.ndarray, C: np.ndarray, latency, relevitate: bool) -> dict:
    """The info entries from kernel outputs ``out``, monitor ``M`` and configuration ``C`` of
    one environment (1-D arrays: numpy scalars) or of N (2-D arrays, one row per environment:
    arrays of N). ``latency``: the observation latency of the episode (int or int array)."""
    col = lambda A, j: A[..., j]                                      # noqa: E731
    t = col(M, K.M_T) - col(C, K.C_T_FAULT)
    info = {"contact_force_N": col(out, K.O_FORCE)}
    for name, j in zip(REWARD_TERMS, _O_TERMS):
        info["reward_" + name] = col(out, j)
    info["time_s"] = t
    info["backward_whirl"] = col(M, K.M_WHIRL) > 0.0
    relev = col(M, K.M_RELEV) > 0.0
    if relevitate:
        info["relevitated"] = relev
    stator, overload = col(out, K.O_STATOR), col(out, K.O_OVERLOAD)
    validity = np.zeros_like(stator)
    info["cost"] = stator + overload + validity
    info["cost_stator_contact"] = stator
    info["cost_bearing_overload"] = overload
    info["cost_contact_validity"] = validity
    info["obs_latency_steps"] = np.asarray(latency, dtype=np.int64)
    coef = col(C, K.C_P_COEF)
    balls = coef >= 0.0
    q = col(M, K.M_PEAK_Q)
    info.update(
        kpi_backward_whirl=col(M, K.M_WHIRL) > 0.0,
        kpi_whirl_revolutions=np.maximum(col(M, K.M_REV1), col(M, K.M_REV2)),
        kpi_peak_whirl_revolutions=col(M, K.M_REV_PEAK),
        kpi_peak_contact_force_N=col(M, K.M_PEAK_F),
        kpi_max_displacement_um=col(M, K.M_MAX_DISP) * 1e6,
        kpi_relevitated=relev,
        kpi_relevitation_time_s=np.where(relev, col(M, K.M_RELEV_T), MISSING),
        kpi_control_effort=col(M, K.M_EFFORT),
        kpi_stator_contact=col(M, K.M_STATOR) > 0.0,
        kpi_bearing_overload=col(M, K.M_OVERLOAD) > 0.0,
        kpi_max_ball_load_N=np.where(balls, q, MISSING),
        kpi_max_contact_pressure_MPa=np.where(balls, np.abs(coef) * np.cbrt(q) * 1e-6, MISSING),
        kpi_episode_time_s=t.copy(),
    )
    if out.ndim == 1:                                 # one environment: numpy scalars
        return {k: v[()] if isinstance(v, np.ndarray) else v for k, v in info.items()}
    return {k: np.array(v, copy=True) if v.base is not None else v for k, v in info.items()}


def kpi_keys(info: dict) -> dict:
    """The ``kpi_*`` entries of ``info``."""
    return {k: v for k, v in info.items() if k.startswith("kpi_")}


def row_info(columns: dict, e: int) -> dict:
    """Environment ``e``'s info (numpy scalars) from the columns of a batch."""
    return {k: v[e] for k, v in columns.items()}
