"""Campbell diagram of a scene's rotor on its AMB springs: simulated against linearised.

    python docs/examples/campbell.py [--scene asymmetric] [--out out/campbell] [--max-rpm 30000]
                                     [--points 7] [--damped]

For spin speeds from 0 to ``--max-rpm`` the rotor of ``--scene`` is held by its AMBs as undamped
springs (no gravity, unbalance or friction), kicked, and its whirl frequencies are read from the
simulated free response (FFT, signed: forward > 0); the lines are the linearised rotor's
(physics/campbell.py), with the 1x line and the running speed ``rotor.speed_rpm``.

* Rigid rotor: the four rigid-body whirl frequencies from the tilt a + ib against the roots of
  the frequency equation. About 15 s on one core.
* Flexible rotor (``rotor.model = "flexible"``, e.g. ``--scene machine-flexible``): the elastic
  modes join. Lines: the reduced floating-frame model the drop kernel integrates; circles: the
  full finite-element model it was reduced from; black dots: the kernel's free responses (the
  rigid-body modes from the orbit at the AMB1 station, the first bending pair from a kick of the
  elastic coordinates; modal damping off). ``--damped`` keeps the scene's AMB damping and modal
  damping (lines and circles only; the damping ratios go into the CSV). About a minute on one core.

Writes ``campbell.png``, ``campbell.json`` (per simulated speed: simulated and linearised
frequencies, their largest relative difference; flexible: the full model's too and the first
forward bending mode at the running speed) and ``campbell.csv`` (the lines: per speed each
mode's frequency, for a flexible rotor also its damping ratio and elastic energy share).
"""
from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from tqdm.auto import tqdm  # noqa: E402

from physics import load_scene  # noqa: E402
from physics.campbell import (BENDING_SHARE, SPRINGS_ONLY, first_bending,  # noqa: E402
                              flexible_free_frequencies, flexible_whirl, free_response,
                              identified_frequencies, whirl_frequencies)

RPM = np.pi / 30
HZ = 1 / (2 * np.pi)
T_END = 4.0                      # s of free response per speed (resolution ~0.25 Hz before fit)
N_MODES = 4                      # flexible: forward and backward modes drawn per direction


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="asymmetric")
    ap.add_argument("--out", default="out/campbell")
    ap.add_argument("--max-rpm", type=float, default=30000.0)
    ap.add_argument("--points", type=int, default=7, help="simulated speeds")
    ap.add_argument("--damped", action="store_true",
                    help="flexible rotor: keep amb.damping and flexible.damping_ratio (no simulation)")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    flexible = load_scene(args.scene).rotor.model == "flexible"
    if flexible:
        flexible_diagram(args, out)
    else:
        rigid_diagram(args, out)


def rigid_diagram(args, out: Path) -> None:
    scene = load_scene(args.scene, {**SPRINGS_ONLY, "solver.rtol": 1e-9})
    rows = []
    for rpm in tqdm(np.linspace(0.0, args.max_rpm, args.points), desc="free responses"):
        t, Y, m = free_response(scene, rpm * RPM, T_END)
        found = identified_frequencies(t, Y[:, m.index("a")], Y[:, m.index("b")])
        expected = whirl_frequencies(scene, rpm * RPM)
        rows.append(dict(rpm=float(rpm), simulated_hz=(found * HZ).tolist(),
                         linearised_hz=(expected * HZ).tolist(),
                         max_rel_difference=float(np.abs(found / expected - 1).max())))
    (out / "campbell.json").write_text(json.dumps(dict(scene=args.scene, overrides=SPRINGS_ONLY,
                                                       speeds=rows), indent=2))

    fig, ax = plt.subplots(figsize=(8, 5.5), constrained_layout=True)
    speeds = np.linspace(0.0, args.max_rpm, 200)
    lines = np.array([whirl_frequencies(scene, s * RPM) for s in speeds]) * HZ
    labels = ("backward conical", "backward cylindrical", "forward cylindrical", "forward conical")
    write_csv(out / "campbell.csv", speeds, {f"{label.replace(' ', '_')}_hz": np.abs(lines[:, j])
                                             for j, label in enumerate(labels)})
    for j, label in enumerate(labels):
        ax.plot(speeds, np.abs(lines[:, j]), ls="--" if lines[0, j] < 0 else "-",
                label=f"{label} (linearised)")
    for r in rows:
        ax.plot([r["rpm"]] * 4, np.abs(r["simulated_hz"]), "ko", ms=4)
    ax.plot([], [], "ko", ms=4, label="simulated free response")
    speed_lines(ax, scene, speeds)
    ax.set_ylim(0, 1.1 * np.abs(lines).max())
    ax.set_title(f"Campbell diagram, {args.scene} preset on its AMB springs")
    ax.legend(fontsize=8)
    fig.savefig(out / "campbell.png", dpi=110)
    worst = max(r["max_rel_difference"] for r in rows)
    print(f"largest simulated/linearised difference {worst:.1e}; wrote {out}/campbell.png, .json, .csv")


def flexible_diagram(args, out: Path) -> None:
    overrides = dict(SPRINGS_ONLY, **{"solver.rtol": 1e-9, "flexible.damping_ratio": 0.0})
    if args.damped:
        overrides = {k: v for k, v in overrides.items()
                     if k not in ("amb.damping", "flexible.damping_ratio")}
    scene = load_scene(args.scene, overrides)
    run = scene.rotor.speed_rpm
    speeds = np.unique(np.append(np.linspace(0.0, args.max_rpm, 201), run))
    reduced = flexible_whirl(scene, speeds * RPM, N_MODES)
    points = np.linspace(0.0, args.max_rpm, args.points)
    full = flexible_whirl(scene, points * RPM, N_MODES, full=True)
    at_run = flexible_whirl(scene, [run * RPM], N_MODES)
    at_run_full = flexible_whirl(scene, [run * RPM], N_MODES, full=True)
    bend, bend_full = first_bending(at_run)[0] * HZ, first_bending(at_run_full)[0] * HZ
    rows = []
    for i, rpm in enumerate(tqdm(points, desc="free responses", disable=args.damped)):
        lin = signed(full, i, 3)
        row = dict(rpm=float(rpm), full_hz=(lin * HZ).tolist(),
                   reduced_hz=(signed(flexible_whirl(scene, [rpm * RPM], N_MODES), 0, 3)
                               * HZ).tolist())
        row["reduced_vs_full"] = float(np.abs(np.array(row["reduced_hz"]) / row["full_hz"] - 1).max())
        if not args.damped:
            found = flexible_free_frequencies(scene, rpm * RPM, T_END)
            row["simulated_hz"] = (found * HZ).tolist()
            row["max_rel_difference"] = float(np.abs(found / (np.array(row["reduced_hz"]) / HZ)
                                                     - 1).max())
        rows.append(row)
    (out / "campbell.json").write_text(json.dumps(dict(
        scene=args.scene, overrides=overrides, model="flexible", running_speed_rpm=run,
        first_forward_bending_hz=bend, first_forward_bending_full_hz=bend_full,
        first_forward_bending_ratio=bend / (run / 60.0), speeds=rows), indent=2))
    columns = {}
    for d in ("forward", "backward"):
        for j in range(N_MODES):
            columns[f"{d}_{j + 1}_hz"] = reduced[d][:, j] * HZ
            columns[f"{d}_{j + 1}_damping_ratio"] = reduced[f"{d}_damping"][:, j]
            columns[f"{d}_{j + 1}_elastic_share"] = reduced[f"{d}_elastic"][:, j]
    write_csv(out / "campbell.csv", speeds, columns)

    fig, ax = plt.subplots(figsize=(8, 5.5), constrained_layout=True)
    k = int(np.argmin(np.abs(speeds - run)))
    for j in range(N_MODES):
        kind = "bending" if reduced["forward_elastic"][k, j] > BENDING_SHARE else "rigid-body"
        ax.plot(speeds, reduced["forward"][:, j] * HZ, "-", color=f"C{j}",
                label=f"mode {j + 1} ({kind})")
        ax.plot(speeds, reduced["backward"][:, j] * HZ, "--", color=f"C{j}")
        ax.plot(points, full["forward"][:, j] * HZ, "o", mfc="none", color=f"C{j}", ms=6)
        ax.plot(points, full["backward"][:, j] * HZ, "o", mfc="none", color=f"C{j}", ms=6)
    ax.plot([], [], "-", color="0.4", label="forward whirl (reduced model)")
    ax.plot([], [], "--", color="0.4", label="backward whirl (reduced model)")
    ax.plot([], [], "o", mfc="none", color="0.4", label="full FE model")
    if not args.damped:
        for r in rows:
            ax.plot([r["rpm"]] * len(r["simulated_hz"]), np.abs(r["simulated_hz"]), "k.", ms=4)
        ax.plot([], [], "k.", ms=4, label="simulated free response")
    speed_lines(ax, scene, speeds)
    ax.plot([run], [bend], "k*", ms=10,
            label=f"first forward bending {bend:.1f} Hz = {bend / (run / 60):.2f} x")
    ax.set_ylim(0, 1.1 * np.nanmax(reduced["forward"]) * HZ)
    damping = "AMB and modal damping" if args.damped else "undamped"
    ax.set_title(f"Campbell diagram, {args.scene} (flexible, {damping}) on its AMB springs",
                 fontsize=10)
    ax.legend(fontsize=7, ncol=2)
    fig.savefig(out / "campbell.png", dpi=110)
    worst = max(r["reduced_vs_full"] for r in rows)
    sim = "" if args.damped else (f"; simulated/reduced "
                                  f"{max(r['max_rel_difference'] for r in rows):.1e}")
    print(f"first forward bending at {run:g} rpm: {bend:.2f} Hz ({bend / (run / 60):.3f} x the "
          f"running speed; full FE model {bend_full:.2f} Hz); largest reduced/full difference "
          f"{worst:.1e}{sim}; wrote {out}/campbell.png, .json, .csv")


def signed(whirl: dict, i: int, n: int) -> np.ndarray:
    """The first ``n`` forward and backward frequencies at speed index ``i``, signed (backward
    < 0), ascending."""
    return np.sort(np.concatenate([-whirl["backward"][i, :n], whirl["forward"][i, :n]]))


def speed_lines(ax, scene, speeds: np.ndarray) -> None:
    """The 1x line, the running speed, labels and grid."""
    ax.plot(speeds, speeds / 60.0, "k:", lw=0.8, label="1x spin")
    ax.axvline(scene.rotor.speed_rpm, color="0.5", lw=0.8, ls="-.",
               label=f"running speed {scene.rotor.speed_rpm:g} rpm")
    ax.set_xlabel("spin speed [rpm]")
    ax.set_ylabel("|whirl frequency| [Hz]")
    ax.grid(alpha=0.3)


def write_csv(path: Path, rpm: np.ndarray, columns: dict) -> None:
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["rpm", *columns])
        for i, s in enumerate(rpm):
            w.writerow([f"{s:.6g}", *(f"{c[i]:.8g}" for c in columns.values())])


if __name__ == "__main__":
    main()
