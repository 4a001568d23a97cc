"""Episode KPIs summarised over episodes, and the benchmark's overall score (docs/agents.md).

Per scenario s and controller c (KPIs averaged over the scenario's episodes):

    J(c, s) = W(c, s) + ½ F(c, s)/F(passive, s) + ½ D(c, s)/D(passive, s)
              [+ (1 − R(c, s)) + T_R(c, s)/T_episode    in tasks that can re-levitate]

with W the backward-whirl rate, F the peak contact force, D the maximum displacement, R the
re-levitation success rate and T_R the re-levitation time (T_episode when it failed). The
overall score of a controller over a scenario suite is

    score(c) = 100 (1 − Σ_s J(c, s) / Σ_s J(passive, s)),

so the passive drop scores 0, a controller that halves the passive cost scores 50, and a
controller worse than passive scores below 0.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

def fmt_or_dash(v, fmt: str) -> str:
    """``format(v, fmt)``, or "-" for a missing value (tables of evaluate and benchmark)."""
    return "-" if v is None else format(v, fmt)


def json_default(o):
    """``json.dumps(default=...)`` for numpy scalars and arrays in the KPI reports."""
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)


def finite_or_null(o):
    """``o`` (a JSON-able tree) with every non-finite float as None: JSON has no NaN/Infinity."""
    if isinstance(o, (np.generic, np.ndarray)):
        o = o.tolist() if isinstance(o, np.ndarray) else o.item()
    if isinstance(o, float):
        return o if math.isfinite(o) else None
    if isinstance(o, dict):
        return {k: finite_or_null(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [finite_or_null(v) for v in o]
    return o


def write_json(path: str | Path, report: dict, indent: int = 2) -> Path:
    """Write a report of the agents layer as strict JSON (null for NaN and infinities)."""
    path = Path(path)
    path.write_text(json.dumps(finite_or_null(report), indent=indent, default=json_default,
                               allow_nan=False))
    return path


def mean_finite(values) -> float | None:
    """Mean of the values that are neither None nor NaN; None when there are none."""
    vals = [float(v) for v in values if v is not None and not (isinstance(v, float) and math.isnan(v))]
    return float(np.mean(vals)) if vals else None


def summarize(episodes) -> dict:
    """Aggregate KPIs over episodes (rates for booleans, means and maxima for the rest)."""
    k = [e.kpis for e in episodes]
    out = dict(episodes=len(episodes),
               backward_whirl_rate=mean_finite(d.get("backward_whirl") for d in k),
               peak_contact_force_N=mean_finite(d.get("peak_contact_force_N") for d in k),
               peak_contact_force_N_max=max((float(d["peak_contact_force_N"]) for d in k
                                             if d.get("peak_contact_force_N") is not None), default=None),
               max_displacement_um=mean_finite(d.get("max_displacement_um") for d in k),
               max_contact_pressure_MPa=mean_finite(d.get("max_contact_pressure_MPa") for d in k),
               relevitation_success_rate=mean_finite(d.get("relevitated") for d in k),
               relevitation_time_s=mean_finite(d.get("relevitation_time_s") for d in k if d.get("relevitated")),
               control_effort=mean_finite(d.get("control_effort") for d in k),
               # episodes whose contact passed its law's validity bound (their force and
               # displacement KPIs are partly the laws' extrapolation; docs/environments.md)
               beyond_validity_rate=mean_finite(d.get("beyond_validity") for d in k),
               mean_return=mean_finite(e.reward for e in episodes))
    return out


def row_cost(row: dict, passive: dict, episode_time: float, relevitation: bool) -> float:
    """J(c, s) of the module docstring for one benchmark row against its passive row.

    Rows hold the scenario means ``backward_whirl`` (rate), ``peak_contact_force_N``,
    ``max_displacement_um``, ``relevitated`` (rate) and ``relevitation_time_s`` (mean over the
    successful episodes)."""
    cost = float(row["backward_whirl"])
    cost += 0.5 * row["peak_contact_force_N"] / max(passive["peak_contact_force_N"], 1e-9)
    cost += 0.5 * row["max_displacement_um"] / max(passive["max_displacement_um"], 1e-9)
    if relevitation:
        rate = row.get("relevitated") or 0.0
        t = row.get("relevitation_time_s")
        cost += (1.0 - rate) + (rate * (t if t is not None else episode_time)
                                + (1.0 - rate) * episode_time) / episode_time
    return cost


def overall_score(costs: list[float], passive_costs: list[float]) -> float:
    return 100.0 * (1.0 - sum(costs) / sum(passive_costs))
