"""Figures of the agents layer: learning curves, policy-vs-passive episodes, benchmark charts."""
from __future__ import annotations

from pathlib import Path

import numpy as np


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def plot_learning_curve(history: list[dict], path: Path, title: str) -> Path | None:
    """Evaluation return (± std) and failure rate (whirl, stator contact) against steps, and
    below it the validation score when the run had ``validation: true``."""
    if not history:
        return None
    plt = _plt()
    steps = np.array([h["timesteps"] for h in history])
    mean = np.array([h["mean_reward"] for h in history])
    std = np.array([h.get("std_reward", 0.0) for h in history])
    validation = [h.get("validation_score", np.nan) for h in history]
    if np.all(np.isnan(validation)):
        fig, ax = plt.subplots(figsize=(7, 4))
    else:
        fig, (ax, axv) = plt.subplots(2, 1, figsize=(7, 6), sharex=True,
                                      gridspec_kw=dict(height_ratios=(3, 2)))
        axv.plot(steps, validation, "d-", color="C2")
        best = int(np.nanargmax(validation))
        axv.plot(steps[best], validation[best], "*", ms=14, color="C1", label="kept as best/")
        axv.set_ylabel("validation score")
        axv.grid(alpha=0.3)
        axv.legend(fontsize=8)
    ax.plot(steps, mean, "o-", label="evaluation return")
    ax.fill_between(steps, mean - std, mean + std, alpha=0.2)
    fig.axes[-1].set_xlabel("environment steps")
    ax.set_ylabel("return")
    if any("mean_failure" in h for h in history):
        ax2 = ax.twinx()
        ax2.plot(steps, [h.get("mean_failure", np.nan) for h in history], "s--", color="C3",
                 label="failure rate")
        ax2.set_ylabel("failure rate (whirl, stator contact, overload)", color="C3")
        ax2.set_ylim(-0.05, 1.05)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def _plane_xy(ep, k: int):
    names = list(ep.obs_names)
    return ep.obs[:, names.index(f"x{k}")], ep.obs[:, names.index(f"y{k}")]


def _finish_time_plot(plt, fig, ax, ylabel: str, title: str, path: Path) -> Path:
    """Label, grid and legend a plot against episode time, save it (PNG) and close it."""
    ax.set_xlabel("time since the episode start [ms]")
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def plot_episode_comparison(ep, passive, name: str, out: Path) -> list[Path]:
    """Orbits at both sensor planes, contact force and actions (legend: ``ep.action_names``):
    ``name`` against passive."""
    plt = _plt()
    out = Path(out)
    runs = [(name, ep, "C0")] + ([("passive", passive, "C7")] if passive is not None else [])
    paths = []

    fig, axes = plt.subplots(1, 2, figsize=(10, 5))
    for k, ax in enumerate(axes, start=1):
        for label, e, color in runs[::-1]:
            x, y = _plane_xy(e, k)
            ax.plot(x * 1e6, y * 1e6, color=color, lw=0.7, label=label)
        ax.set_aspect("equal")
        ax.set_xlabel("x [µm]")
        ax.set_ylabel("y [µm]")
        ax.set_title(f"orbit at sensor plane {k}")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    fig.suptitle(f"{name} vs passive (seed {ep.seed})")
    fig.tight_layout()
    paths.append(out / "orbits.png")
    fig.savefig(paths[-1], dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(9, 4))
    for label, e, color in runs[::-1]:
        f = e.contact_force
        for j in range(f.shape[1]):
            ax.plot(e.t * 1e3, f[:, j], color=color, lw=0.8, ls="-" if j == 0 else "--",
                    label=label if f.shape[1] == 1 else f"{label} RB{j + 1}")
    paths.append(_finish_time_plot(plt, fig, ax, "contact force [N]",
                                   f"contact force: {name} vs passive (seed {ep.seed})",
                                   out / "contact_force.png"))

    if ep.actions is not None and ep.actions.size:
        fig, ax = plt.subplots(figsize=(9, 3.5))
        names = ep.action_names or [f"action[{j}]" for j in range(ep.actions.shape[1])]
        colors = {}
        for j, label in enumerate(names):
            kind, style = action_style(label)
            ax.step(ep.t * 1e3, ep.actions[:, j], where="post",
                    color=colors.setdefault(kind, f"C{len(colors)}"), label=label, **style)
        paths.append(_finish_time_plot(plt, fig, ax, "action", f"actions of {name}",
                                       out / "actions.png"))
    return paths


def action_style(name: str) -> tuple[str, dict]:
    """(kind, line style) of an action's line: one colour per kind (the name without its
    AMB/damper plane digit); plane 1 a wide pale band, plane 2 dashed on top of it, so that
    equal commands of the two planes both show."""
    for plane, style in (("2", dict(ls="--", lw=1.0)), ("1", dict(ls="-", lw=3.0, alpha=0.4))):
        for tag in (f"amb{plane}", f"damping{plane}"):
            if tag in name:
                return name.replace(tag, tag[:-1]), style
    return name, dict(ls="-", lw=1.0)


def plot_benchmark(report: dict, out: Path) -> list[Path]:
    """Score per controller and task, whirl map (controller x scenario), peak contact force."""
    plt = _plt()
    out = Path(out)
    paths = []
    board = report["leaderboard"]
    tasks = list(dict.fromkeys(e["task"] for e in board))

    fig, axes = plt.subplots(1, len(tasks), figsize=(5 * len(tasks), 4), squeeze=False)
    for ax, task in zip(axes[0], tasks):
        es = [e for e in board if e["task"] == task]
        ax.barh([e["controller"] for e in es][::-1], [e["score"] for e in es][::-1],
                color=["C2" if e["controller"].split("-")[0] in ("ppo", "sac", "td3") else "C0"
                       for e in es][::-1])
        ax.axvline(0.0, color="k", lw=0.8)
        ax.set_xlabel("overall score (passive = 0, higher is better)")
        ax.set_title(task)
        ax.grid(axis="x", alpha=0.3)
    fig.tight_layout()
    paths.append(out / "score.png")
    fig.savefig(paths[-1], dpi=110)
    plt.close(fig)

    rows = report["rows"]
    for key, fname, label, fmt in (("backward_whirl", "whirl_map.png", "backward-whirl rate", ".2f"),
                                   ("peak_contact_force_N", "peak_force.png",
                                    "peak contact force [kN]", ".1f")):
        fig, axes = plt.subplots(len(tasks), 1, figsize=(12, 2.2 + 0.5 * len(board)), squeeze=False)
        for ax, task in zip(axes[:, 0], tasks):
            ctrls = [e["controller"] for e in board if e["task"] == task]
            scen = list(dict.fromkeys(r["scenario"] for r in rows if r["task"] == task))
            M = np.full((len(ctrls), len(scen)), np.nan)
            for r in rows:
                if r["task"] == task:
                    v = r[key] / (1e3 if key == "peak_contact_force_N" else 1.0)
                    M[ctrls.index(r["controller"]), scen.index(r["scenario"])] = v
            vmax = 1.0 if key == "backward_whirl" else np.nanmax(M)
            im = ax.imshow(M, aspect="auto", cmap="Reds", vmin=0.0, vmax=vmax)
            for i in range(M.shape[0]):
                for j in range(M.shape[1]):
                    ax.text(j, i, format(M[i, j], fmt), ha="center", va="center", fontsize=7,
                            color="white" if M[i, j] > 0.6 * vmax else "black")
            ax.set_yticks(range(len(ctrls)), ctrls)
            ax.set_xticks(range(len(scen)), scen, rotation=30, ha="right", fontsize=7)
            ax.set_title(f"{task}: {label}")
            fig.colorbar(im, ax=ax, fraction=0.02)
        fig.tight_layout()
        paths.append(out / fname)
        fig.savefig(paths[-1], dpi=110)
        plt.close(fig)
    return paths


def plot_ride_through(report: dict, out: Path) -> Path:
    """One panel per controller: peak backward-whirl revolutions (worst phase) over friction ×
    power-return delay, the whirl threshold as a contour (grids of at least 2 × 2), the
    ride-through time in blue, and the passive drop's peak revolutions in the title."""
    plt = _plt()
    mus = np.asarray(report["frictions"])
    delays = 1e3 * np.asarray(report["power_return_s"])
    names = list(report["controllers"])
    thr = report["whirl_revolutions"]
    vmax = max(2 * thr, max(np.nanmax(np.asarray(m["peak_whirl_revolutions"], dtype=float))
                            for m in report["controllers"].values()))
    contour = len(mus) > 1 and len(delays) > 1
    fig, axes = plt.subplots(1, len(names), figsize=(4.2 * len(names) + 1, 4.2), squeeze=False,
                             sharey=True)
    for ax, name in zip(axes[0], names):
        m = report["controllers"][name]
        revs = np.asarray(m["peak_whirl_revolutions"], dtype=float).T       # (delays, frictions)
        im = ax.pcolormesh(_cell_edges(mus, 0.05), _cell_edges(delays, 10.0), revs, cmap="Reds",
                           vmin=0.0, vmax=vmax)
        if contour:
            ax.contour(mus, delays, revs, levels=[thr], colors="k", linewidths=1.2)
        for i, mu in enumerate(mus):
            for j, d in enumerate(delays):
                ax.text(mu, d, f"{revs[j, i]:.1f}", ha="center", va="center", fontsize=6,
                        color="white" if revs[j, i] > 0.6 * vmax else "black")
        ride = np.array([np.nan if t is None else 1e3 * t for t in m["ride_through_s"]])
        ax.plot(mus, ride, "o-", color="C0", ms=3)
        low = np.asarray(m["ride_through_lower_bound"], dtype=bool)
        ax.plot(mus[low], ride[low], "^", color="C0", ms=7)      # held to the longest delay
        ax.set_title(name)
        ax.set_xlabel("friction coefficient μ")
    axes[0, 0].set_ylabel("power back after the fault [ms]")
    passive = ", ".join(f"{mu:g}: {r:.0f}" for mu, r in
                        zip(mus, report["passive"]["peak_whirl_revolutions"]))
    fig.suptitle(f"{report['env_id']}: peak backward-whirl revolutions, worst of "
                 f"{len(report['phases_deg'])} phases (whirl ≥ {thr:g}"
                 f"{': black line' if contour else ''}); blue: ride-through time (▲: at least, held to the longest delay)\npassive drop (power never back), μ: revolutions  {passive}",
                 fontsize=9, y=1.04)
    fig.colorbar(im, ax=axes[0].tolist(), fraction=0.03)
    path = Path(out) / "ride_through.png"
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return path


def _cell_edges(centres, width: float) -> np.ndarray:
    """Edges of the cells around sorted grid values (midway between neighbours, the end cells
    as wide as their neighbours); a single value gets a cell ``width`` wide."""
    c = np.asarray(centres, dtype=float)
    if len(c) == 1:
        return c[0] + np.array([-0.5, 0.5]) * width
    mid = 0.5 * (c[1:] + c[:-1])
    return np.concatenate([[2 * c[0] - mid[0]], mid, [2 * c[-1] - mid[-1]]])


def plot_tuning(report: dict, out: Path) -> Path:
    """``rotordrop tune``: best validation score so far and each generation's best."""
    plt = _plt()
    h = report["history"]
    it = [r["iteration"] for r in h]
    fig, ax = plt.subplots(figsize=(6.5, 3.8), constrained_layout=True)
    ax.plot(it, [r["best_validation_score"] for r in h], "o-", label="best so far")
    ax.plot(it[1:], [r["generation_best"] for r in h[1:]], ".", color="0.5", label="generation best")
    ax.set_xlabel("generation (0 = start gains)")
    ax.xaxis.get_major_locator().set_params(integer=True)
    ax.set_ylabel("validation score (passive = 0)")
    ax.set_title(f"{report['controller']} on {report['env_id']}: "
                 + ", ".join(f"{k} = {v:.3g}" for k, v in report["gains"].items()), fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    path = Path(out) / "tune.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


ROBUST_FRICTION_BINS = (0.3, 0.375, 0.45, 0.525, 0.6)


def plot_robust(report: dict, out: Path) -> list[Path]:
    """The robust suite: score per row (learned in green) and the backward-whirl rate per
    friction bin of passive, the best designed row and the learned rows."""
    plt = _plt()
    board = report["leaderboard"]
    names = [e["controller"] for e in board]
    fig, axes = plt.subplots(1, 2, figsize=(13, 0.32 * len(names) + 2.5))
    y = np.arange(len(names))[::-1]
    axes[0].barh(y, [e["score"] for e in board],
                 color=["C2" if e["kind"] == "learned" else "C0" for e in board])
    axes[0].axvline(0.0, color="k", lw=0.8)
    axes[0].set(yticks=y, yticklabels=names, xlabel="score (passive = 0)",
                title=f"robust suite, {len(report['scenarios'])} drops")
    edges = np.asarray(ROBUST_FRICTION_BINS)
    mu = np.array([s["friction"] for s in report["scenarios"]])
    which = np.clip(np.searchsorted(edges, mu, side="right") - 1, 0, len(edges) - 2)
    mid = 0.5 * (edges[:-1] + edges[1:])
    designed = [e["controller"] for e in board if e["kind"] == "designed" and e["controller"] != "passive"]
    show = ["passive", *designed[:1], *[e["controller"] for e in board if e["kind"] == "learned"]]
    for name in show:
        w = {r["scenario"]: r["backward_whirl"] for r in report["rows"] if r["controller"] == name}
        v = np.array([w[s["name"]] for s in report["scenarios"]])
        axes[1].plot(mid, [v[which == b].mean() if np.any(which == b) else np.nan
                           for b in range(len(mid))], "o-", label=name)
    axes[1].set(xlabel="friction (bin centre)", ylabel="backward-whirl rate", ylim=(-0.02, 1.02),
                title="drops per bin: " + ", ".join(str(int(np.sum(which == b))) for b in range(len(mid))))
    axes[1].legend(fontsize=7)
    axes[1].grid(alpha=0.3)
    fig.tight_layout()
    path = Path(out) / "robust.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return [path]


def plot_deltas(rows: list[dict], title: str, path: Path) -> Path:
    """Every leaderboard row's Δ to the reference row with its 95 % interval (paired bootstrap),
    in rank order; ``rows``: controller, kind, reference, diff, lo, hi (the CSV beside the PNG).
    The axis is linear within ±1 point and logarithmic beyond, so that the close rows' intervals
    and the far ones both show."""
    plt = _plt()
    names = [r["controller"] for r in rows]
    diff, lo, hi = (np.array([float(r[k]) for r in rows]) for k in ("diff", "lo", "hi"))
    y = np.arange(len(rows))[::-1]
    fig, ax = plt.subplots(figsize=(8.5, 0.3 * len(rows) + 1.3))
    for kind, colour in (("designed", "C0"), ("learned", "C2")):
        on = np.array([r["kind"] == kind for r in rows])
        if on.any():
            ax.errorbar(diff[on], y[on], xerr=[diff[on] - lo[on], hi[on] - diff[on]], fmt="o",
                        color=colour, ms=4, capsize=3, label=kind)
    ax.axvline(0.0, color="k", lw=0.8)
    ax.set_xscale("symlog", linthresh=1.0)
    left, right = min(-1.0, 1.3 * float(lo.min())), max(1.0, 1.3 * float(hi.max()))
    ax.set_xlim(left, right)
    ticks = [t for t in (-300, -100, -30, -10, -3, -1, 0, 1, 3, 10, 30, 100, 300)
             if left <= t <= right]
    ax.set_xticks(ticks, [f"{t:+d}" if t else "0" for t in ticks])
    ax.minorticks_off()
    ax.set_yticks(y, names, fontsize=8)
    for yi, d, l, h in zip(y, diff, lo, hi):
        ax.annotate(f"{d:+.2f} [{l:+.2f}, {h:+.2f}]", (1.01, yi), xycoords=("axes fraction", "data"),
                    va="center", fontsize=7)
    ref = rows[0]["reference"] if rows else ""
    ax.set(xlabel=f"Δ score vs {ref} (points; 95 % interval)", title=title)
    ax.grid(axis="x", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
