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

That is the ``legacy`` score. The default score (``severity``) splits the whirl term into the
onset verdict and the whirl's severity,

    W(c, s)  ->  ½ W(c, s) + ½ N(c, s) / max(N(passive, s), N_0)

with N the peak net backward orbit revolutions after the fault (the quantity whose reaching
N_0 = 3 revolutions is the whirl verdict; the environments' monitor accumulates it at every
KPI sample) averaged over the scenario's episodes. The passive drop of a whirling scenario
still costs 1 there; a controller that stops a whirl after 4 revolutions where the passive
drop makes 60 costs ½ + ½·4/60 instead of 1. :func:`check_score` names the scores.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from physics.metrics import WHIRL_MIN_REVOLUTIONS

#: the benchmark's scores (``rotordrop benchmark --score``): the default first
SCORES = ("severity", "legacy")
DEFAULT_SCORE = SCORES[0]


def check_score(score: str) -> str:
    """``score``, or ValueError naming the allowed scores."""
    if score not in SCORES:
        raise ValueError(f"--score = {score!r} must be one of {', '.join(SCORES)}")
    return score

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


def whirl_reference(passive: dict) -> float:
    """The severity term's normaliser: the passive drop's peak net backward revolutions in the
    scenario, at least the verdict's ``WHIRL_MIN_REVOLUTIONS``."""
    return max(float(passive["peak_whirl_revolutions"]), float(WHIRL_MIN_REVOLUTIONS))


def cost_terms(row: dict, passive: dict, episode_time: float, relevitation: bool,
               score: str = DEFAULT_SCORE) -> dict[str, float]:
    """The terms of J(c, s) (module docstring) for one benchmark row against its passive row:
    ``whirl`` (the verdict: W, or ½ W with the severity score), ``whirl_severity`` (½ N / N_ref,
    0 in the legacy score), ``force``, ``displacement``, and in tasks that can re-levitate
    ``relevitation_failure`` (1 − R) and ``relevitation_time`` (T_R / T_episode, T_episode for
    the failed share). :func:`row_cost` sums them."""
    legacy = check_score(score) == "legacy"
    terms = dict(whirl=(1.0 if legacy else 0.5) * float(row["backward_whirl"]),
                 whirl_severity=0.0 if legacy else
                 0.5 * float(row["peak_whirl_revolutions"]) / whirl_reference(passive),
                 force=0.5 * row["peak_contact_force_N"] / max(passive["peak_contact_force_N"], 1e-9),
                 displacement=0.5 * row["max_displacement_um"] / max(passive["max_displacement_um"],
                                                                     1e-9))
    if relevitation:
        rate = row.get("relevitated") or 0.0
        t = row.get("relevitation_time_s")
        terms.update(relevitation_failure=1.0 - rate,
                     relevitation_time=(rate * (t if t is not None else episode_time)
                                        + (1.0 - rate) * episode_time) / episode_time)
    return terms


def row_cost(row: dict, passive: dict, episode_time: float, relevitation: bool,
             score: str = DEFAULT_SCORE) -> float:
    """J(c, s) of the module docstring for one benchmark row against its passive row (the sum
    of :func:`cost_terms`).

    Rows hold the scenario means ``backward_whirl`` (rate), ``peak_whirl_revolutions``
    (``severity`` score), ``peak_contact_force_N``, ``max_displacement_um``, ``relevitated``
    (rate) and ``relevitation_time_s`` (mean over the successful episodes)."""
    t = cost_terms(row, passive, episode_time, relevitation, score)
    cost = t["whirl"] if check_score(score) == "legacy" else t["whirl"] + t["whirl_severity"]
    cost += t["force"]
    cost += t["displacement"]
    if relevitation:
        cost += t["relevitation_failure"] + t["relevitation_time"]
    return cost


def drop_costs(drops: dict, passive: dict, episode_time: float, relevitation: bool,
               score: str = DEFAULT_SCORE) -> np.ndarray:
    """The cost of each drop (episode) of a row: ``drops`` maps the per-episode KPIs
    (``backward_whirl``, ``peak_whirl_revolutions``, ``peak_contact_force_N``,
    ``max_displacement_um``, ``relevitated``, ``relevitation_time_s``) to equal-length lists,
    ``passive`` is the scenario's passive row (its means). J is linear in the episode KPIs, so
    the mean of these costs is the row's :func:`row_cost`."""
    d = {k: np.asarray(v, dtype=float) for k, v in drops.items()
         if k not in ("relevitated", "relevitation_time_s")}
    if check_score(score) == "legacy":
        cost = d["backward_whirl"].copy()
    else:
        cost = 0.5 * d["backward_whirl"] + 0.5 * d["peak_whirl_revolutions"] / whirl_reference(passive)
    cost += 0.5 * d["peak_contact_force_N"] / max(passive["peak_contact_force_N"], 1e-9)
    cost += 0.5 * d["max_displacement_um"] / max(passive["max_displacement_um"], 1e-9)
    if relevitation:
        ok = np.array([bool(x) for x in drops["relevitated"]])
        t = np.array([float(x) if x is not None and o else episode_time
                      for x, o in zip(drops["relevitation_time_s"], ok)])
        cost += (~ok).astype(float) + t / episode_time
    return cost


def overall_score(costs: list[float], passive_costs: list[float]) -> float:
    return 100.0 * (1.0 - sum(costs) / sum(passive_costs))


#: the paired bootstrap of the leaderboards: resamples and seed (deterministic)
BOOTSTRAP_RESAMPLES = 2000
BOOTSTRAP_SEED = 20_261_127


def bootstrap_scores(costs: np.ndarray, passive: np.ndarray, reference: int,
                     resamples: int = BOOTSTRAP_RESAMPLES, seed: int = BOOTSTRAP_SEED,
                     clusters=None) -> dict:
    """Paired bootstrap over scenarios of the scores of K rows that ran the same n drops.

    ``costs`` (K, n): each row's cost per drop; ``passive`` (n,): the passive drop's; the score
    of a row is 100 (1 − Σ costs / Σ passive). ``clusters`` (n,): the scenario of each drop
    (default: every drop its own): the drops of one scenario (its unbalance phases) are not
    independent, so a resample draws the G scenarios with replacement, all drops of a drawn
    scenario together, the same scenarios for every row (paired), and recomputes every score;
    ``reference`` is the row the others are compared with. Returns per row (arrays of K):
    ``score``, ``score_se``, ``diff`` (score − the reference's), ``diff_se`` and the 95 %
    percentile interval ``diff_ci_low``, ``diff_ci_high`` of the difference. Vectorised: the
    resamples are a (resamples, G) matrix of scenario counts."""
    costs = np.atleast_2d(np.asarray(costs, dtype=float))
    passive = np.asarray(passive, dtype=float)
    k, n = costs.shape
    if passive.shape != (n,):
        raise ValueError(f"passive has {passive.shape} costs, the rows {n} drops")
    _, cluster = np.unique(np.arange(n) if clusters is None else np.asarray(clusters),
                           return_inverse=True)
    if cluster.shape != (n,):
        raise ValueError(f"clusters has {np.shape(clusters)} entries, the rows {n} drops")
    g = int(cluster.max()) + 1
    score = 100.0 * (1.0 - costs.sum(axis=1) / passive.sum())
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, g, size=(resamples, g))
    counts = np.bincount((np.arange(resamples)[:, None] * g + idx).ravel(),
                         minlength=resamples * g).reshape(resamples, g).astype(float)[:, cluster]
    boot = 100.0 * (1.0 - (counts @ costs.T) / (counts @ passive)[:, None])      # (B, K)
    diff = boot - boot[:, [reference]]
    lo, hi = np.percentile(diff, [2.5, 97.5], axis=0)
    return dict(score=score, score_se=boot.std(axis=0, ddof=1),
                diff=score - score[reference], diff_se=diff.std(axis=0, ddof=1),
                diff_ci_low=lo, diff_ci_high=hi)


def attach_bootstrap(entries: list[dict], costs, passive, reference: int, clusters=None) -> None:
    """Add to each entry (the rows of ``costs``, in order) its paired-bootstrap uncertainty
    against the entry ``reference`` (:func:`bootstrap_scores`, resampling the scenarios
    ``clusters``): ``score_se``, ``reference`` (its name), ``diff_vs_reference``, ``diff_se``,
    ``diff_ci95`` and ``drops``."""
    b = bootstrap_scores(costs, passive, reference, clusters=clusters)
    name = entries[reference]["controller"]
    for i, e in enumerate(entries):
        e.update(score_se=float(b["score_se"][i]), reference=name,
                 diff_vs_reference=float(b["diff"][i]), diff_se=float(b["diff_se"][i]),
                 diff_ci95=[float(b["diff_ci_low"][i]), float(b["diff_ci_high"][i])],
                 drops=int(np.asarray(passive).size))


def seed_groups(board: list[dict], learned: dict) -> list[dict]:
    """Learned rows trained with the same algorithm and hyperparameters (the seeds of one
    configuration): :func:`groups_of` with each policy's configuration (algorithm, env id,
    hyperparameters) and seed."""
    import hashlib
    import json
    configs = {}
    for name, pol in learned.items():
        key = json.dumps([pol.algo, pol.env_id, pol.meta.get("hyperparams") or pol.env_kwargs],
                         sort_keys=True, default=str)
        configs[name] = (hashlib.sha1(key.encode()).hexdigest()[:12], pol.meta.get("seed"))
    return groups_of(board, configs)


def groups_of(board: list[dict], configs: dict) -> list[dict]:
    """The seed groups of ``board``'s rows named in ``configs`` (name -> (configuration key,
    seed)): mean, standard deviation (over seeds, ddof = 1) and mean − std of their scores;
    groups of one row are left out. A seed counts once: a shipped policy benchmarked beside the
    run it was shipped from (same seed) is one member, the first listed. Each learned row gets
    its ``configuration`` and ``seed`` (so reports on the same drops can be merged,
    :func:`merged_groups`) and each member its seeds' spread."""
    keys: dict[str, list[str]] = {}
    seeds: dict[str, set] = {}
    repeats: dict[str, list[str]] = {}
    for name, (key, seed) in configs.items():
        seen = seeds.setdefault(key, set())
        if seed is not None and seed in seen:
            repeats.setdefault(key, []).append(name)
            continue
        seen.add(seed)
        keys.setdefault(key, []).append(name)
    score = {e["controller"]: e["score"] for e in board}
    for e in board:
        if e["controller"] in configs:
            e.update(configuration=configs[e["controller"]][0], seed=configs[e["controller"]][1])
    out = []
    for key, names in keys.items():
        if len(names) < 2:
            continue
        s = np.array([score[n] for n in names])
        out.append(dict(members=names, repeats=repeats.get(key, []), scores=s.tolist(),
                        mean=float(s.mean()),
                        std=float(s.std(ddof=1)), mean_minus_std=float(s.mean() - s.std(ddof=1))))
    out.sort(key=lambda g: -g["mean_minus_std"])
    for g in out:                                 # each member row shows its seeds' spread
        for e in board:
            if e["controller"] in g["members"] + g["repeats"]:
                e.update(seeds=len(g["members"]), seed_mean=g["mean"], seed_std=g["std"])
    return out


def merged_groups(reports: list[dict]) -> dict:
    """One report of the leaderboards of ``reports`` (benchmark.json dicts of one drawn suite:
    the same drops, score and bootstrap, e.g. seeds scored in separate runs): their rows (a
    name seen twice, e.g. the reference, kept once: the same drops give it the same numbers),
    the seed groups over the learned rows' recorded ``configuration`` and ``seed``, and the
    target. ValueError when the reports' drops, score or bootstrap differ, or a row's numbers
    differ between them."""
    first = reports[0]
    same = ("suite", "score", "bootstrap", "scenarios")
    for r in reports[1:]:
        for k in same:
            if r.get(k) != first.get(k):
                raise ValueError(f"the reports differ in {k}: merge reports of the same drops only")
    board: dict[str, dict] = {}
    for r in reports:
        for e in r["leaderboard"]:
            seen = board.setdefault(e["controller"], e)
            if abs(seen["score"] - e["score"]) > 1e-9:
                raise ValueError(f"row {e['controller']} scores {seen['score']:.4f} and "
                                 f"{e['score']:.4f} in two reports of the same drops")
    rows = sorted(board.values(), key=lambda e: -e["score"])
    configs = {e["controller"]: (e["configuration"], e.get("seed")) for e in rows
               if e.get("kind") == "learned" and e.get("configuration")}
    groups = groups_of(rows, configs)
    return {**{k: first.get(k) for k in same}, "leaderboard": rows, "seed_groups": groups,
            "target": target(rows, groups)}


#: a target is judged on a configuration of at least this many seeds (mean − std over them)
MIN_SEEDS = 3


def target(board: list[dict], groups: list[dict], margin: float = 2.0) -> dict:
    """The target: the best learned configuration, mean − std over its seeds, ≥ the best
    designed row of any seat + ``margin``. Judged on seed groups of at least :data:`MIN_SEEDS`
    seeds only: a learned row without them is reported (``best_single_seed``), never judged;
    ``met`` is None (not judged) when no configuration has the seeds."""
    designed = [e for e in board if e["kind"] == "designed"]
    best_d = max(designed, key=lambda e: e["score"]) if designed else None
    judged = [g for g in groups if len(g["members"]) >= MIN_SEEDS]
    best_g = max(judged, key=lambda g: g["mean_minus_std"]) if judged else None
    single = [e for e in board if e["kind"] == "learned"]
    best_s = max(single, key=lambda e: e["score"]) if single else None
    met = None if best_g is None or best_d is None else \
        bool(best_g["mean_minus_std"] >= best_d["score"] + margin)
    return dict(margin=margin, min_seeds=MIN_SEEDS,
                best_designed=best_d["controller"] if best_d else None,
                best_designed_seat=best_d.get("seat") if best_d else None,
                best_designed_score=best_d["score"] if best_d else None,
                best_learned=" + ".join(best_g["members"]) if best_g else None,
                best_learned_score=best_g["mean_minus_std"] if best_g else None,
                best_learned_seeds=len(best_g["members"]) if best_g else 0,
                best_single_seed=best_s["controller"] if best_s else None,
                best_single_seed_score=best_s["score"] if best_s else None,
                met=met)


def target_sentence(t: dict) -> str:
    """The target line of a leaderboard: met / not met on a seed group, or why it is not judged."""
    head = (f"Target (best learned configuration, mean − std over ≥ {t.get('min_seeds', MIN_SEEDS)} "
            f"seeds, ≥ best designed row of any seat + {t['margin']:g}): best designed "
            f"{t['best_designed']} ({t.get('best_designed_seat') or '-'} seat) "
            f"{fmt_or_dash(t['best_designed_score'], '.2f')}")
    if t.get("met") is None:
        single = (f"; the best single learned row, {t['best_single_seed']} "
                  f"{fmt_or_dash(t.get('best_single_seed_score'), '.2f')}, is one seed: reported, "
                  "not judged" if t.get("best_single_seed") else "")
        return head + f"; not judged: no learned configuration with ≥ {t.get('min_seeds', MIN_SEEDS)} seeds{single}."
    return head + (f", best learned {t['best_learned']} {t['best_learned_score']:.2f} "
                   f"({t['best_learned_seeds']} seeds): {'met' if t['met'] else 'not met'}.")
