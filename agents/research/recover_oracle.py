"""``rotordrop research recover-oracle``: how many of the Recover task's events a plan that
knows the event recovers, as a search over a pool of designed plans in their seats.

Per test event of a recover suite (the first ``--events`` of ``rotordrop benchmark --suite
recover``'s), every plan of a fixed pool (:func:`plan_pool`) runs in its seat on the suite's
env kwargs, and the event is scored by the plan that did best on it (recovered first, then the
lower peak contact force: :func:`agents.benchmarking.headroom.best_rows` of the cost
:func:`event_cost`), as if the plan had been picked for that event in advance. The pool, per
seat (each plan a designed law with stated constants, :class:`Plan`):

* supervisor seat (over the built-in PID, 1 ms step): the PID (``inner-loop``, the reference);
  constant gain and radial reference offset commands from the start (``InnerLoop``'s grid);
  ``sync-phase-search`` at four amplitudes; a synchronous offset of one fixed phase (eight
  phases x three amplitudes) held from the detection of persistent contact; ``sync-motion-comp``
  at three gains x three leads; a PID gain command held from the detection
  (:class:`GainOnContact`); the search and the motion compensation with an eager watch;
* controller seat (raw currents, 0.2 ms step): ``pid-relevitate``; ``sync-current-search`` at
  three amplitudes; a synchronous current of one fixed phase (eight phases x two amplitudes)
  held from the detection; a release and re-levitation from the detection (the currents off
  for 5, 20 or 50 ms, then ``pid-relevitate``'s ramped lift: :class:`ReleaseOnContact`).

It is a search, not a bound: another law, a time-varying plan or a finer grid may recover
more. The report gives the recovered fraction of the per-event best (per seat and over both),
of each family's per-event best and of the best single plan (one plan for all events, chosen
*on the test events*: an optimistic figure for a designed law, which must be chosen on
validation events), each with its binomial SE, Wilson 95 % interval and the paired bootstrap
difference against the PID (:data:`agents.benchmarking.score.BOOTSTRAP_RESAMPLES`, seed
:data:`~agents.benchmarking.score.BOOTSTRAP_SEED`), on all events and split into the events
the PID leaves in persistent contact although a contact-free steady state exists for them (a
shock or a transient load on a machine the PID holds contact-free without the event,
:func:`agents.benchmarking.recover.calm_levitation`) and the others.

    rotordrop research recover-oracle --events 100 --seat supervisor --out out/recover-oracle

writes ``oracle_recover.json`` (settings, the pool, each plan's events, the summary),
``oracle_recover.csv`` (per event: kind, group, the PID's outcome, the best plan and how many
plans recover it) and ``oracle_recover.png`` (the recovered fractions with their intervals).
"""
from __future__ import annotations

import csv
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..benchmarking.headroom import best_rows
from ..benchmarking.recover import (ENV_ID, REFERENCE, TIE_FORCE_N, calm_levitation,
                                    paired_bootstrap, rate, run_row)
from ..benchmarking.score import BOOTSTRAP_SEED, write_json
from ..control.controllers import (SEARCH, InnerLoop, PidRelevitate, Searching, SyncCurrentSearch,
                                   SyncMotionCompensation, SyncPhaseSearch, supervisor_action,
                                   with_constants)
from ..control.seats import seat_of

SEAT_NAMES = ("supervisor", "controller")
#: the fixed phases of the held synchronous plans [deg from the orbit radius, 90: forward]
PHASES = (0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0)
#: an eager watch: persistent contact after 20 % of 4 revolutions (the laws' own: 60 % of 8)
EAGER = dict(fraction=0.2, revolutions=4.0)
#: the event groups of the split (module doc)
GROUPS = ("stuck with a contact-free state", "other events")


class GainOnContact(SyncPhaseSearch):
    """A plan of the pool: on persistent contact (the synchronous laws' watch,
    :class:`agents.control.controllers.PhaseSearch`) the PID gain command ``scale`` (gains x
    2^(scale x the env's octaves)) held until the orbit has stayed inside ``r_contact`` for
    ``release`` revolutions, with ``sync-phase-search``'s offset of ``amplitude`` at the
    phases searched (amplitude 0: the gain alone)."""

    name = "gain-on-contact"
    GAINS = dict(SEARCH, amplitude=0.0, scale=0.0, phases=(180.0,))

    def __init__(self, plant, **gains):
        super().__init__(plant, **gains)
        supervisor_action("scale", self.g["scale"])

    def commands(self, obs):
        out = super().commands(obs)
        active = self.search.active
        out["gain"] = np.where(active, self.g["scale"], out["gain"])
        return out


class ReleaseOnContact(Searching, PidRelevitate):
    """A plan of the pool (controller seat): on persistent contact (the synchronous laws'
    watch) the AMB currents are set to zero for ``off`` seconds (the rotor leaves the
    contact-stiffened synchronous state and settles on its retainer bearing), then
    ``pid-relevitate``'s own PID lifts it again from where it lies, on its ramp; the watch
    restarts once the orbit has stayed free for ``release`` revolutions."""

    name = "release-on-contact"
    GAINS = dict(SEARCH, off=0.02, phases=(180.0,))

    def __init__(self, plant, **gains):
        super().__init__(plant)
        self.start_search(plant, gains)
        self.released = np.zeros(0)

    def reset(self, n, which=None):
        super().reset(n, which)
        if which is None or len(self.released) != n:
            self.released = np.full(n, np.nan)
        else:
            self.released[which] = np.nan

    def commands(self, obs):
        out = super().commands(obs)
        active, _ = self.search.step(obs, self.t)
        self.released[~active] = np.nan
        start = active & np.isnan(self.released)
        self.released[start] = self.t[start]
        off = active & (self.t - self.released < self.g["off"])
        self.on_t[off] = np.nan                 # the PID restarts, ramped, once the time is over
        out["currents"] = np.where(off[:, None], 0.0, out["currents"])
        return out


@dataclass(frozen=True)
class Plan:
    """One member of the pool: a designed law (a controller class) with its constants
    ``constants`` over the class's, named ``name``, of the pool family ``family``."""
    name: str
    family: str
    law: type
    constants: dict = field(default_factory=dict)

    @property
    def seat(self) -> str:
        return seat_of(self.law).name

    def controller(self) -> type:
        """The law as a controller class whose class constants are this plan's."""
        return with_constants(self.law, self.constants, self.name)


def _f(v: float) -> str:
    return f"{v:g}"


def plan_pool(seats=SEAT_NAMES) -> list[Plan]:
    """The pool of the module doc for ``seats`` (``supervisor``, ``controller``), the reference
    ``inner-loop`` first; ValueError for an unknown or empty seat list."""
    seats = tuple(seats)
    if not seats or any(s not in SEAT_NAMES for s in seats) or len(set(seats)) != len(seats):
        raise ValueError(f"--seat = {list(seats)!r} must name each of "
                         f"{', '.join(SEAT_NAMES)} at most once, at least one")
    pool = [Plan(REFERENCE, "PID (reference)", InnerLoop)]
    if "supervisor" in seats:
        pool += [Plan(f"constant g{_f(g)} r{_f(r)}", "constant gain/offset from the start",
                      InnerLoop, {"gain": g, "offset_r": r})
                 for g in (-1.0, -0.5, 0.0, 0.5, 1.0) for r in (0.0, -0.25, -0.5) if g or r]
        pool += [Plan(f"sync-phase-search A{_f(a)}", "sync-phase-search", SyncPhaseSearch,
                      {"amplitude": a}) for a in (0.1, 0.25, 0.5, 1.0)]
        pool += [Plan(f"held phase {_f(p)} A{_f(a)}", "offset of a fixed phase from detection",
                      SyncPhaseSearch, {"amplitude": a, "phases": (p,)})
                 for p in PHASES for a in (0.25, 0.5, 1.0)]
        pool += [Plan(f"sync-motion-comp k{_f(k)} lead{_f(d)}", "sync-motion-comp",
                      SyncMotionCompensation, {"gain": k, "lead": d})
                 for k in (0.3, 0.6, 1.0) for d in (-0.5, 0.0, 0.5)]
        pool += [Plan(f"gain-on-contact s{_f(s)}", "gain held from detection", GainOnContact,
                      {"scale": s}) for s in (-1.0, -0.5, 0.5, 1.0)]
        pool += [Plan("sync-phase-search A0.5 eager", "eager watch", SyncPhaseSearch,
                      {"amplitude": 0.5, **EAGER}),
                 Plan("sync-motion-comp k0.6 eager", "eager watch", SyncMotionCompensation,
                      {"gain": 0.6, **EAGER})]
    if "controller" in seats:
        pool += [Plan("pid-relevitate", "own PID (controller seat)", PidRelevitate)]
        pool += [Plan(f"sync-current-search A{_f(a)}", "sync-current-search", SyncCurrentSearch,
                      {"amplitude": a}) for a in (0.3, 0.6, 1.0)]
        pool += [Plan(f"held current phase {_f(p)} A{_f(a)}", "current of a fixed phase from "
                      "detection", SyncCurrentSearch, {"amplitude": a, "phases": (p,)})
                 for p in PHASES for a in (0.6, 1.0)]
        pool += [Plan(f"release {_f(1e3 * t)} ms", "release and re-levitation from detection",
                      ReleaseOnContact, {"off": t}) for t in (0.005, 0.02, 0.05)]
    return pool


def event_cost(recovered: np.ndarray, force: np.ndarray) -> np.ndarray:
    """A plan's cost on an event: 1 unless recovered, plus F / (F + 10 kN) / 2 of its peak
    contact force F (< 1/2: a recovery always wins, then the gentler one)."""
    force = np.asarray(force, float)
    return (~np.asarray(recovered, bool)).astype(float) + 0.5 * force / (force + TIE_FORCE_N)


def compare(x: np.ndarray, ref: np.ndarray) -> dict:
    """A recovered-or-not column's rate and its paired difference against ``ref``'s."""
    if not len(x):
        return {"events": 0}
    return {"events": int(len(x)), "recovered": rate(x),
            "vs_reference": paired_bootstrap(x, ref, np.random.default_rng(BOOTSTRAP_SEED))}


def summary(pool: list[Plan], rec: np.ndarray, force: np.ndarray, stuck: np.ndarray) -> dict:
    """The rows of the report (module doc) from the plans' recovered (plans x events) and
    peak-force matrices, on all events and on the two groups of ``stuck``."""
    names = [p.name for p in pool]
    cost = event_cost(rec, force)
    ref = rec[names.index(REFERENCE)]
    columns = {REFERENCE: ref}
    if "sync-phase-search A0.25" in names:
        columns["sync-phase-search (the leaderboard's constants)"] = rec[
            names.index("sync-phase-search A0.25")]
    single = int(np.argmax(rec.sum(axis=1) - 1e-9 * cost.sum(axis=1)))
    columns[f"best single plan on test ({names[single]}; optimistic)"] = rec[single]
    for fam in dict.fromkeys(p.family for p in pool):
        if fam == "PID (reference)":
            continue
        idx = [i for i, p in enumerate(pool) if p.family == fam]
        columns[f"per-event best: {fam}"] = rec[idx][best_rows(cost[idx]), np.arange(rec.shape[1])]
    for seat in SEAT_NAMES:
        idx = [i for i, p in enumerate(pool) if p.seat == seat]
        if len(idx) > 1:
            columns[f"per-event best, {seat} seat"] = rec[idx][best_rows(cost[idx]),
                                                               np.arange(rec.shape[1])]
    columns["per-event best, all plans"] = rec[best_rows(cost), np.arange(rec.shape[1])]
    split = {"all events": np.ones(rec.shape[1], bool), GROUPS[0]: stuck, GROUPS[1]: ~stuck}
    return {label: {g: compare(col[m], ref[m]) for g, m in split.items()}
            for label, col in columns.items()}


def recover_oracle(out, suite: str = "recover", events: int = 100, seats=("supervisor",),
                   progress: bool = True) -> dict:
    """Run the pool on the first ``events`` test events of ``suite`` and write the outputs of
    the module doc into ``out``; returns the record."""
    from tqdm.auto import tqdm

    from ..benchmarking.suites import SUITES, RecoverSuite
    chosen = SUITES.get(suite)
    if not isinstance(chosen, RecoverSuite):
        raise ValueError(f"--suite {suite}: the recover oracle runs a recover suite's events "
                         "(recover, recover-robust)")
    if isinstance(events, bool) or int(events) != events or not 1 <= events <= chosen.size:
        raise ValueError(f"--events = {events!r} must be an integer in [1, {chosen.size}] "
                         f"(the {chosen.name} suite's test events)")
    pool = plan_pool(seats)
    seeds = chosen.test_seeds(int(events))
    t0 = time.perf_counter()
    runs, cpu = [], []
    for plan in tqdm(pool, desc="recover oracle", unit="plan", disable=not progress):
        records, c = run_row(plan.name, seeds, chosen.env_kwargs, law=plan.controller())
        runs.append(records)
        cpu.append(c)
    c0 = time.process_time()
    calm = calm_levitation(chosen, seeds)
    cpu_calm = time.process_time() - c0
    rec = np.array([[r["recovered"] for r in rs] for rs in runs])
    force = np.array([[r["peak_contact_force_N"] for r in rs] for rs in runs])
    pid = runs[0]
    stuck = np.array([r["persistent"] and r["event"] in ("shock", "load") and c
                      for r, c in zip(pid, calm)])
    best = best_rows(event_cost(rec, force))
    record = dict(
        settings=dict(suite=chosen.name, env_id=ENV_ID, events=int(events),
                      seeds=[seeds.start, seeds.stop - 1], seats=list(seats),
                      env_kwargs=chosen.env_kwargs),
        pool=[dict(name=p.name, family=p.family, law=p.law.name, seat=p.seat,
                   constants=p.constants, recovered=int(rec[i].sum()), cpu_s=cpu[i])
              for i, p in enumerate(pool)],
        calm=calm, stuck=stuck.tolist(), best_plan=[pool[i].name for i in best],
        recovered=rec.tolist(), peak_contact_force_N=force.tolist(),
        events=[{k: r[k] for k in ("seed", "event", "event_time_s")} for r in pid],
        summary=summary(pool, rec, force, stuck),
        cpu_s=dict(plans=float(sum(cpu)), calm=cpu_calm), wall_time_s=time.perf_counter() - t0)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "oracle_recover.json", record)
    with open(out / "oracle_recover.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["seed", "event", "group", "pid_recovered", "pid_persistent", "best_recovered",
                    "best_plan", "plans_recovering"])
        for j, r in enumerate(pid):
            w.writerow([r["seed"], r["event"], GROUPS[0] if stuck[j] else GROUPS[1],
                        int(r["recovered"]), int(r["persistent"]), int(rec[best[j], j]),
                        pool[best[j]].name, int(rec[:, j].sum())])
    plot(record, out / "oracle_recover.png")
    print(table(record))
    print(f"wrote {out / 'oracle_recover.json'}, oracle_recover.csv, oracle_recover.png in "
          f"{record['wall_time_s']:.0f} s ({record['cpu_s']['plans']:.0f} CPU-s for "
          f"{len(pool)} plans x {int(events)} events)")
    return record


def _cell(s: dict) -> str:
    if not s.get("events"):
        return "—"
    r, d = s["recovered"], s["vs_reference"]
    lo, hi = r["wilson95"]
    return (f"{100 * r['value']:.1f} ± {100 * r['se']:.1f} [{100 * lo:.0f}, {100 * hi:.0f}]; "
            f"Δ {100 * d['delta']:+.1f} ± {100 * d['se']:.1f}")


def table(record: dict) -> str:
    """The report as a markdown table: per row and event group, recovered % ± SE [Wilson 95 %]
    and Δ against the PID ± paired bootstrap SE (points)."""
    groups = list(next(iter(record["summary"].values())))
    sizes = {g: next(iter(record["summary"].values()))[g].get("events", 0) for g in groups}
    lines = ["| row | " + " | ".join(f"{g} ({sizes[g]})" for g in groups) + " |",
             "|---|" + "---:|" * len(groups)]
    for label, by in record["summary"].items():
        lines.append(f"| {label} | " + " | ".join(_cell(by[g]) for g in groups) + " |")
    return "\n".join(lines)


def plot(record: dict, path: Path) -> Path:
    """Recovered % with Wilson 95 % intervals per row (bars) and event group (colours)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = list(record["summary"])
    groups = list(record["summary"][rows[0]])
    fig, ax = plt.subplots(figsize=(10, 1.2 + 0.42 * len(rows)))
    h = 0.8 / len(groups)
    for k, g in enumerate(groups):
        y = np.arange(len(rows)) + (k - (len(groups) - 1) / 2) * h
        cells = [record["summary"][r][g] for r in rows]
        v = np.array([100 * c["recovered"]["value"] if c.get("events") else np.nan for c in cells])
        lo = np.array([100 * c["recovered"]["wilson95"][0] if c.get("events") else np.nan
                       for c in cells])
        hi = np.array([100 * c["recovered"]["wilson95"][1] if c.get("events") else np.nan
                       for c in cells])
        ax.barh(y, v, height=h, label=f"{g} ({cells[0].get('events', 0)} events)")
        ax.errorbar(v, y, xerr=[v - lo, hi - v], fmt="none", ecolor="k", capsize=2, lw=0.8)
    ax.set_yticks(range(len(rows)), rows, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("events recovered [%] (Wilson 95 % interval)")
    s = record["settings"]
    ax.set_title(f"Recover: plans that know the event\n({s['suite']} test events "
                 f"{s['seeds'][0]}-{s['seeds'][1]}; a search, not a bound)", fontsize=10)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.4, -0.06 - 1.0 / len(rows)),
              ncol=len(groups))
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def run(a) -> None:
    """``rotordrop research recover-oracle`` with its parsed options ``a`` (agents/research)."""
    recover_oracle(a.out, a.suite, a.events, a.seat or ("supervisor",), not a.quiet)


def main(argv=None) -> int:
    """``python -m agents.research.recover_oracle ORACLE.json``: print the report's table."""
    from ..benchmarking.recover import print_table
    return print_table(table, argv, "a recover-oracle report (oracle_recover.json)")


if __name__ == "__main__":
    raise SystemExit(main())
