"""``rotordrop ride-through``: how late may the AMB power return for a controller to stop the whirl?

Re-levitation can only start when the power is back (spec §5). Until then the rotor is on its
retainer bearings, and above the passive whirl threshold the backward whirl builds up (about
2 revolutions in the first 50 ms at μ = 0.48). This map runs a re-levitating controller on a
grid of friction coefficients × power-return delays (each at several unbalance phases, the
benchmark's episode settings) and reports per cell the peak backward-whirl revolutions (the
worst phase), the whirl rate, the peak contact force and the re-levitation rate. Its summary is
the **ride-through time** per friction: the longest grid delay up to which (every shorter
delay included) the controller re-levitates without a backward whirl in any phase. The passive
drop (power never returns) is the reference column. A controller class that does not command
re-levitation (no ``levitate`` or ``currents`` channel) is refused before the map starts.

Delays must lie inside the episode (``EPISODE_TIME``). A ride-through time equal to the longest
grid delay is a lower bound (``ride_through_lower_bound`` in the JSON, "≥" in the table): the map
does not tell how much longer the controller would hold.

Outputs: ``ride_through.json`` (grid, per-controller arrays, ride-through times),
``ride_through.csv`` (one row per controller, friction, delay) and ``ride_through.png``.
"""
from __future__ import annotations

import csv
import time
from pathlib import Path

import numpy as np

from .benchmark import (EPISODE_TIME, PHASES, RELEVITATION_ENVS, Entry, Scenario, check_unique_names,
                        controller_entry, episode_kwargs, task_of)
from ..control.controllers import BASELINES, Passive, command_for, controller_class, is_controller_spec
from ..learning.policies import load_shipped, policy_label, resolve, shipped_names
from .rollout import check_actor, run_episodes
from .score import write_json

FRICTIONS = tuple(round(0.30 + 0.05 * i, 2) for i in range(7))          # 0.30 ... 0.60
DELAYS = tuple(round(0.01 * i, 2) for i in range(11))                   # 0 ... 100 ms
QUICK = dict(frictions=(0.35, 0.45, 0.55), delays=(0.0, 0.03, 0.06), phases=(0.0, 180.0))
FIELDS = ("peak_whirl_revolutions", "backward_whirl", "peak_contact_force_N", "relevitated",
          "relevitation_time_s")


def controllers_for(env_id: str) -> list[str]:
    """The default controllers of a map: every re-levitating baseline and shipped policy of
    ``env_id`` (the passive drop is the reference column, not a controller)."""
    names = [name for name, cls in BASELINES.items() if command_for(cls) is not None]
    return names + [n for n in shipped_names() if load_shipped(n).env_id == env_id]


def _entry(spec: str, env_id: str) -> Entry:
    cls = controller_class(spec)
    if cls is not None:
        _check_relevitates(cls, spec)
        return controller_entry(cls, env_id)
    policy, trained_on = resolve(spec)
    if trained_on != env_id:
        advice = (f"pass --env {trained_on}" if trained_on in RELEVITATION_ENVS else
                  f"{trained_on} has no re-levitation, so ride-through cannot run it (it needs "
                  f"a policy of {' or '.join(RELEVITATION_ENVS)})")
        raise ValueError(f"policy {spec!r} was trained on {trained_on}, not on {env_id}; {advice}")
    return Entry(policy_label(spec, policy), task_of(env_id), policy.bound, dict(policy.env_kwargs))


def _check_relevitates(cls, spec: str) -> None:
    """Refuse a controller class that does not command re-levitation (no ``levitate`` or
    ``currents`` channel): the power return, which the map varies, does not reach it."""
    if command_for(cls) is None:
        raise ValueError(f"--policy {spec!r}: ride-through maps controllers that re-levitate "
                         f"(set the 'levitate' or 'currents' channel); {cls.name} commands "
                         f"{', '.join(cls.needs) + ' only' if cls.needs else 'nothing'}")


def _check_grid(name: str, values, lo: float, hi: float, shown: float = 1.0, unit: str = "",
                below_hi: bool = False) -> tuple[float, ...]:
    """Sorted unique grid values, each in [lo, hi] (or [lo, hi) with ``below_hi``); errors
    show values × ``shown`` in ``unit`` (the CLI's unit)."""
    values = tuple(float(v) for v in values)
    if not values:
        raise ValueError(f"{name} needs at least one value")
    bad = [round(v * shown, 9) for v in values
           if not (np.isfinite(v) and lo <= v and (v < hi if below_hi else v <= hi))]
    if bad:
        raise ValueError(f"{name} values {bad} are outside [{lo * shown:g}, {hi * shown:g}"
                         f"{')' if below_hi else ']'}{unit}")
    return tuple(sorted(set(values)))


def _scene_range(key: str) -> tuple[float, float]:
    """The allowed range [lo, hi] of a scene parameter (physics.scene's table)."""
    from physics.scene import param_meta
    meta = param_meta(key)
    return meta["lo"], meta["hi"]


def ride_through_times(peak_revs: np.ndarray, relevitated: np.ndarray, delays, threshold: float):
    """Per friction (rows), the longest delay d_k such that every delay ≤ d_k re-levitates in
    every phase with peak revolutions below ``threshold``; None when even the first fails."""
    ok = (peak_revs < threshold) & (relevitated >= 1.0)
    out = []
    for row in ok:
        n = len(row) if row.all() else int(np.argmin(row))
        out.append(delays[n - 1] if n > 0 else None)
    return out


def ride_through(out: str | Path, env_id: str = "RotorDrop-Relevitate-v1",
                 policies: list[str] | None = None, frictions=FRICTIONS, delays=DELAYS,
                 phases=PHASES, progress: bool = True, plots: bool = True) -> dict:
    """Run the map (module doc) and write its JSON, CSV and figure into ``out``."""
    from tqdm.auto import tqdm

    from physics.metrics import WHIRL_MIN_REVOLUTIONS
    if env_id not in RELEVITATION_ENVS:
        raise ValueError(f"--env must be a re-levitation environment ({', '.join(RELEVITATION_ENVS)}), "
                         f"got {env_id!r}")
    frictions = _check_grid("--friction", frictions, *_scene_range("contact.friction"))
    delays = _check_grid("--delay-ms", delays, 0.0, EPISODE_TIME, shown=1e3, below_hi=True,
                         unit=f" ms (the power has to return within the {1e3 * EPISODE_TIME:g} ms episode)")
    phases = _check_grid("--phase", phases, -360.0, 360.0)
    specs = list(dict.fromkeys(policies or controllers_for(env_id)))
    entries = check_unique_names([_entry(p, env_id) for p in specs])
    for spec, entry in zip(specs, entries):
        if is_controller_spec(spec):
            check_actor(env_id, entry.make, entry.env_kwargs)      # fail fast: a user's class
    passive = Entry(Passive.name, task_of(env_id), Passive, {})
    t0 = time.perf_counter()
    bar = tqdm(total=len(phases) * len(frictions) * (1 + len(entries) * len(delays)),
               desc="ride-through map", unit="ep", disable=not progress)

    def cell(entry: Entry, mu: float, delay: float | None) -> dict:
        sc = Scenario("cell", mu, env_kwargs={} if delay is None else {"power_return_time": delay})
        kpis = []
        for ph in phases:
            kpis += [e.kpis for e in run_episodes(env_id, entry.make, [0], episode_kwargs(entry, sc, ph))]
            bar.update(1)
        return dict(peak_whirl_revolutions=max(k["peak_whirl_revolutions"] for k in kpis),
                    backward_whirl=float(np.mean([bool(k["backward_whirl"]) for k in kpis])),
                    peak_contact_force_N=max(k["peak_contact_force_N"] for k in kpis),
                    relevitated=float(np.mean([bool(k["relevitated"]) for k in kpis])),
                    relevitation_time_s=_mean_or_none([k["relevitation_time_s"] for k in kpis
                                                       if k["relevitated"]]))

    reference = [cell(passive, mu, None) for mu in frictions]
    maps, rows = {}, []
    for entry in entries:
        grid = [[cell(entry, mu, d) for d in delays] for mu in frictions]
        arrays = {f: [[c[f] for c in r] for r in grid] for f in FIELDS}
        revs = np.array(arrays["peak_whirl_revolutions"], dtype=float)
        relev = np.array(arrays["relevitated"], dtype=float)
        arrays["ride_through_s"] = ride_through_times(revs, relev, delays, WHIRL_MIN_REVOLUTIONS)
        arrays["ride_through_lower_bound"] = [t == delays[-1] for t in arrays["ride_through_s"]]
        maps[entry.name] = arrays
        rows += [dict(controller=entry.name, friction=mu, power_return_s=d, **c)
                 for mu, r in zip(frictions, grid) for d, c in zip(delays, r)]
    bar.close()
    rows += [dict(controller=Passive.name, friction=mu, power_return_s=None, **c)
             for mu, c in zip(frictions, reference)]
    report = dict(env_id=env_id, phases_deg=list(phases), frictions=list(frictions),
                  power_return_s=list(delays), whirl_revolutions=WHIRL_MIN_REVOLUTIONS,
                  passive={f: [c[f] for c in reference] for f in FIELDS}, controllers=maps,
                  wall_time_s=time.perf_counter() - t0)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "ride_through.json", report)
    with open(out / "ride_through.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["controller", "friction", "power_return_s", *FIELDS])
        w.writeheader()
        w.writerows(rows)
    files = ["ride_through.json", "ride_through.csv"]
    if plots:
        from .plots import plot_ride_through
        files.append(plot_ride_through(report, out).name)
    report["files"] = files
    report["out"] = str(out)
    return report


def _mean_or_none(values):
    return float(np.mean(values)) if values else None


def summary_table(report: dict) -> str:
    """Markdown: ride-through time [ms] per controller (rows) and friction (columns), with the
    passive drop's whirl rate as the first row; "≥" when the longest delay of the grid held
    (``ride_through_lower_bound``: the map does not tell how much longer would hold)."""
    mus = report["frictions"]
    head = "| controller | " + " | ".join(f"μ={m:g}" for m in mus) + " |\n"
    head += "|---|" + "---:|" * len(mus) + "\n"
    body = "| passive whirl rate | " + " | ".join(f"{w:.2f}" for w in report["passive"]["backward_whirl"]) + " |\n"
    for name, m in report["controllers"].items():
        body += f"| {name} | " + " | ".join(
            "none" if t is None else ("≥ " if low else "") + f"{1e3 * t:.0f} ms"
            for t, low in zip(m["ride_through_s"], m["ride_through_lower_bound"])) + " |\n"
    return head + body
