"""The results page from committed data: ``python -m agents.benchmarking.results`` (or ``rotordrop results``).

Reads the benchmark output committed under ``docs/data/`` and the learning-curve CSVs under
``docs/img/`` and writes

* ``docs/results.md``: the leaderboards of the nominal suite, the robust suite and the hard
  benchmark (where their data exist) and the list of learning-curve figures, and
* the leaderboard block of ``README.md`` between ``<!-- leaderboard:start -->`` and
  ``<!-- leaderboard:end -->`` (the Full task of the nominal suite).

Data files (each written by the project's own commands; only what the tables need is kept):

=====================================  =======================================================
``docs/data/leaderboard-nominal.json``  ``rotordrop benchmark --out DIR``: ``DIR/benchmark.json``
``docs/data/leaderboard-robust.json``   ``rotordrop benchmark --suite robust --out DIR``: ``DIR/benchmark.json``
``docs/data/oracle-nominal.json``       ``rotordrop oracle --out DIR``: ``DIR/oracle.json``
``docs/data/oracle-robust.json``        ``rotordrop oracle --suite robust --out DIR``: ``DIR/oracle.json``
``docs/data/hard-<name>.json``          ``rotordrop evaluate ... --episodes 200 --seed 900000 --out DIR``: ``DIR/kpis.json``
``docs/data/hard-table.json``           the hard benchmark's algorithm table: per training run
                                        (``--hard-run VARIANT KPIS RUN``: the run's
                                        ``training.json`` and ``rotordrop evaluate``'s
                                        ``kpis.json`` of its model) and per designed reference
                                        (``--hard-ref VARIANT KPIS``) the per-drop outcomes and
                                        their summary, no trajectories
=====================================  =======================================================

After re-running a benchmark, hand its output to the command, which stores it and regenerates
the pages in one go::

    python -m agents.benchmarking.results --nominal out/bench/benchmark.json --robust out/robust/benchmark.json \\
        --oracle-nominal out/oracle/oracle.json --oracle-robust out/oracle-robust/oracle.json \\
        --hard out/hard-tqc/kpis.json
    python -m agents.benchmarking.results --hard-run noisy out/tqc-noisy-0/kpis.json runs/tqc-noisy-0 \
        --hard-ref noisy out/whirl-brake-noisy/kpis.json

Each leaderboard shows as a compact table, a figure of every row's Δ with its 95 % interval
(``docs/img/leaderboards/<suite>-<task>.png``, drawn from the CSV of the same numbers beside it)
and the full table one click away. ``--check`` writes nothing and exits 1 when the committed
pages or figure data differ from what the committed data give (the test suite runs it). The
tables need only the standard library; the figures, matplotlib.
"""
from __future__ import annotations

import argparse
import csv
import json
import re
import statistics
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DATA = Path("docs/data")
IMG = Path("docs/img")
RESULTS = Path("docs/results.md")
README = Path("README.md")
TASKS = Path("docs/tasks.md")
START, END = "<!-- leaderboard:start -->", "<!-- leaderboard:end -->"
#: the benchmark.json keys kept in docs/data (the per-episode ``rows`` are left out)
DROPPED_KEYS = ("rows",)
#: the kpis.json keys kept for the hard benchmark (the passive comparison is left out)
HARD_KEYS = ("policy", "env_id", "env_kwargs", "seeds", "summary", "episodes")
#: the hard benchmark's algorithm table (not a kpis.json: left out of the hard-*.json rows)
HARD_TABLE = "hard-table.json"
#: the algorithm table's variants: title, and the sensing env kwargs every entry must have
HARD_VARIANTS = {"nominal": ("nominal sensing (the env defaults)", {}),
                 "noisy": ("noisy and delayed sensing: `sensor_noise=1e-6` (1 µm), "
                           "`sensor_delay=1e-4` (0.1 ms)",
                           {"sensor_noise": 1e-6, "sensor_delay": 1e-4})}
SENSING = ("sensor_noise", "sensor_delay", "obs_latency_steps")
TASK_TITLES = {"damping": "Damping (`RotorDrop-Damping-v1`)",
               "relevitate": "Re-levitation (`RotorDrop-Relevitate-v1`)",
               "full": "Damping and re-levitation (`RotorDrop-Full-v1`)"}


# -- formatting --------------------------------------------------------------------------------
def _f(x, spec: str = ".2f") -> str:
    return "–" if x is None else format(x, spec)


def leaderboard_table(entries: list[dict], kind: bool = False, in_out: bool = True) -> list[str]:
    """One markdown leaderboard (the columns of ``rotordrop benchmark``'s leaderboard.md); the
    bootstrap columns (SE of the score, difference to the best designed row ± SE and its 95 %
    interval) where the data have them."""
    se = any(e.get("score_se") is not None for e in entries)
    ref = next((e["reference"] for e in entries if e.get("reference")), None)
    seat = any(e.get("seat") for e in entries)
    head = ["rank", "controller"] + (["kind"] if kind else []) + (["seat"] if seat else []) + ["score"]
    head += ["SE", f"Δ vs `{ref}` ± SE [95 %]"] if se else []
    head += (["in-dist.", "out-of-dist."] if in_out else [])
    head += ["whirl rate", "whirl where passive whirls", "peak F / passive (mean, max)",
             "disp. / passive", "relevitated", "stator contact"]
    align = ["---:", "---"] + (["---"] * (kind + seat)) + ["---:"] * (len(head) - 2 - kind - seat)
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join(align) + "|"]
    for i, e in enumerate(entries, 1):
        cells = [str(i), f"`{e['controller']}`"] + ([e.get("kind", "")] if kind else [])
        cells += [e.get("seat") or "–"] if seat else []
        cells.append(_f(e["score"]))
        if se:
            cells += se_cells(e)
        if in_out:
            cells += [_f(e.get("in_distribution_score")), _f(e.get("out_of_distribution_score"))]
        cells += [_f(e["whirl_rate"]), _f(e.get("whirl_rate_where_passive_whirls")),
                  f"{_f(e['force_ratio'])}, {_f(e['max_force_ratio'])}", _f(e["displacement_ratio"]),
                  _f(e.get("relevitation_rate")), _f(e["stator_contact_rate"])]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


#: the seat a row ran in when the data do not say (rows written before the field existed)
DEFAULT_SEAT = "supervisor"
#: the Δ figures of the leaderboards (PNG, with the CSV of the plotted numbers beside it)
FIGURES = IMG / "leaderboards"


def compact_table(entries: list[dict]) -> list[str]:
    """The leaderboard people read first: rank, controller, seat, score ± SE, Δ to the
    reference row with its 95 % interval, whirl rate and re-levitation rate."""
    ref = next((e["reference"] for e in entries if e.get("reference")), None)
    lines = [f"| rank | controller | seat | score ± SE | Δ vs `{ref}` [95 %] | whirl | "
             "re-levitated |", "|---:|---|---|---:|---:|---:|---:|"]
    for i, e in enumerate(entries, 1):
        diff = "–"
        if e.get("diff_ci95") is not None:
            lo, hi = e["diff_ci95"]
            diff = f"{e['diff_vs_reference']:+.2f} [{lo:+.2f}, {hi:+.2f}]"
        lines.append(f"| {i} | `{e['controller']}` | {e.get('seat') or DEFAULT_SEAT} | "
                     f"{_f(e['score'])} ± {_f(e.get('score_se'))} | {diff} | "
                     f"{_f(e['whirl_rate'])} | {_f(e.get('relevitation_rate'))} |")
    return lines


def leaderboard_view(entries: list[dict], slug: str, **full) -> list[str]:
    """A leaderboard on the site: the compact table, the figure of every row's Δ with its
    interval (``docs/img/leaderboards/<slug>.png``) and the full table one click away."""
    out = [f"Seat: the interface a row acts through (`{DEFAULT_SEAT}` where the data do not "
           f"record it). The figure's numbers are in `{(FIGURES / slug).as_posix()}.csv`; every "
           "column is one click below it.", "",
           '<div class="leaderboard" markdown>', ""] + compact_table(entries) + ["", "</div>", ""]
    if any(e.get("diff_ci95") is not None for e in entries):
        out += [f"![Δ of every row to the reference row with its 95 % interval]"
                f"({(FIGURES / slug).relative_to('docs').as_posix()}.png)", ""]
    out += ['??? info "Every column"', ""]
    out += ["    " + line for line in leaderboard_table(entries, **full)] + [""]
    return out


def delta_rows(entries: list[dict]) -> list[dict]:
    """The numbers a Δ figure plots: per row (rank order) its name, kind and Δ with its 95 %
    interval, to the reference row."""
    return [{"controller": e["controller"], "kind": e.get("kind", ""),
             "reference": e.get("reference") or "", "diff": repr(e["diff_vs_reference"]),
             "lo": repr(e["diff_ci95"][0]), "hi": repr(e["diff_ci95"][1])}
            for e in entries if e.get("diff_ci95") is not None]


def leaderboards(root: Path) -> dict[str, tuple[str, list[dict]]]:
    """slug -> (title, rows) of every leaderboard in the committed data."""
    out = {}
    nominal = _load(root / DATA / "leaderboard-nominal.json")
    if nominal:
        for task in _tasks(nominal):
            out[f"nominal-{task}"] = (f"nominal suite: {TASK_TITLES.get(task, task)}",
                                      [e for e in nominal["leaderboard"] if e["task"] == task])
    robust = _load(root / DATA / "leaderboard-robust.json")
    if robust:
        out["robust-full"] = (f"robust suite, {len(robust['scenarios'])} drops",
                              robust["leaderboard"])
    return out


def figure_data(root: Path) -> dict[Path, str]:
    """The CSV of each Δ figure (the text the PNG is drawn from)."""
    out = {}
    for slug, (_, entries) in leaderboards(root).items():
        rows = delta_rows(entries)
        if rows:
            lines = [",".join(rows[0])] + [",".join(r.values()) for r in rows]
            out[root / FIGURES / f"{slug}.csv"] = "\n".join(lines) + "\n"
    return out


def draw_figures(root: Path, csvs: list[Path]) -> list[Path]:
    """The Δ figure of each CSV (matplotlib, imported here: the tables need only the standard
    library)."""
    from .plots import plot_deltas
    titles = {slug: title for slug, (title, _) in leaderboards(root).items()}
    pngs = []
    for path in csvs:
        with path.open(newline="") as fh:
            rows = list(csv.DictReader(fh))
        title = titles.get(path.stem, path.stem).replace("`", "")
        pngs.append(plot_deltas(rows, title, path.with_suffix(".png")))
    return pngs


def se_cells(e: dict) -> list[str]:
    """The SE of a row's score and its difference to the reference row (± SE, [95 %])."""
    seeds = (f" (seeds {e['seed_mean']:.2f} ± {e['seed_std']:.2f}, n={e['seeds']})"
             if e.get("seed_std") is not None else "")
    if e.get("diff_se") is None:
        return [_f(e.get("score_se")) + seeds, "–"]
    lo, hi = e["diff_ci95"]
    return [_f(e.get("score_se")) + seeds,
            f"{e['diff_vs_reference']:+.2f} ± {e['diff_se']:.2f} [{lo:+.2f}, {hi:+.2f}]"]


def _tasks(report: dict) -> list[str]:
    return list(dict.fromkeys(e["task"] for e in report["leaderboard"]))


def nominal_section(report: dict, source: str) -> list[str]:
    thr = report.get("passive_threshold")
    out = ["## Nominal suite", "",
           f"`rotordrop benchmark{' --quick' if report.get('quick') else ''}` "
           f"(data: `{source}`). Passive whirl threshold μ\\* = {_f(thr, 'g')}; "
           f"{len(report['scenarios'])} scenarios at {len(report['phases_deg'])} unbalance "
           f"phases, {report['episode_time_s']:g} s after the fault; re-levitation tasks with "
           f"the power back {1e3 * report['power_return_s']:g} ms after the fault unless the "
           f"scenario says otherwise. {score_words(report)}", ""]
    for task in _tasks(report):
        out += [f"### {TASK_TITLES.get(task, task)}", ""]
        out += leaderboard_view([e for e in report["leaderboard"] if e["task"] == task],
                                f"nominal-{task}")
        out += seed_table([g for g in report.get("seed_groups") or []
                           if any(e["task"] == task and e["controller"] in g["members"]
                                  for e in report["leaderboard"])])
    return out


def score_words(report: dict) -> str:
    """What the score and its uncertainty columns are."""
    name = report.get("score")
    text = (f"Score{f' ({name})' if name else ''}: 100 (1 − Σ J / Σ J_passive); passive scores 0 "
            "([how it is scored](agents.md#benchmark-rotordrop-benchmark)).")
    b = report.get("bootstrap")
    if b:
        text += (f" SE: {b.get('method', 'paired bootstrap over the drops')} ({b['resamples']} resamples, seed "
                 f"{b['seed']}); Δ: the score minus the best designed row's, with its SE and 95 % "
                 "interval.")
    return text


def seed_table(groups: list[dict]) -> list[str]:
    """Learned configurations trained with several seeds: their scores, mean ± std."""
    if not groups:
        return []
    out = ["Learned configurations trained with several seeds:", "",
           "| configuration (seeds) | scores | mean ± std | mean − std |", "|---|---|---:|---:|"]
    for g in groups:
        out.append(f"| {', '.join(f'`{m}`' for m in g['members'])} | "
                   f"{', '.join(_f(s) for s in g['scores'])} | {_f(g['mean'])} ± {_f(g['std'])} | "
                   f"{_f(g['mean_minus_std'])} |")
    return out + [""]


def sample_rate_phrase(d: dict) -> str:
    """", noise sampled at 10 kHz" from a robust distribution record (empty for a record made
    before the sensors had a sample rate: noise held per control step)."""
    rate = d.get("sensor_sample_rate_hz")
    return "" if rate is None else f", noise sampled at {rate / 1e3:g} kHz"


def robust_section(report: dict, source: str) -> list[str]:
    d = report.get("distribution", {})
    seeds = d.get("scenario_seeds", [None, None])
    out = ["## Robust suite", "",
           f"`rotordrop benchmark --suite robust{' --quick' if report.get('quick') else ''}` "
           f"(data: `{source}`): {len(report['scenarios'])} drops of `RotorDrop-Full-v1` "
           f"(scenario seeds {seeds[0]}–{seeds[1]}) with {_f(1e6 * d.get('sensor_noise_m', 0), 'g')} µm "
           f"sensor noise{sample_rate_phrase(d)}, "
           + (f"{'–'.join(f'{1e3 * v:g}' for v in d['sensor_delay_s'])} ms sensor delay (every "
              "controller), " if d.get("sensor_delay_s") else "")
           + f"{'–'.join(str(x) for x in d.get('latency_ms', []))} ms transport "
           "latency (rows in the supervisor seat), actuator spread and plant variation "
           "([what is perturbed](agents.md#robust-suite))."
           + (f" {score_words(report)}" if report.get("score") else ""), ""]
    out += leaderboard_view(report["leaderboard"], "robust-full", kind=True, in_out=False)
    out += seed_table(report.get("seed_groups") or [])
    return out


ORACLE_KEYS = ("command", "settings", "summary")


def _learned_names(root: Path) -> set[str]:
    return {p.stem for p in (root / "agents" / "policies").glob("*.zip")}


def oracle_section(reports: list[tuple[str, dict, str]], root: Path) -> list[str]:
    """The per-drop searched plan of the supervisor interface (``rotordrop oracle``) against the
    designed rows scored on the same drops. Learned rows are left out here (policies are replaced; their
    standing is in the leaderboards above)."""
    learned = _learned_names(root)
    out = ["## Oracle (searched open-loop plans)", "",
           "`rotordrop oracle` searches, per drop and knowing the drop in advance, an open-loop "
           "command sequence of the supervisor interface (a local search over a few segments "
           "from the best designed row's plan): its score is reachable on those drops, a lower "
           "bound on what that interface can reach, not a ceiling; a policy may do better "
           "([how](agents.md#the-supervisor-interface)). Designed rows scored on the same drops; a "
           "row `constant g=G r=R` is `inner-loop` with the constant gain action G and radial "
           "offset R clearance (`inner-loop-lift` is g=0.5 r=-0.5).", ""]
    for title, r, src in reports:
        s = r["settings"]
        rows = [e for e in r["summary"] if e["controller"] == "oracle"
                or (e["controller"] not in learned and "@" not in e["controller"])]
        designed = [e for e in rows if e["controller"] != "oracle"]
        oracle = next((e for e in rows if e["controller"] == "oracle"), None)
        best = max(designed, key=lambda e: e["score"]) if designed else None
        seed = s.get("scenario_seed")
        from rotordrop_env import ENV_IDS
        out += [f"### {title}", "",
                f"{s.get('scenarios')} drops (scenario seeds {seed}–{seed + s.get('scenarios', 1) - 1}), "
                f"search {s.get('population')} × {s.get('iterations')} per drop, "
                f"{s.get('score', 'legacy')} score, on `{s.get('env_id', 'RotorDrop-Full-v0')}`"
                + (" (an earlier environment version: its numbers are not comparable with the"
                   " leaderboards above)" if s.get("env_id", "RotorDrop-Full-v0") not in ENV_IDS
                   else "") + f" (data: `{src}`)."
                + (f" Searched plan over the best designed row (`{best['controller']}`): "
                   f"**{oracle['score'] - best['score']:+.2f}** points." if oracle and best else ""), "",
                *_oracle_header(rows)]
        for e in rows:
            out.append(f"| `{e['controller']}` | {_f(e['score'])} | " + _oracle_se(e, rows)
                       + f"{_f(e['whirl_rate'])} | {_f(e.get('whirl_rate_where_passive_whirls'))} | "
                       f"{_f(e.get('relevitation_rate'))} | {_f(e.get('mean_J'), '.3f')} |")
        out.append("")
    return out


def _oracle_header(rows: list[dict]) -> list[str]:
    """The oracle table's header: with the SE and Δ columns when the report carries them."""
    ref = next((e["reference"] for e in rows if e.get("reference")), None)
    se = [f"SE | Δ vs `{ref}` ± SE [95 %] | "] if ref else [""]
    return ["| row | score | " + se[0] + "whirl rate | whirl where passive whirls | re-levitated "
            "| mean J |", "|---|---:|" + ("---:|---:|" if ref else "") + "---:|---:|---:|---:|"]


def _oracle_se(e: dict, rows: list[dict]) -> str:
    """The SE and Δ cells of an oracle row, as the leaderboards' (:func:`se_cells`)."""
    if not any(r.get("reference") for r in rows):
        return ""
    return " | ".join(se_cells(e)) + " | "


def oracle_budget_section(report: dict, src: str) -> list[str]:
    """The oracle's score against its search budget on the same drops (``--oracle-budget``)."""
    runs = sorted(report["runs"], key=lambda r: r["rollouts_per_drop"])
    first = runs[0]
    out = ["### Search budget", "",
           f"The same {first['scenarios']} drops ({first['suite']}, scenario seeds "
           f"{first['scenario_seed']}–{first['scenario_seed'] + first['scenarios'] - 1}) searched "
           f"with growing budgets (population × generations); Δ: the searched plan minus the best "
           f"designed row on those drops, paired bootstrap over the drops (data: `{src}`).", "",
           "| population × generations | rollouts per drop | oracle score | SE | best designed row "
           "| Δ ± SE [95 %] | no gain over its start (drops) | wall time |",
           "|---|---:|---:|---:|---|---:|---:|---:|"]
    for r in runs:
        lo, hi = r["diff_ci95"]
        out.append(f"| {r['population']} × {r['iterations']} | {r['rollouts_per_drop']} | "
                   f"{_f(r['score'])} | {_f(r['score_se'])} | `{r['reference']}` "
                   f"{_f(r['reference_score'])} | {r['diff']:+.2f} ± {r['diff_se']:.2f} "
                   f"[{lo:+.2f}, {hi:+.2f}] | {r['unchanged']} / {r['scenarios']} | "
                   f"{r['wall_time_s']:.0f} s |")
    return out + [""]


def headroom_section(result: dict, src: str) -> list[str]:
    """Where the robust suite's points go (``python -m agents.benchmarking.headroom``)."""
    from .headroom import table
    return ["## Headroom on the robust suite", "",
            f"Each column's score split into the points each term of J costs (score = 100 − the "
            f"sum), on the {result['drops']} test drops of the robust leaderboard: the best "
            f"designed row `{result['reference']}`, the best learned row, each drop scored by the "
            f"best designed row on it and by the best row of all (knowing the drop), and every "
            f"term at its best over all rows at once with the re-levitation time at the power "
            f"return (optimistic: the terms trade against each other; not a bound). ± SE: paired "
            f"bootstrap over the drops ([how](agents.md#robust-suite); data: `{src}`).", "",
            table(result), ""]


def budget_run(report: dict) -> dict:
    """One row of the budget sweep from a ``rotordrop oracle`` oracle.json."""
    s = report["settings"]
    orc = next(e for e in report["summary"] if e["controller"] == "oracle")
    ref = next(e for e in report["summary"] if e["controller"] == orc["reference"])
    searched = [d["search"] for d in report["per_scenario"]]
    return dict(population=s["population"], iterations=s["iterations"],
                rollouts_per_drop=searched[0]["rollouts"],
                scenarios=s["scenarios"], scenario_seed=s["scenario_seed"],
                suite=s.get("suite", "nominal"), score=orc["score"], score_se=orc["score_se"],
                reference=orc["reference"], reference_score=ref["score"],
                diff=orc["diff_vs_reference"], diff_se=orc["diff_se"], diff_ci95=orc["diff_ci95"],
                unchanged=sum(d["J"] >= d["start_J"] for d in searched),
                wall_time_s=report["wall_time_s"])


def _quantile(values: list[float], q: float) -> float:
    v = sorted(values)
    k = (len(v) - 1) * q
    lo, hi = int(k), min(int(k) + 1, len(v) - 1)
    return v[lo] + (v[hi] - v[lo]) * (k - lo)


def hard_row(report: dict, source: str) -> str:
    eps = report["episodes"]
    s = report["summary"]
    after = _after_power_return_ms(eps)
    n_ok = sum(1 for e in eps if e.get("relevitated"))
    stator = [bool(e.get("stator_contact")) for e in eps if "stator_contact" in e]
    times = (f"{statistics.median(after):.1f} / {_quantile(after, 0.9):.1f} / {max(after):.1f} ms"
             if after else "–")
    seeds = report["seeds"]
    return (f"| `{report['policy']}` | {s['episodes']} (seeds {seeds[0]}–{seeds[-1]}) | "
            f"**{_f(s['relevitation_success_rate'])}** ({n_ok} / {len(eps)}) | {times} | "
            f"{_f(s['backward_whirl_rate'])} | {_f(sum(stator) / len(stator) if stator else None)} | "
            f"`{source}` |")


def hard_section(reports: list[tuple[dict, str]]) -> list[str]:
    out = ["## Hard benchmark", "",
           "Re-levitation on raw coil currents, learned from scratch within a budget of "
           f"{_budget()} environment steps per run "
           "([rules and commands](agents.md#hard-benchmark-raw-currents-from-scratch)); every "
           "row is `rotordrop evaluate` on the 200 held-out drops. The designed rows on the same "
           "interface are the references a learned entry is compared with: `whirl-brake` (the "
           "strongest designed raw-current law: PD centring with whirl-braking terms) and "
           "`pid-relevitate` (PD with gravity feed-forward and a ramped reference).", "",
           "| policy | drops | re-levitation rate | after the power return (median / 90 % / max) | "
           "whirl rate | stator contact | data |",
           "|---|---|---:|---:|---:|---:|---|"]
    out += [hard_row(r, src) for r, src in reports]
    return out + [""]


def _after_power_return_ms(eps: list[dict]) -> list[float]:
    return [1e3 * (e["relevitation_time_s"] - e["scenario"]["power_return_time"])
            for e in eps if e.get("relevitated") and e.get("relevitation_time_s") is not None
            and "power_return_time" in e.get("scenario", {})]


def hard_entry(variant: str, report: dict, source: str, run: Path | None = None) -> dict:
    """The algorithm table's record of one evaluation (a ``rotordrop evaluate`` kpis.json on
    the 200 held-out drops): per-drop re-levitation and whirl as 0/1 strings, the times after
    the power return (median, 90 %, max), the stator-contact rate, the sensing it ran with;
    with ``run`` (a training run directory) the run's algorithm, seed, steps, wall time and its
    own evaluation curve (steps, wall time, re-levitation rate of its 16 evaluation drops).
    ValueError when the sensing is not the variant's."""
    if variant not in HARD_VARIANTS:
        raise ValueError(f"variant must be one of {', '.join(HARD_VARIANTS)}, got {variant!r}")
    kw = report["env_kwargs"]
    sensing = {k: kw[k] for k in SENSING if kw.get(k)}
    if sensing != HARD_VARIANTS[variant][1]:
        raise ValueError(f"{source}: sensing {sensing or 'none'} is not the {variant} variant's "
                         f"({HARD_VARIANTS[variant][1] or 'none'})")
    eps = report["episodes"]
    after = _after_power_return_ms(eps)
    stator = [bool(e.get("stator_contact")) for e in eps]
    entry = dict(variant=variant, policy=report["policy"], env_id=report["env_id"],
                 command=kw.get("command"), sensing=sensing, source=source,
                 seeds=[report["seeds"][0], report["seeds"][-1]], episodes=len(eps),
                 relevitated="".join("1" if e.get("relevitated") else "0" for e in eps),
                 backward_whirl="".join("1" if e.get("backward_whirl") else "0" for e in eps),
                 after_power_return_ms=([round(statistics.median(after), 2),
                                         round(_quantile(after, 0.9), 2), round(max(after), 2)]
                                        if after else None),
                 stator_contact=sum(stator) / len(stator))
    if run is not None:
        info = json.loads((Path(run) / "training.json").read_text())
        entry.update(algo=info["algo"], seed=info["seed"], run=Path(run).name,
                     model="best" if report["policy"].endswith("/best") else "final",
                     time_limit_s=info.get("time_limit_s"),
                     timesteps=info["timesteps"], wall_time_s=round(info["wall_time_s"], 1),
                     steps_per_s=round(info["steps_per_s"], 1), command_line=info["command"],
                     curve=[[h["timesteps"], round(h["wall_time_s"], 1),
                             round(h.get("mean_relevitated", float("nan")), 4)]
                            for h in info["learning_curve"]])
    return entry


def store_hard_table(path: Path, runs: list[tuple[str, str, str]], refs: list[tuple[str, str]],
                     root: Path) -> Path:
    """Add (or replace) ``runs`` ((variant, kpis.json, run dir)) and ``refs`` ((variant,
    kpis.json)) in the algorithm table ``path`` (keyed by variant and algorithm and seed, or
    variant and policy)."""
    table = json.loads(path.read_text()) if path.exists() else {"runs": [], "references": []}

    def rel(p):
        p = Path(p).resolve()
        return p.relative_to(root.resolve()).as_posix() if p.is_relative_to(root.resolve()) else str(p)

    for variant, kpis, run in runs:
        e = hard_entry(variant, json.loads(Path(kpis).read_text()), rel(kpis), Path(run))
        table["runs"] = [r for r in table["runs"] if (r["variant"], r["algo"], r["seed"])
                         != (variant, e["algo"], e["seed"])] + [e]
    for variant, kpis in refs:
        e = hard_entry(variant, json.loads(Path(kpis).read_text()), rel(kpis))
        table["references"] = [r for r in table["references"]
                               if (r["variant"], r["policy"]) != (variant, e["policy"])] + [e]
    order = list(HARD_VARIANTS)
    table["runs"].sort(key=lambda r: (order.index(r["variant"]), r["algo"], r["seed"]))
    table["references"].sort(key=lambda r: (order.index(r["variant"]), r["policy"]))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(table, indent=1, sort_keys=True) + "\n")
    return path


def _rate(bits: str) -> float:
    return bits.count("1") / len(bits)


def _binomial_se(p: float, n: int) -> float:
    return (p * (1.0 - p) / n) ** 0.5


def _mean_std(values: list[float], spec: str = ".2f") -> str:
    """mean ± std (ddof 1) over seeds; the value alone for one."""
    if not values:
        return "–"
    if len(values) == 1:
        return format(values[0], spec)
    return f"{format(statistics.mean(values), spec)} ± {format(statistics.stdev(values), spec)}"


def hard_algorithm_rows(table: dict, variant: str) -> list[dict]:
    """Per algorithm of ``variant`` (seeds pooled) and per reference: the table's numbers."""
    rows = []
    runs = [r for r in table["runs"] if r["variant"] == variant]
    for algo in dict.fromkeys(r["algo"] for r in runs):
        mine = sorted((r for r in runs if r["algo"] == algo), key=lambda r: r["seed"])
        rates = [_rate(r["relevitated"]) for r in mine]
        rows.append(dict(
            name=algo, kind="learned", runs=mine, rates=rates,
            rate_mean=statistics.mean(rates),
            rate_std=statistics.stdev(rates) if len(rates) > 1 else None,
            ses=[_binomial_se(p, r["episodes"]) for p, r in zip(rates, mine)],
            medians=[r["after_power_return_ms"][0] for r in mine if r["after_power_return_ms"]],
            whirl=[_rate(r["backward_whirl"]) for r in mine],
            stator=[r["stator_contact"] for r in mine],
            steps=[r["timesteps"] for r in mine]))
    for ref in (r for r in table["references"] if r["variant"] == variant):
        p = _rate(ref["relevitated"])
        rows.append(dict(name=ref["policy"], kind="designed", runs=[ref], rates=[p],
                         rate_mean=p, rate_std=None, ses=[_binomial_se(p, ref["episodes"])],
                         medians=[ref["after_power_return_ms"][0]] if ref["after_power_return_ms"] else [],
                         whirl=[_rate(ref["backward_whirl"])], stator=[ref["stator_contact"]],
                         steps=[]))
    return rows


#: the hard benchmark's ranking rule: every run trains for this many environment steps (the
#: same for every algorithm, ``rotordrop train --timesteps``; wall time on shared cores is no
#: budget), at least ``HARD_MIN_SEEDS`` seeds per algorithm, ranked by the mean − std of the
#: re-levitation rate over the seeds
HARD_STEP_BUDGET = 100_000
HARD_MIN_SEEDS = 3
#: a run may overshoot the budget by one rollout / batch (SB3 stops at a whole rollout: PPO's
#: 8 × 512-step rollouts end at 102 400 steps)
HARD_STEP_SLACK = 0.05


def _within_budget(run: dict) -> bool:
    """Whether a training run of the algorithm table kept the rule: the step budget (up to one
    rollout over it) and no wall-time limit."""
    return (HARD_STEP_BUDGET <= run["timesteps"] <= HARD_STEP_BUDGET * (1 + HARD_STEP_SLACK)
            and not run.get("time_limit_s"))


def hard_ranking(table: dict, variant: str) -> list[dict]:
    """The algorithms of ``variant`` ranked by mean − std of the re-levitation rate over their
    seeds (best first); ValueError naming what breaks the rule (:data:`HARD_STEP_BUDGET`:
    runs whose step budgets differ or were cut by wall time, fewer than
    :data:`HARD_MIN_SEEDS` seeds)."""
    rows = [r for r in hard_algorithm_rows(table, variant) if r["kind"] == "learned"]
    problems = []
    for r in rows:
        off = [run["timesteps"] for run in r["runs"] if not _within_budget(run)]
        if off:
            problems.append(f"{r['name']}: {', '.join(f'{s // 1000} k' for s in off)} steps"
                            + (" under a wall-time limit" if any(run.get("time_limit_s")
                                                                for run in r["runs"]) else ""))
        if len(r["runs"]) < HARD_MIN_SEEDS:
            problems.append(f"{r['name']}: {len(r['runs'])} seed(s)")
    if problems:
        raise ValueError(f"the {variant} table ranks nothing: every run must train "
                         f"{HARD_STEP_BUDGET // 1000} k environment steps with no wall-time limit, "
                         f"at least {HARD_MIN_SEEDS} seeds per algorithm; "
                         + "; ".join(problems))
    for r in rows:
        r["mean_minus_std"] = r["rate_mean"] - (r["rate_std"] or 0.0)
    return sorted(rows, key=lambda r: -r["mean_minus_std"])


def _ranked(rows: list[dict]) -> str:
    return ", ".join(f"`{r['name']}` {r['mean_minus_std']:.2f}" for r in rows)


def hard_standing(table: dict) -> str:
    """The hard benchmark's standing as tasks.md states it, per variant: the ranking at the step
    budget (or why the table ranks nothing) and every algorithm's re-levitation rate over its
    seeds, beside the designed references on the same drops and sensing."""
    out = []
    for variant, (title, _) in HARD_VARIANTS.items():
        rows = hard_algorithm_rows(table, variant)
        learned = [r for r in rows if r["kind"] == "learned"]
        if not learned:
            continue
        try:
            verdict = f"ranked by mean − std over the seeds: {_ranked(hard_ranking(table, variant))}"
        except ValueError:
            verdict = "not a ranking ([why](results.md#algorithm-table))"
        rates = ", ".join(f"`{r['name']}` {_mean_std(r['rates'])} "
                          f"({', '.join(str(run['relevitated'].count('1')) for run in r['runs'])} "
                          f"/ {r['runs'][0]['episodes']} per seed)" for r in learned)
        refs = ", ".join(f"`{r['name']}` {r['runs'][0]['relevitated'].count('1')} / "
                         f"{r['runs'][0]['episodes']}" for r in rows if r["kind"] == "designed")
        out.append(f"**{variant.capitalize()}**: {title}. {_budget_text(rows)} Re-levitation "
                   f"rate, mean ± std over the seeds: {rates}; {verdict}. Designed references on "
                   f"the same drops: {refs}.")
    return "\n\n".join(out)


def _budget_text(rows: list[dict]) -> str:
    """What the learned runs of a variant trained for: the step budget, or the wall-clock
    limits that cut them (an older table)."""
    runs = [run for r in rows if r["kind"] == "learned" for run in r["runs"]]
    limits = sorted({run["time_limit_s"] for run in runs if run.get("time_limit_s")})
    if limits:
        return ("Runs stopped by a wall-clock limit of "
                + " / ".join(f"{b:g} s" for b in limits) + " (before the step budget was "
                "the rule), so each trained its own number of steps.")
    return f"Every run trained {_budget()} environment steps (up to one rollout more)."


def _budget() -> str:
    """:data:`HARD_STEP_BUDGET` as the docs write it (``100 000``)."""
    return f"{HARD_STEP_BUDGET:,}".replace(",", " ")


def hard_table_section(table: dict, source: str) -> list[str]:
    """The algorithm table of each variant: learned rows (mean ± std over seeds, per seed with its
    SE over the drops) and the designed references on the same drops and sensing."""
    drops = table["runs"][0]["episodes"]
    out = ["### Algorithm table", "",
           "Each learned row: at least 3 training runs (seeds 0, 1, 2, …) from random "
           "initialisation, one core per run (`--threads 1`), evaluated on the "
           f"{drops} held-out drops with the sensing it was trained with; the model evaluated is "
           "the run's `best/` (kept by the return on its own 16 evaluation drops, seed + 10 000), "
           "nothing selected on the held-out drops. Re-levitation rate and whirl rate: mean ± std "
           "(ddof 1) over the seeds; *per seed*: each seed's rate ± its binomial SE over the "
           f"{drops} drops, sqrt(p (1 − p) / {drops}); *after the power return*: the median over the "
           "re-levitated drops, mean ± std over the seeds that re-levitated any; *steps*: "
           "environment steps trained, per seed. Designed rows: the same "
           f"{drops} drops, the same sensing (the observations they act on carry the noise and the "
           "delay), one row each, its SE over the drops. Configs: "
           "`docs/experiments/configs/<algo>-currents[-noisy].yaml`; commands: "
           "[rules and commands](agents.md#hard-benchmark-raw-currents-from-scratch).", ""]
    for variant, (title, _) in HARD_VARIANTS.items():
        rows = hard_algorithm_rows(table, variant)
        if not rows:
            continue
        try:
            verdict = ("Ranking (mean − std over the seeds, the same step budget for every "
                       f"algorithm): {_ranked(hard_ranking(table, variant))}.")
        except ValueError as exc:
            verdict = f"Not a ranking: {exc}."
        out += [f"**{variant.capitalize()}**: {title}. {_budget_text(rows)} {verdict}", "",
                "| algorithm | kind | re-levitation rate (mean ± std) | per seed (± SE over the "
                f"{drops} drops) | after the power return, median [ms] | whirl rate (mean ± std) | "
                "stator contact | steps per seed |",
                "|---|---|---:|---:|---:|---:|---:|---:|"]
        for r in rows:
            per_seed = ", ".join(f"{p:.2f} ± {se:.2f}" for p, se in zip(r["rates"], r["ses"]))
            counts = ", ".join(f"{run['relevitated'].count('1')}" for run in r["runs"])
            counts += f" / {r['runs'][0]['episodes']}"
            out.append(
                f"| `{r['name']}` | {r['kind']} | **{_mean_std(r['rates'])}** | {per_seed} "
                f"({counts}) | {_mean_std(r['medians'], '.1f')} | {_mean_std(r['whirl'])} | "
                f"{statistics.mean(r['stator']):.2f} | "
                f"{', '.join(f'{s // 1000} k' for s in r['steps']) or '–'} |")
        out.append("")
    return out + [f"Data: `{source}` (per run and reference: the per-drop outcomes, the run's "
                  "steps, wall time and its own evaluation curve).", ""]


def learning_curves(root: Path) -> list[str]:
    """One row per curve of each learning-curve figure under docs/img (``learning-*.png``, and
    ``hard-*.png`` with a CSV): from the CSV beside the figure (``python -m
    agents.training.learning_curves`` writes it), the runs, the last step and the best point; and the
    pages that discuss the figure."""
    img, docs = root / IMG, root / "docs"
    pngs = sorted(img.glob("learning-*.png")) + sorted(
        p for p in img.glob("hard-*.png") if p.with_suffix(".csv").exists())
    pages = [docs / "agents.md"] + sorted((docs / "experiments").glob("*.md"))
    pages = [p for p in pages if p.exists()]
    out = ["## Learning curves", "",
           "Each figure is drawn by `python -m agents.training.learning_curves` from the runs' "
           "`training.json`, with a CSV beside it; the table gives, per curve, the best point of "
           "the mean over its runs (± the std over runs at that step).", "",
           "| figure | curve | runs | last step | best point | discussed in |",
           "|---|---|---:|---:|---|---|"]
    for png in pngs:
        rel = png.relative_to(docs).as_posix()
        seen = [p for p in pages if png.name in p.read_text()]
        where = ", ".join(f"[{p.stem}]({p.relative_to(docs).as_posix()})" for p in seen) or "–"
        c = png.with_suffix(".csv")
        if not c.exists():
            out.append(f"| [{png.name}]({rel}) | – | – | – | no CSV committed | {where} |")
            continue
        with c.open(newline="") as fh:
            rows = list(csv.DictReader(fh))
        qty = next(k[:-5] for k in rows[0] if k.endswith("_mean"))
        for i, label in enumerate(dict.fromkeys(r["label"] for r in rows)):
            mine = [r for r in rows if r["label"] == label]
            best = max(mine, key=lambda r: float(r[f"{qty}_mean"]))
            std = float(best.get(f"{qty}_std") or 0.0)
            point = (f"{qty} {float(best[f'{qty}_mean']):.4g}"
                     + (f" ± {std:.2g}" if int(best["runs"]) > 1 else "")
                     + f" at step {int(best['timesteps'])}")
            first = f"[{png.name}]({rel})" if i == 0 else ""
            out.append(f"| {first} | {label} | {max(int(r['runs']) for r in mine)} | "
                       f"{max(int(r['timesteps']) for r in mine)} | {point} | "
                       f"{where if i == 0 else ''} |")
    return out + [""]


# -- pages -------------------------------------------------------------------------------------
def _load(path: Path):
    return json.loads(path.read_text()) if path.exists() else None


def results_page(root: Path = ROOT) -> str:
    data = root / DATA
    lines = ["# Results", "",
             "<!-- Generated by `python -m agents.benchmarking.results` from docs/data/ and docs/img/: "
             "do not edit by hand. -->", "",
             "Every table on this page is generated from committed benchmark output by "
             "`python -m agents.benchmarking.results` (after re-running a benchmark: "
             "`rotordrop results --nominal out/bench/benchmark.json`, likewise `--robust`, "
             "`--oracle-nominal`, `--oracle-robust` and `--hard`; "
             "[the commands](agents.md#benchmark-results)). How the rows came to be is in the "
             "[experiment log](experiments/index.md).", ""]
    nominal = _load(data / "leaderboard-nominal.json")
    if nominal:
        lines += nominal_section(nominal, (DATA / "leaderboard-nominal.json").as_posix())
    robust = _load(data / "leaderboard-robust.json")
    if robust:
        lines += robust_section(robust, (DATA / "leaderboard-robust.json").as_posix())
    oracles = [(title, json.loads((data / name).read_text()), (DATA / name).as_posix())
               for title, name in (("Nominal drops", "oracle-nominal.json"),
                                   ("Robust suite", "oracle-robust.json"))
               if (data / name).exists()]
    if oracles:
        lines += oracle_section(oracles, root)
    room = _load(data / "headroom-robust.json")
    if room:
        lines += headroom_section(room, (DATA / "headroom-robust.json").as_posix())
    budget = _load(data / "oracle-budget.json")
    if budget:
        lines += oracle_budget_section(budget, (DATA / "oracle-budget.json").as_posix())
    hard = [(json.loads(p.read_text()), (DATA / p.name).as_posix())
            for p in sorted(data.glob("hard-*.json")) if p.name != HARD_TABLE]
    if hard:
        lines += hard_section(hard)
    table = _load(data / HARD_TABLE)
    if table:
        lines += hard_table_section(table, (DATA / HARD_TABLE).as_posix())
    lines += learning_curves(root)
    return "\n".join(lines).rstrip() + "\n"


def readme_block(root: Path = ROOT) -> str:
    """The README's leaderboard: the Full task of the nominal suite."""
    nominal = _load(root / DATA / "leaderboard-nominal.json")
    if not nominal:
        return "No benchmark data committed yet: see docs/results.md."
    full = [e for e in nominal["leaderboard"] if e["task"] == "full"]
    return "\n".join([f"`rotordrop benchmark`, damping and re-levitation together "
                      f"(`RotorDrop-Full-v1`, passive threshold μ\\* = {_f(nominal['passive_threshold'], 'g')}"
                      + (f", {nominal['score']} score; SE and Δ: "
                         f"{(nominal.get('bootstrap') or {}).get('method', 'paired bootstrap over the drops')}"
                         ", against the best designed row of any seat" if nominal.get("score") else "")
                      + "); every table: [docs/results.md](docs/results.md).", ""]
                     + leaderboard_table(full))


def readme_text(root: Path = ROOT) -> str:
    text = (root / README).read_text()
    pattern = re.compile(re.escape(START) + r".*?" + re.escape(END), flags=re.S)
    if not pattern.search(text):
        raise ValueError(f"README.md has no {START} ... {END} block")
    return pattern.sub(lambda _: f"{START}\n{readme_block(root)}\n{END}", text)


def store(src: str | Path, dest: Path, keep=None, drop=()) -> Path:
    """Copy a benchmark.json / kpis.json into docs/data, keeping what the tables need."""
    report = json.loads(Path(src).read_text())
    if keep is not None:
        report = {k: report[k] for k in keep if k in report}
    return write_report({k: v for k, v in report.items() if k not in drop}, dest)


def write_report(report: dict, dest: Path) -> Path:
    """``report`` as docs/data writes JSON (sorted keys, one-space indent)."""
    dest.parent.mkdir(parents=True, exist_ok=True)
    dest.write_text(json.dumps(report, indent=1, sort_keys=True) + "\n")
    return dest


#: docs/tasks.md's generated blocks: key -> (leaderboard file, task)
STANDINGS = {"damping": ("leaderboard-nominal.json", "damping"),
             "relevitate": ("leaderboard-nominal.json", "relevitate"),
             "full": ("leaderboard-nominal.json", "full"),
             "robust": ("leaderboard-robust.json", "full")}


def _cited(e: dict) -> str:
    """`` `name` (seat seat) score ± SE``: a row as tasks.md quotes it."""
    seat = f" ({e['seat']} seat)" if e.get("seat") else ""
    return f"`{e['controller']}`{seat} {e['score']:.2f}" + (
        f" ± {e['score_se']:.2f}" if e.get("score_se") is not None else "")


def standing(report: dict, task: str) -> str:
    """A task's standing from its leaderboard: the best designed row of any seat and the best
    learned row, its difference to it (paired bootstrap), its seeds (mean ± std, or one seed:
    reported, not judged) and, for a suite with a target, the target line."""
    rows = [e for e in report["leaderboard"] if e["task"] == task]
    designed = [e for e in rows if e.get("kind", "designed") == "designed" and e["controller"] != "passive"]
    learned = [e for e in rows if e.get("kind") == "learned"]
    if not designed:
        return "No designed row in the data."
    d = max(designed, key=lambda e: e["score"])
    out = [f"Best designed row (any seat): {_cited(d)}."]
    if learned:
        e = max(learned, key=lambda e: e["score"])
        rel = (f", {e['diff_vs_reference']:+.2f} ± {e['diff_se']:.2f} "
               f"[{e['diff_ci95'][0]:+.2f}, {e['diff_ci95'][1]:+.2f}] against "
               f"`{e['reference']}`" if e.get("diff_se") is not None else "")
        seeds = (f"; over its configuration's {e['seeds']} seeds {e['seed_mean']:.2f} ± "
                 f"{e['seed_std']:.2f} (mean ± std)" if e.get("seed_std") is not None else
                 "; one seed: reported, not judged")
        out.append(f"Best learned row: {_cited(e)}{rel}{seeds}.")
    t = report.get("target")
    if t:
        if t.get("met") is None:
            out.append(f"Target (mean − std over ≥ {t.get('min_seeds', 3)} seeds ≥ best designed "
                       f"+{t['margin']:g}): not judged, no learned configuration with "
                       f"{t.get('min_seeds', 3)} seeds in the data.")
        else:
            out.append(f"Target (mean − std over ≥ {t.get('min_seeds', 3)} seeds ≥ best designed "
                       f"+{t['margin']:g}): {t['best_learned_score']:.2f} against "
                       f"{t['best_designed_score'] + t['margin']:.2f}: "
                       f"{'met' if t['met'] else 'not met'}.")
    how = (report.get("bootstrap") or {}).get("method")
    if how:
        out.append(f"(± SE: {how}.)")
    return " ".join(out)


#: docs/tasks.md's learning tables: key -> a `rotordrop benchmark --suite robust --only ...`
#: report of learned seed groups beside their reference (``rotordrop results --learning KEY=FILE``)
LEARNING = {"controller-seat-residual": "learning-controller-seat-residual.json",
            "controller-seat-scratch": "learning-controller-seat-scratch.json",
            "supervisor-seat-residual": "learning-supervisor-seat-residual.json",
            "supervisor-seat-scratch": "learning-supervisor-seat-scratch.json"}


def store_learning(paths: list[str], dest: Path, prefix: str | None = None) -> Path:
    """Benchmark reports of learned seed groups on the same drops (one, or several run apart:
    :func:`agents.benchmarking.score.merged_groups`) stored as one learning report; with
    ``prefix``, only the learned rows and seed groups whose names start with it (one run that
    scored several configurations gives each table its own, the target judged on them)."""
    from .score import merged_groups, target
    reports = [json.loads(Path(p).read_text()) for p in paths]
    report = reports[0] if len(reports) == 1 else merged_groups(reports)
    if prefix:
        board = [e for e in report["leaderboard"]
                 if e["kind"] != "learned" or e["controller"].startswith(prefix)]
        groups = [g for g in report["seed_groups"]
                  if all(m.startswith(prefix) for m in g["members"])]
        if not groups:
            raise ValueError(f"no seed group of rows named {prefix}* in {', '.join(paths)}")
        report = {**report, "leaderboard": board, "seed_groups": groups,
                  "target": {**report["target"], **target(board, groups, report["target"]["margin"])}}
    return write_report({k: v for k, v in report.items() if k not in DROPPED_KEYS}, dest)


def learning_table(report: dict) -> str:
    """The learned configurations of a benchmark report (its seed groups) against the best
    designed row there: per seed the test score ± SE and the difference to that row (paired
    bootstrap), the seeds' mean ± std and mean − std, then the target line."""
    board = {e["controller"]: e for e in report["leaderboard"]}
    t = report["target"]
    ref = t["best_designed"]
    r = board[ref]
    lines = [f"{len(report['scenarios'])} test drops of `--suite {report['suite']}`; reference "
             f"`{ref}` on the same drops: {r['score']:.2f} ± {r['score_se']:.2f} "
             f"({r.get('seat') or '-'} seat); Δ: paired bootstrap against it.", "",
             "| configuration | seat | seeds | test score ± SE per seed | Δ ± SE per seed | "
             "mean ± std | mean − std |", "|---|---|---:|---|---|---:|---:|"]
    for g in report["seed_groups"]:
        rows = [board[m] for m in g["members"]]
        lines.append(f"| {_common_name(g['members'])} | {rows[0].get('seat') or '-'} | "
                     f"{len(rows)} | " + ", ".join(f"{e['score']:.2f} ± {e['score_se']:.2f}"
                                                    for e in rows)
                     + " | " + ", ".join(f"{e['diff_vs_reference']:+.2f} ± {e['diff_se']:.2f}"
                                         for e in rows)
                     + f" | {g['mean']:.2f} ± {g['std']:.2f} | {g['mean_minus_std']:.2f} |")
    verdict = ("not judged: no configuration with "
               f"{t['min_seeds']} seeds" if t["met"] is None else
               f"best configuration {t['best_learned_score']:.2f} (mean − std) against "
               f"{t['best_designed_score'] + t['margin']:.2f}: {'met' if t['met'] else 'not met'}")
    lines += ["", f"Target (mean − std over ≥ {t['min_seeds']} seeds ≥ best designed "
                  f"+{t['margin']:g}) on these drops: {verdict}."]
    return "\n".join(lines)


def _common_name(names: list[str]) -> str:
    """The configuration's name: what its members' names share, up to a separator."""
    import os
    prefix = os.path.commonprefix(names).rstrip("-_@s0123456789") or names[0]
    return f"`{prefix}`"


def _regenerate(text: str, kind: str, key: str, block: str) -> str:
    start, end = f"<!-- {kind}:{key}:start -->", f"<!-- {kind}:{key}:end -->"
    pattern = re.compile(re.escape(start) + r".*?" + re.escape(end), flags=re.S)
    return pattern.sub(lambda _: f"{start}\n{block}\n{end}", text)


#: the Recover suites' leaderboards: suite -> its file in docs/data (tasks.md's
#: ``<!-- recover:SUITE:start -->`` blocks)
RECOVER_BOARDS = {"recover": "leaderboard-recover.json",
                  "recover-robust": "leaderboard-recover-robust.json"}


def recover_blocks(text: str, root: Path) -> str:
    """``text`` with each ``<!-- recover:SUITE:start -->`` ... ``end`` block the table of the
    committed recovery leaderboard of that suite (:func:`agents.benchmarking.recover.recover_markdown`)."""
    from .recover import recover_markdown
    for suite, name in RECOVER_BOARDS.items():
        report = _load(root / DATA / name)
        if report is None:
            continue
        a, b = report["seeds"]
        block = (f"`rotordrop benchmark --suite {suite}`: test events {a}-{b} "
                 f"({len(report['events'][report['reference']])} events, "
                 f"{report['cpu_s_total'] / 60:.1f} CPU-minutes; `{DATA.as_posix()}/{name}`). "
                 + recover_standing(report) + "\n\n" + recover_markdown(report))
        text = _regenerate(text, "recover", suite, block)
    return text


def recover_standing(report: dict) -> str:
    """The sentence tasks.md states a recovery leaderboard's standing in: what the reference
    (the standard PID) leaves in persistent contact, the best designed row against it, and
    what no row recovers."""
    board = {r["controller"]: r for r in report["board"]}
    ref = board[report["reference"]]
    best = report["board"][0]
    d = best["vs_reference"]["recovered"]
    ev = report["events"]
    none = sum(not any(ev[n][i]["recovered"] for n in ev) for i in range(len(ev[ref["controller"]])))
    pers = ref["persistent"]
    calm = report.get("calm") or [False] * len(ev[ref["controller"]])
    stuck = [c for e, c in zip(ev[ref["controller"]], calm) if e["persistent"]]
    transient = sum(c and e["event"] in ("shock", "load")
                    for e, c in zip(ev[ref["controller"]], calm) if e["persistent"])
    return (f"The standard PID (`{ref['controller']}`) recovers {100 * ref['recovered']['value']:.1f} "
            f"± {100 * ref['recovered']['se']:.1f} % of the events and leaves "
            f"{100 * pers['value']:.1f} ± {100 * pers['se']:.1f} % in persistent contact "
            f"({transient} of those {len(stuck)} after a shock or a transient load on a machine the "
            "PID holds contact-free without the event: a contact-free steady state exists for "
            "them); the best "
            f"row, `{best['controller']}` ({best['seat']} seat), recovers "
            f"{100 * best['recovered']['value']:.1f} ± {100 * best['recovered']['se']:.1f} % "
            f"({100 * d['delta']:+.1f} ± {100 * d['se']:.1f} points against the PID, paired "
            f"bootstrap over events); {none} of {len(ev[ref['controller']])} events "
            f"({100 * none / len(ev[ref['controller']]):.1f} %) are recovered by no row.")


def tasks_text(root: Path = ROOT) -> str:
    """docs/tasks.md with each ``<!-- standing:KEY:start -->`` ... ``end`` block regenerated
    from the committed leaderboards (:data:`STANDINGS`), each ``<!-- learning:KEY:... -->``
    block from its learning report (:data:`LEARNING`), the Recover task's tables
    (:func:`recover_blocks`) and the hard benchmark's standing (``<!-- hard:table:... -->``,
    :func:`hard_standing`)."""
    text = recover_blocks((root / TASKS).read_text(), root)
    table = _load(root / DATA / HARD_TABLE)
    if table is not None:
        text = _regenerate(text, "hard", "table", hard_standing(table))
    for key, (name, task) in STANDINGS.items():
        report = _load(root / DATA / name)
        if report is not None:
            text = _regenerate(text, "standing", key, standing(report, task))
    for key, name in LEARNING.items():
        report = _load(root / DATA / name)
        if report is not None:
            text = _regenerate(text, "learning", key, learning_table(report))
    return text


def generated(root: Path = ROOT) -> dict[Path, str]:
    pages = {root / RESULTS: results_page(root), root / README: readme_text(root),
             **figure_data(root)}
    if (root / TASKS).exists():
        pages[root / TASKS] = tasks_text(root)
    return pages


def check_complete(path: str, force: bool) -> None:
    """Refuse to store a ``--quick`` or partial benchmark (``--scenarios``, ``--episodes``)
    over the committed data unless ``force``: the pages would quote a reduced suite."""
    report = json.loads(Path(path).read_text())
    reduced = [w for w, flag in (("--quick", report.get("quick")),
                                 ("partial (--scenarios/--episodes)", report.get("partial")))
               if flag]
    if reduced and not force:
        raise ValueError(f"{path} is a {' and '.join(reduced)} benchmark: storing it would replace "
                         "the committed full-suite leaderboard, README and results and tasks "
                         "pages; re-run the full benchmark, or pass --force")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``python -m agents.benchmarking.results`` and ``rotordrop results``."""
    p.add_argument("--nominal", help="a `rotordrop benchmark` benchmark.json to store as "
                                     "docs/data/leaderboard-nominal.json")
    p.add_argument("--robust", help="a `rotordrop benchmark --suite robust` benchmark.json to "
                                    "store as docs/data/leaderboard-robust.json")
    p.add_argument("--recover", help="a `rotordrop benchmark --suite recover` benchmark.json to "
                                     "store as docs/data/leaderboard-recover.json")
    p.add_argument("--recover-robust", help="a `rotordrop benchmark --suite recover-robust` "
                                            "benchmark.json to store as "
                                            "docs/data/leaderboard-recover-robust.json")
    p.add_argument("--hard", action="append", default=[],
                   help="a `rotordrop evaluate` kpis.json of the hard benchmark to store as "
                        "docs/data/hard-<policy>.json (repeatable)")
    p.add_argument("--hard-run", nargs=3, action="append", default=[],
                   metavar=("VARIANT", "KPIS", "RUN"),
                   help="add a training run to the hard benchmark's algorithm table "
                        "(docs/data/hard-table.json): the variant (nominal | noisy), the "
                        "kpis.json of `rotordrop evaluate` on its model, its run directory "
                        "(repeatable; a run of the same variant, algorithm and seed is replaced)")
    p.add_argument("--hard-ref", nargs=2, action="append", default=[], metavar=("VARIANT", "KPIS"),
                   help="add a designed reference row to the algorithm table: the variant and "
                        "the kpis.json of `rotordrop evaluate` on the same drops and sensing")
    p.add_argument("--oracle-nominal", help="a `rotordrop oracle` oracle.json (nominal drops) to "
                                            "store as docs/data/oracle-nominal.json")
    p.add_argument("--oracle-robust", help="a `rotordrop oracle --suite robust` oracle.json to "
                                           "store as docs/data/oracle-robust.json")
    p.add_argument("--learning", action="append", default=[], metavar="KEY=FILE[,FILE...][:PREFIX]",
                   help="`rotordrop benchmark --suite robust --only REF --policy RUN...` "
                        "benchmark.json files of learned seed groups on the same drops (merged; "
                        "with :PREFIX only the rows named PREFIX*), stored as the docs/data file of "
                        f"KEY ({', '.join(f'{k}: {v}' for k, v in LEARNING.items())}) for "
                        "docs/tasks.md's learning table (repeatable)")
    p.add_argument("--headroom", help="a `python -m agents.benchmarking.headroom` headroom.json of "
                                      "the robust leaderboard, stored as "
                                      "docs/data/headroom-robust.json")
    p.add_argument("--oracle-budget", nargs="+", default=[],
                   help="`rotordrop oracle` oracle.json files of one suite's drops at several "
                        "search budgets, stored together as docs/data/oracle-budget.json")
    p.add_argument("--root", default=str(ROOT), help="the project folder (default: this checkout)")
    p.add_argument("--check", action="store_true",
                   help="write nothing; exit 1 if the committed pages differ from the data")
    p.add_argument("--force", action="store_true",
                   help="store a --quick or partial benchmark over the committed one anyway")


def run(args) -> int:
    """Store the given benchmark output in docs/data and regenerate the pages (or ``--check``)."""
    root = Path(args.root)
    recover = {"recover": getattr(args, "recover", None),
               "recover-robust": getattr(args, "recover_robust", None)}
    given = (args.nominal, args.robust, args.hard, args.oracle_nominal, args.oracle_robust,
             args.oracle_budget, args.headroom, args.hard_run, args.hard_ref, args.learning,
             *recover.values())
    if args.check and any(given):
        print("results: error: --check takes no data files", file=sys.stderr)
        return 2
    stored = []
    try:
        for src in (args.nominal, args.robust):
            if src:
                check_complete(src, getattr(args, "force", False))
    except ValueError as exc:
        print(f"results: error: {exc}", file=sys.stderr)
        return 2
    if args.nominal:
        stored.append(store(args.nominal, root / DATA / "leaderboard-nominal.json", drop=DROPPED_KEYS))
    if args.robust:
        stored.append(store(args.robust, root / DATA / "leaderboard-robust.json", drop=DROPPED_KEYS))
    for suite, src in recover.items():
        if src:
            stored.append(store(src, root / DATA / RECOVER_BOARDS[suite]))
    for src, name in ((args.oracle_nominal, "oracle-nominal.json"),
                      (args.oracle_robust, "oracle-robust.json")):
        if src:
            stored.append(store(src, root / DATA / name, keep=ORACLE_KEYS))
    if args.headroom:
        stored.append(store(args.headroom, root / DATA / "headroom-robust.json"))
    for spec in args.learning:
        key, _, src = spec.partition("=")
        src, _, prefix = src.partition(":")
        if key not in LEARNING or not src:
            print(f"results: error: --learning {spec!r}: write KEY=FILE[,FILE...][:PREFIX] with "
                  f"KEY one of {', '.join(LEARNING)}", file=sys.stderr)
            return 2
        try:
            stored.append(store_learning(src.split(","), root / DATA / LEARNING[key], prefix or None))
        except (ValueError, KeyError) as exc:
            print(f"results: error: --learning {key}: {exc}", file=sys.stderr)
            return 2
    if args.oracle_budget:
        runs = [budget_run(json.loads(Path(p).read_text())) for p in args.oracle_budget]
        dest = root / DATA / "oracle-budget.json"
        dest.write_text(json.dumps({"runs": runs}, indent=1, sort_keys=True) + "\n")
        stored.append(dest)
    for h in args.hard:
        name = re.sub(r"[^A-Za-z0-9_.-]+", "-", json.loads(Path(h).read_text())["policy"]).strip("-")
        stored.append(store(h, root / DATA / f"hard-{name}.json", keep=HARD_KEYS))
    if args.hard_run or args.hard_ref:
        try:
            stored.append(store_hard_table(root / DATA / HARD_TABLE, args.hard_run, args.hard_ref,
                                           root))
        except (ValueError, KeyError, FileNotFoundError) as exc:
            print(f"results: error: {exc}", file=sys.stderr)
            return 2
    stale = []
    for path, text in generated(root).items():
        if path.exists() and path.read_text() == text and (
                path.suffix != ".csv" or path.with_suffix(".png").exists()):
            continue
        stale.append(path)
        if not args.check:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
    if not args.check:
        stale += draw_figures(root, [p for p in stale if p.suffix == ".csv"])
    if args.check:
        if stale:
            print("out of date (run `python -m agents.benchmarking.results`): "
                  + ", ".join(str(s.relative_to(root)) for s in stale), file=sys.stderr)
            return 1
        print("docs/results.md, docs/tasks.md and the README leaderboard match docs/data")
        return 0
    print("wrote " + ", ".join(str(s.relative_to(root)) for s in stored + stale) if stored + stale
          else "nothing to change")
    return 0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m agents.benchmarking.results", description=__doc__.split("\n")[0])
    add_arguments(p)
    return run(p.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
