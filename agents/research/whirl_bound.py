"""How few backward-whirl revolutions can *any* AMB current sequence reach once the power is back?

An oracle probe of the re-levitation task: for one fixed scenario (friction, unbalance phase,
power-return delay) a cross-entropy search (agents/benchmarking/search.py) optimises an open-loop correction
of the AMB currents, piecewise constant over ``--segments`` × ``--steps`` control steps from the
moment the power returns, added to a baseline controller's currents (default ``whirl-brake``)
and clipped to the current limit. The correction is allowed the full range [-2, 2], so it can
override the baseline entirely. The search knows the scenario in advance, which no controller
does: its peak revolutions are an empirical lower bound for what feedback control can reach
there. Cost: the peak net backward orbit revolutions of the episode (3 make a whirl).

As a cross-check that needs no search, the command also runs the baseline with its law in the
outer half of the clearance replaced by a saturated push (full current) at a fixed angle to the
orbit radius (0° outwards, 90° along a forward orbit, 180° to the centre), for 12 angles.

    rotordrop research whirl-bound --friction 0.48 --friction 0.53 --out out/whirl_bound

prints the baseline's and the best sequence's peak revolutions per scenario and writes
``whirl_bound.json``.
"""
from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from agents.benchmarking.benchmark import (RELEVITATION_ENVS, Entry, Scenario,
                              episode_kwargs, task_of)
from agents.control.controllers import _rot90, command_for, controller_class, controller_env_kwargs
from agents.control.open_loop import CurrentOverride, OpenLoopCorrection
from agents.control.plant import Plant
from agents.benchmarking.rollout import run_episodes
from agents.benchmarking.search import cross_entropy
from physics.metrics import WHIRL_MIN_REVOLUTIONS
from rotordrop_env.layout import CURRENT_ACTIONS


class SaturatedPush(CurrentOverride):
    """The baseline with its law in the outer half of the clearance replaced by a push of unit
    length at ``angle_deg`` to the orbit radius (module doc)."""

    def __init__(self, plant: Plant, baseline: str, angle_deg: float):
        super().__init__(plant, baseline)
        self.c, self.s = np.cos(np.radians(angle_deg)), np.sin(np.radians(angle_deg))

    def override(self, obs, currents):
        p = self.plant
        pos = p.positions(obs) / p.clearance
        r = np.repeat(np.hypot(pos[:, 0::2], pos[:, 1::2]), 2, axis=1)
        unit = pos / np.maximum(r, 1e-9)
        push = self.c * unit + self.s * p.spin_sign(obs)[:, None] * _rot90(unit)
        return np.where(r[0] > 0.5, np.clip(push[0], -1.0, 1.0), currents)


def bound(env_id: str, baseline: str, friction: float, phase: float, delay: float, segments: int,
          steps: int, iterations: int, population: int, std: float, seed: int) -> dict:
    entry = Entry(baseline, task_of(env_id), None,
                  controller_env_kwargs(controller_class(baseline), env_id))
    kw = episode_kwargs(entry, Scenario("bound", friction, env_kwargs={"power_return_time": delay}), phase)

    def kpis(make_actor) -> dict:
        return run_episodes(env_id, make_actor, [0], kw)[0].kpis

    def correction(theta):
        return kpis(lambda plant: OpenLoopCorrection(plant, baseline, steps, theta))

    shape = (segments, len(CURRENT_ACTIONS))
    base_kpis = correction(np.zeros(shape))
    _, theta, history = cross_entropy(
        lambda th: float(correction(th)["peak_whirl_revolutions"]), np.zeros(shape),
        np.full(shape, std), -2.0, 2.0, iterations, population, min(population, max(2, population // 5)),
        np.random.default_rng(seed), min_std=0.05, desc=f"mu={friction:g} phase={phase:g}")
    best_kpis = correction(theta)
    pushes = {phi: float(kpis(lambda plant: SaturatedPush(plant, baseline, phi))["peak_whirl_revolutions"])
              for phi in range(0, 360, 30)}
    return dict(friction=friction, phase_deg=phase, power_return_s=delay,
                baseline_peak_revolutions=base_kpis["peak_whirl_revolutions"],
                best_peak_revolutions=best_kpis["peak_whirl_revolutions"],
                best_backward_whirl=bool(best_kpis["backward_whirl"]),
                best_peak_contact_force_N=best_kpis["peak_contact_force_N"],
                best_push_deg=min(pushes, key=pushes.get), best_push_revolutions=min(pushes.values()),
                push_revolutions=pushes, history=[h["best_cost"] for h in history],
                correction=theta.tolist())


def run(a) -> None:
    """``rotordrop research whirl-bound`` with its parsed options ``a`` (agents/research)."""
    if a.env not in RELEVITATION_ENVS:
        raise ValueError(f"--env must be one of {', '.join(RELEVITATION_ENVS)}, got {a.env!r}")
    cls = controller_class(a.baseline)
    if cls is None or command_for(cls) != "continuous":
        raise ValueError(f"--baseline {a.baseline!r} must be a controller that commands the AMB "
                         f"currents (needs 'currents'), e.g. whirl-brake or pid-relevitate")
    t0 = time.perf_counter()
    rows = [bound(a.env, a.baseline, mu, ph, a.delay_ms * 1e-3, a.segments, a.steps, a.iterations,
                  a.population, a.std, a.seed)
            for mu in (a.friction or [0.48, 0.53]) for ph in (a.phase or [0.0, 180.0])]
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    settings = {k: v for k, v in vars(a).items() if k not in ("command", "research", "func")}
    rec = dict(env=a.env, baseline=a.baseline, settings=settings, whirl_revolutions=WHIRL_MIN_REVOLUTIONS,
               rows=rows, wall_time_s=time.perf_counter() - t0)
    (out / "whirl_bound.json").write_text(json.dumps(rec, indent=2))
    print(f"{a.env}, power back at {a.delay_ms:g} ms, open-loop correction of {a.baseline} over "
          f"{a.segments * a.steps} control steps ({a.iterations} x {a.population} episodes per scenario)")
    print(f"{'mu':>6}{'phase':>7}  {a.baseline + ' revs':>22}{'best revs':>11}{'whirl':>7}"
          f"{'best push':>16}")
    for r in rows:
        print(f"{r['friction']:6.2f}{r['phase_deg']:7.0f}  {r['baseline_peak_revolutions']:22.2f}"
              f"{r['best_peak_revolutions']:11.2f}{r['best_backward_whirl']!s:>7}"
              f"{r['best_push_revolutions']:8.2f} at {r['best_push_deg']:3d}°")
    print(f"wrote {out / 'whirl_bound.json'} in {rec['wall_time_s']:.0f} s")
