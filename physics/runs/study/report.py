"""Figures and the Markdown report of the paper study (``report.md`` next to ``study.json``)."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..plots import RPM, orbit_panel, save_figure  # noqa: E402
from ...results import Result  # noqa: E402
from .checks import counts_text, warnings_note  # noqa: E402
from .claims import PAPER_SOFT_Y_UM, PAPER_THRESHOLD  # noqa: E402
from .paper import BASE, PRIMARY_SLIP, SOFT  # noqa: E402
from .labels import PLANE_KPIS, value_label  # noqa: E402

PLANE = "RB1"           # the paper's figures are at retainer bearing 1


# --------------------------------------------------------------------------------- figures --
def _save(fig, path: Path) -> str:
    """Write the figure; its file name is what the report links to."""
    return save_figure(fig, path).name


def plot_probability(a: dict, out: Path) -> str:
    fig, ax = plt.subplots(figsize=(8, 4.2), constrained_layout=True)
    styles = {("paper", True): "C0-", ("paper", False): "C0:", ("kinematic", True): "C3-",
              ("kinematic", False): "C3:"}
    for (slip, drag), st in styles.items():
        rows = [r for r in a["whirl_probability"] if r["slip"] == slip and r["bearing_friction"] == drag]
        if not rows:
            continue
        ax.plot([r["friction"] for r in rows],
                [np.nan if r["probability"] is None else r["probability"] for r in rows], st,
                marker=".", ms=4, lw=1.2, label=f"{slip} slip, bearing drag {'on' if drag else 'off'}")
        undecided = [(r["friction"], r["undecided"] / (r["runs"] + r["undecided"])) for r in rows
                     if r["undecided"]]
        if undecided and (slip, drag) == (PRIMARY_SLIP, True):
            ax.plot(*zip(*undecided), "x", color="0.4", ms=5,
                    label=f"undecided share ({slip} slip, drag on): left validity before the verdict")
    ax.axhline(0.5, color="0.6", lw=0.8)
    ax.axvline(PAPER_THRESHOLD, color="k", ls="--", lw=0.8, label="paper: whirl from μ = 0.39")
    ax.set_xlabel("friction coefficient μ")
    ax.set_ylabel("whirl probability")
    ax.set_ylim(-0.03, 1.03)
    ax.set_title(f"Backward-whirl probability over {a['plan']['members']} equally plausible drops per μ")
    ax.legend(fontsize=8, loc="center right")
    return _save(fig, out / "whirl_probability.png")


def _undecided_note(rows: list[dict]) -> str:
    """How many drops of the friction study left validity before their whirl verdict (counted
    apart from the probability), and at which μ (primary slip law, drag on)."""
    n = sum(r["undecided"] for r in rows)
    if not n:
        return "\nEvery drop of the friction study was decided (whirl or not) within validity.\n"
    mine = [r for r in rows if r["slip"] == PRIMARY_SLIP and r["bearing_friction"] and r["undecided"]]
    none = [r["friction"] for r in mine if r["probability"] is None]
    where = (f"; with {PRIMARY_SLIP} slip and drag on, {sum(r['undecided'] for r in mine)} at "
             f"μ = {mine[0]['friction']:.2f} … {mine[-1]['friction']:.2f}" if mine else "")
    return (f"\n{n} drops left validity before their whirl verdict (undecided, counted apart from "
            f"the probability: grey crosses in the figure){where}"
            + (f"; from μ = {none[0]:.2f} on, some μ have no decided drop at all ({len(none)} "
               f"grid values)" if none else "") + ".\n")


def _orbit_row(runs: dict[float, Result], label: str, path: Path, width: float, share: bool) -> str:
    """One orbit panel at RB1 per run (after the fault) with the clearance circle (Fig. 3)."""
    vals = sorted(runs)
    fig, axes = plt.subplots(1, len(vals), figsize=(width * len(vals), 3.6 if share else 3.8),
                             constrained_layout=True, sharex=share, sharey=share)
    axes = np.atleast_1d(axes)
    for ax, v in zip(axes, vals):
        orbit_panel(ax, runs[v], PLANE, lw=0.4, circle_lw=0.8)
        ax.set_title(f"{label} = {v:g}" + (" (whirl)" if _whirls(runs[v]) else ""), fontsize=9)
    axes[0].set_ylabel("Y [µm]")
    return _save(fig, path)


def plot_friction_runs(runs: dict[float, Result], out: Path) -> list[str]:
    """Orbits (Fig. 3), contact forces (Fig. 4) and sleeve speeds (Fig. 5) at RB1."""
    mus = sorted(runs)
    names = [_orbit_row(runs, "μ", out / "friction_orbits.png", width=3.2, share=True)]

    fig, axes = plt.subplots(len(mus), 1, figsize=(9, 1.6 * len(mus) + 0.8), sharex=True,
                             sharey=True, constrained_layout=True)
    for ax, mu in zip(np.atleast_1d(axes), mus):
        r = runs[mu]
        ax.plot(r.t, r.contact_force(PLANE), lw=0.5)
        ax.text(0.01, 0.8, f"μ = {mu:g}", transform=ax.transAxes, fontsize=8)
        ax.set_ylabel("F_r [N]")
    np.atleast_1d(axes)[-1].set_xlabel("time [s]")
    fig.suptitle(f"Contact force at {PLANE} (paper Fig. 4)")
    names.append(_save(fig, out / "friction_forces.png"))

    fig, ax = plt.subplots(figsize=(9, 4), constrained_layout=True)
    for mu in mus:
        r = runs[mu]
        ax.plot(r.t, r.sleeve_speed(PLANE) * RPM, lw=1, label=f"sleeve, μ = {mu:g}")
    ax.plot(r.t, r.rotor_speed * RPM, "k--", lw=0.8, label="rotor")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("speed [rpm]")
    ax.set_title(f"Sleeve speed at {PLANE} (paper Fig. 5)")
    ax.legend(fontsize=8)
    names.append(_save(fig, out / "friction_sleeve_speed.png"))
    return names


def plot_friction_response(a: dict, out: Path) -> str:
    rows = a["friction_observables"][f"{PRIMARY_SLIP}, drag on"]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), constrained_layout=True)
    for tag, st in (("no_whirl", "C0o"), ("whirl", "C3s")):
        pts = [(r["friction"], r[tag]) for r in rows if r[tag] is not None]
        if not pts:
            continue
        mu = [p[0] for p in pts]
        nan = lambda v: np.nan if v is None else v  # noqa: E731
        axes[0].plot(mu, [nan(p[1]["max_displacement_um"]) for p in pts], st, ms=3,
                     label=tag.replace("_", " "))
        axes[1].plot(mu, [nan(p[1]["peak_contact_force_N"]) for p in pts], st, ms=3,
                     label=tag.replace("_", " "))
    axes[0].set_ylabel("median max displacement [µm]")
    axes[1].set_ylabel("median peak contact force [N]")
    for ax in axes:
        ax.set_xlabel("friction coefficient μ")
        ax.legend(fontsize=8)
    fig.suptitle(f"Response against friction, split by outcome ({PRIMARY_SLIP} slip, bearing drag on)")
    return _save(fig, out / "friction_response.png")


def plot_support(runs: dict[float, Result], key: str, out: Path) -> list[str]:
    vals = sorted(runs)
    stem = key.split(".")[1]
    names = [_orbit_row(runs, key, out / f"{stem}_orbits.png", width=3.6, share=False)]

    fig, axes = plt.subplots(2, 1, figsize=(9, 6), sharex=True, constrained_layout=True)
    for v in vals:
        r = runs[v]
        axes[0].plot(r.t, r.orbit(PLANE)[:, 1] * 1e6, lw=0.7, label=f"{v:g}")
        axes[1].plot(r.t, r.contact_force(PLANE), lw=0.5, label=f"{v:g}")
    axes[0].axhline(-PAPER_SOFT_Y_UM, color="k", ls=":", lw=0.8)
    axes[0].set_ylabel(f"Y at {PLANE} [µm]")
    axes[1].set_ylabel("contact force [N]")
    axes[1].set_xlabel("time [s]")
    axes[0].legend(title=key, fontsize=8)
    names.append(_save(fig, out / f"{stem}_response.png"))
    return names


def plot_sensitivity(a: dict, out: Path) -> str:
    rows = a["sensitivity"]
    labels = [f"{r['factor']}: {r['setting']}" if r["factor"] != "nominal" else "nominal" for r in rows]
    th = [r["onset"].get("threshold") if r["onset"] else None for r in rows]
    cf = [r["onset"].get("certain_from") if r["onset"] else None for r in rows]
    soft = [r["soft_max_y_displacement_um"] for r in rows]
    fig, axes = plt.subplots(1, 2, figsize=(12, 0.32 * len(rows) + 1.6), sharey=True,
                             constrained_layout=True)
    y = np.arange(len(rows))[::-1]
    nan = lambda v: np.nan if v is None else v  # noqa: E731
    axes[0].plot([nan(v) for v in th], y, "C0o", label="50 % whirl probability")
    axes[0].plot([nan(v) for v in cf], y, "C3|", ms=10, label="every drop whirls from")
    axes[0].axvline(PAPER_THRESHOLD, color="k", ls="--", lw=0.8, label="paper 0.39")
    axes[0].set_xlabel("friction coefficient μ")
    axes[0].legend(fontsize=7, loc="lower right")
    axes[0].grid(True, axis="x", alpha=0.3)
    axes[1].plot([nan(v) for v in soft], y, "C2o")
    axes[1].axvline(PAPER_SOFT_Y_UM, color="k", ls="--", lw=0.8, label="paper ≈ 600 µm")
    axes[1].legend(fontsize=7, loc="lower right")
    axes[1].grid(True, axis="x", alpha=0.3)
    axes[1].set_xlabel(f"max Y at {_soft_case(a)} [µm]")
    axes[0].set_yticks(y)
    axes[0].set_yticklabels(labels, fontsize=7)
    return _save(fig, out / "sensitivity.png")


def _yes_no(decision) -> str:
    """A whirl decision for the tables: yes, no, or n/a (left validity undecided)."""
    return "n/a" if decision is None else "yes" if decision else "no"


def _whirls(r: Result) -> bool:
    from ...metrics import compute_metrics, whirled
    return whirled(compute_metrics(r))


# ---------------------------------------------------------------------------------- report --
def _f(x, spec=".2f"):
    return "–" if x is None else format(x, spec)


def _nominal(r: dict, key: str, spec: str = ".0f") -> str:
    """A nominal drop's number, or "n/a (beyond validity at t = …)" when the drop left the contact
    laws' validity (``physics.runs.study.checks.beyond_validity``)."""
    t = r.get("beyond_validity_at_s")
    return f"n/a (beyond validity at t = {t:.3f} s)" if t is not None else _f(r.get(key), spec)


def _num(x: float) -> str:
    """A scene value as the report writes it: 0.25, 5000, 5e7."""
    mantissa, _, exp = f"{x:g}".partition("e")
    return mantissa + (f"e{int(exp)}" if exp else "")


def _held(a: dict, key: str) -> str:
    """The scene's value of a key the other studies hold fixed (``analyse()["held"]``)."""
    return _num(a["held"][key])


def _soft_case(a: dict) -> str:
    return f"K_s = {_num(SOFT)}, μ = {_held(a, 'contact.friction')}"


def _checks_text(a: dict) -> str:
    """The drop checks of every run, per study (``analyse()["warnings"]``)."""
    total = warnings_note(a["warnings"]["total"])
    if not total:
        return "Drop checks (the warnings `rotordrop drop` prints): no drop flagged.\n"
    per = "; ".join(f"{study}: {counts_text(counts)}" for study, counts in a["warnings"].items()
                    if study != "total" and any(counts.values()))
    return (f"{total[0].upper()}{total[1:]} (per study: {per}). These are the warnings `rotordrop drop` prints for the "
            "run's command; the drops are in the statistics, except those without a fault, which "
            "count as failed, and those past a contact law's validity bound (penetration, "
            "dry_whip), which count in the whirl probability but in no force or displacement "
            "number.\n")


def write_report(a: dict, out: Path, figures: dict[str, list[str]], meta: dict) -> Path:
    """The Markdown report (every number in it is in study.json)."""
    L: list[str] = []
    w = L.append
    th = a["friction_threshold"]
    w("# The paper's drop study, reproduced\n")
    w(f"Kärkkäinen, Sopanen & Mikkola, §V, on the `{a['scene']}` scene"
      + (" with " + ", ".join(f"`--set {k}={v}`" for k, v in a["overrides"].items())
         if a["overrides"] else "")
      + f". {a['runs']['total']} drops, {a['runs']['failed']} failed; "
      f"{meta['wall_s']:.0f} s wall {meta['where']}"
      + (" (**quick** mode: coarse grid, small ensembles — statistics are indicative only)"
         if meta["quick"] else "") + ".\n")
    w(_checks_text(a))
    w("## Summary\n")
    w("| quantity | paper | ours |\n|---|---|---|")
    w(f"| whirl threshold (50 % probability), kinematic slip (default) | 0.39 | {_f(th['kinematic'])} |")
    w(f"| whirl threshold (50 % probability), paper's eq. 19 (creates energy) | – | {_f(th['paper'])} |")
    soft = next((r for r in a["support_stiffness"] if r["stiffness"] == SOFT), {})
    w(f"| max Y at {_soft_case(a)} | ≈ 600 µm | {_f(soft.get('max_y_displacement_um'), '.0f')} µm |")
    n_ok = sum(c["reproduced"] for c in a["claims"])
    w(f"| claims reproduced | – | {n_ok} of {len(a['claims'])} |\n")
    w(meta.get("calibration", ""))

    w("\n## 1. Friction\n")
    w(f"μ = {a['plan']['frictions'][0]:g} … {a['plan']['frictions'][-1]:g} "
      f"({len(a['plan']['frictions'])} values), both slip laws, bearing friction torque on and off, "
      f"{a['plan']['members']} drops per μ. The drops of an ensemble differ only in the rotor's "
      "angular position at the fault (`unbalance.angle_deg`, stratified over 360°) and the fault "
      "time (`amb.off_time`, ±0.5 ms jitter); the same members are used at every μ. A drop whirls "
      "when the rotor makes at least 3 net backward revolutions in its sleeve.\n")
    w(f"![whirl probability]({figures['probability'][0]})\n")
    w("| slip, bearing drag | 50 % crossing | logistic μ50 (width) | lowest μ that whirls | "
      "every drop whirls from | 50 % crossings |\n|---|---|---|---|---|---|")
    for k, o in a["friction_onset"].items():
        w(f"| {k} | {_f(o.get('threshold'))} | {_f(o.get('logistic_mu50'))} "
          f"({_f(o.get('logistic_width'), '.3f')}) | {_f(o.get('lowest_whirl'))} | "
          f"{_f(o.get('certain_from'))} | {o.get('crossings', '–')} |")
    agree = a.get("slip_law_agreement")
    if agree is not None:
        w(f"\nThe paper and kinematic slip laws give the same whirl decision in {100 * agree:.1f} % of "
          "the drops: the decision falls during the first bounces, while the sleeve still slips at "
          "full friction (slip far above the regularisation threshold), where both laws give the "
          "same force μF_r. They differ once the sleeve approaches the rotor's surface speed "
          "(later forces, spin-down).")
    w("\nThe threshold is where the whirl probability reaches 50 % (linear interpolation "
      "between grid points), named only where the probability never falls along the grid; the "
      "logistic fit uses every drop. More than one 50 % crossing means whirling and non-whirling "
      "μ interleave below the μ from which every drop whirls: whirl is then a probability over "
      "μ, not a threshold (- in the column).\n")
    w(_undecided_note(a["whirl_probability"]))
    w(f"![orbits]({figures['friction'][0]})\n")
    w(f"![forces]({figures['friction'][1]})\n")
    w(f"![sleeve speed]({figures['friction'][2]})\n")
    w(f"![response]({figures['response'][0]})\n")

    w(f"\n## 2. Support stiffness (μ = {_held(a, 'contact.friction')}, "
      f"C_s = {_held(a, 'support.damping')} N s/m)\n")
    base_f = next((r.get("peak_contact_force_N") for r in a["support_stiffness"]
                   if r["stiffness"] == BASE), None)
    soft_f = soft.get("peak_contact_force_N")
    w("| K_s [N/m] | max Y [µm] | max radial [µm] | peak F_r [N] | ÷ base | ÷ soft | whirl | "
      "ensemble: whirl prob., peak F_r median (min–max), beyond validity |\n"
      "|---|---|---|---|---|---|---|---|")
    for r in a["support_stiffness"]:
        e = r.get("ensemble", {})
        pf = e.get("peak_contact_force_N", {})
        f = r.get("peak_contact_force_N")
        w(f"| {r['stiffness']:.0e} | {_nominal(r, 'max_y_displacement_um')} | "
          f"{_nominal(r, 'max_displacement_um')} | {_nominal(r, 'peak_contact_force_N')} | "
          f"{_f(f / base_f if f and base_f else None)} | {_f(f / soft_f if f and soft_f else None)} | "
          f"{_yes_no(r.get('backward_whirl'))} | {_f(e.get('whirl_probability'))}, "
          f"{_f(pf.get('median'), '.0f')} ({_f(pf.get('min'), '.0f')}–{_f(pf.get('max'), '.0f')}), "
          f"{e.get('beyond_validity', 0)} |")
    w("\nPaper: K_s = 5e8 gives 2× the base-case contact force and ≈ 5× the soft case; the soft "
      "case peaks near 600 µm just after the drop.\n")
    w(f"![stiffness orbits]({figures['stiffness'][0]})\n")
    w(f"![stiffness response]({figures['stiffness'][1]})\n")

    w(f"\n## 3. Support damping (μ = {_held(a, 'contact.friction')}, "
      f"K_s = {_held(a, 'support.stiffness')} N/m)\n")
    w("| C_s [N s/m] | peak F_r [N] | max radial [µm] | whirl prob. | force settling [s] | "
      "RMS radial speed in sleeve [mm/s] | contact losses |\n|---|---|---|---|---|---|---|")
    for r in a["support_damping"]:
        e = r.get("ensemble", {})
        med = lambda k: e.get(k, {}).get("median")  # noqa: E731
        w(f"| {r['damping']:g} | {_nominal(r, 'peak_contact_force_N')} | "
          f"{_nominal(r, 'max_displacement_um')} | {_f(e.get('whirl_probability'))} | "
          f"{_f(med('force_settling_s'), '.3f')} | {_f(med('radial_speed_rms_mm_s'), '.1f')} | "
          f"{_f(med('separations'), '.0f')} |")
    w("\nNominal drop for peak force and displacement; ensemble medians for the rest. Force "
      "settling: time after the fault after which the contact force's mean and standard "
      "deviation over every 10 ms window stay within 25 % of its mean over the second half of "
      "the run.\n")
    w(f"![damping orbits]({figures['damping'][0]})\n")
    w(f"![damping response]({figures['damping'][1]})\n")

    w("\n## 4. Claims\n")
    w("| # | paper says | paper | ours | reproduced | criterion | why not |\n"
      "|---|---|---|---|---|---|---|")
    for i, c in enumerate(a["claims"], 1):
        w(f"| {i} | {c['claim']} | {c['paper']} | {c['ours']} | "
          f"{'yes' if c['reproduced'] else '**no**'} | {c['criterion']} | {c['why']} |")

    w("\n## 5. Sensitivity to assumed parameters and calibration\n")
    w(f"Each assumed [A] parameter moved within its plausible range, one at a time, around the "
      f"`{a['scene']}` scene: whirl onset from μ = {a['plan']['sensitivity_frictions'][0]:g} … "
      f"{a['plan']['sensitivity_frictions'][-1]:g} with {a['plan']['sensitivity_members']} drops "
      f"per μ ({PRIMARY_SLIP} slip), and the soft-support response ({_soft_case(a)}, median of "
      f"{a['plan']['soft_members']}).\n")
    w(f"![sensitivity]({figures['sensitivity'][0]})\n")
    w("| parameter | value | 50 % crossing | every drop whirls from | lowest whirl | "
      "max Y soft [µm] | plausible range |\n|---|---|---|---|---|---|---|")
    ranges = meta.get("ranges", {})
    for r in a["sensitivity"]:
        o = r["onset"] or {}
        w(f"| {r['factor']} | {r['setting']} | {_f(o.get('threshold'))} | "
          f"{_f(o.get('certain_from'))} | {_f(o.get('lowest_whirl'))} | "
          f"{_f(r['soft_max_y_displacement_um'], '.0f')} | {ranges.get(r['factor'], '')} |")

    w("\n## 6. Re-running single drops\n")
    w("Every drop of the study is an ordinary scene; `study.json` holds the command for the "
      "interesting ones. For example:\n")
    for label, cmd in meta.get("commands", []):
        w(f"- {label}:\n\n  ```\n  {cmd}\n  ```")
    if a["failures"]:
        w("\n## Failed runs\n")
        w(f"{len(a['failures'])} run(s) failed and are excluded from the statistics:\n")
        for f in a["failures"][:50]:
            w(f"- `{f['command']}`: {f['error'].splitlines()[0]}")
    path = out / "report.md"
    path.write_text("\n".join(L) + "\n")
    return path


def plot_parametric(report: dict, axes, out: Path, name: str = "sweep.png",
                    limits: dict | None = None) -> str:
    """``rotordrop study sweep``: whirl probability, peak contact force and maximum displacement
    over the varied keys (1 key: curves with the members' range; 2 keys: annotated maps). Cells
    with failed drops are marked (an x on the curves, "k failed" in the maps); a statistic over
    no drop that ran is left out ("-")."""
    cells = report["cells"]
    panels = [("whirl_probability", "whirl probability")] + [
        (key, PLANE_KPIS[key]) for key in ("peak_contact_force_N", "max_displacement_um")]
    failed = np.array([c["failed"] for c in cells])

    def value(c, key, stat="median"):
        v = c[key]
        return np.nan if v is None else (v if key == "whirl_probability" else v[stat])

    def column(key, stat="median"):
        return np.array([value(c, key, stat) for c in cells], float)

    def ticks(axis, most=30):
        """Positions (indices) and labels of the ticks of a map or choice axis, at most ``most``."""
        step = -(-len(axis.values) // most)
        return range(0, len(axis.values), step), [value_label(v) for v in axis.values[::step]]

    title = f"{report['scene']}: {report['members']} drops per cell" + (
        f", {failed.sum()} failed (marked)" if failed.any() else "")
    if len(axes) == 1:
        a = axes[0]
        x = np.asarray(a.values, float) if a.numeric else np.arange(len(a.values))
        fig, axs = plt.subplots(1, 3, figsize=(13, 3.8), constrained_layout=True)
        for ax, (key, label) in zip(axs, panels):
            y = column(key)
            ax.plot(x, y, "o-" if a.numeric else "o", ms=4)
            if key == "whirl_probability":
                ax.set_ylim(-0.05, 1.05)
            elif a.numeric and len(x) > 1:
                ax.fill_between(x, column(key, "min"), column(key, "max"), alpha=0.25,
                                label="members' range")
            else:                        # a band needs neighbours: whiskers for choices or one value
                ax.errorbar(x, y, yerr=[y - column(key, "min"), column(key, "max") - y], fmt="none",
                            capsize=4, label="members' range")
            if failed.any():             # at the bottom, also where no drop of the cell ran
                ax.plot(x[failed > 0], np.full(np.count_nonzero(failed), 0.03), "x", color="C3",
                        transform=ax.get_xaxis_transform(), label="cell with failed drops")
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=7)
            ax.set_xlabel(a.key)
            ax.set_ylabel(label + ("" if key == "whirl_probability" else " (median)"))
            if not a.numeric:
                ax.set_xticks(*ticks(a))
            elif min(x) > 0 and max(x) / min(x) > 50:
                ax.set_xscale("log")
            ax.grid(alpha=0.3)
        fig.suptitle(title, fontsize=10)
    else:
        (a, b), n_a, n_b = axes, len(axes[0].values), len(axes[1].values)
        annotate = max(n_a, n_b) <= 30          # beyond that the numbers would not fit their cells
        fig, axs = plt.subplots(3, 1, figsize=(min(16.0, max(6.0, 3.0 + 0.9 * n_a)),
                                               3 * min(6.0, 1.4 + 0.35 * n_b)), constrained_layout=True)
        F = failed.reshape(n_a, n_b).T
        for ax, (key, label) in zip(axs, panels):
            M = column(key).reshape(n_a, n_b).T
            lo, hi = (0.0, 1.0) if key == "whirl_probability" else (limits or {}).get(key, (None, None))
            im = ax.imshow(M, origin="lower", aspect="auto", cmap="Reds", vmin=lo, vmax=hi)
            fig.colorbar(im, ax=ax, fraction=0.05)      # first: it settles the colour limits
            if annotate:
                for j, i in np.ndindex(M.shape):
                    text = ("-" if np.isnan(M[j, i]) else f"{M[j, i]:.2f}" if key == "whirl_probability"
                            else f"{M[j, i]:.0f}") + (f"\n{F[j, i]} failed" if F[j, i] else "")
                    dark = np.isfinite(M[j, i]) and im.norm(M[j, i]) > 0.6
                    ax.text(i, j, text, ha="center", va="center", fontsize=6,
                            color="white" if dark else "black")
            elif F.any():
                jj, ii = np.nonzero(F)
                ax.plot(ii, jj, "x", color="C0", ms=4, label="cell with failed drops")
                ax.legend(fontsize=7)
            ax.set_xticks(*ticks(a), rotation=45, fontsize=7)
            ax.set_yticks(*ticks(b), fontsize=7)
            ax.set_xlabel(a.key)
            ax.set_ylabel(b.key)
            ax.set_title(label + ("" if key == "whirl_probability" else ", median"), fontsize=9)
        fig.suptitle(title, fontsize=10)
    return _save(fig, out / name)
