"""Friction heat over a whole spin-down: a rotor sliding in seized retainers, heat off and on.

    python docs/examples/thermal_spin_down.py [--out out/thermal-spin-down] [--mu 0.3] [--t-end 70]

The paper's base case with retainers that cannot turn (``bearing.seal_torque = 50 N m``, ten
times the friction torque: a seized bearing, or a bushing-type retainer) and the kinematic slip
law: the rotor rests in the sleeves and slides on them until it stops, and all its spin energy
becomes friction heat. Three runs: ``effects.thermal`` off; on with the default law
(``thermal.mu_slope = -1e-3 /K``, mu falls as oxide films form); on with mu rising with heat
(``+2e-3 /K``, the paper's expectation). Writes ``thermal-spin-down.png`` (rotor speed, RB1
sleeve temperature and friction coefficient over time), ``thermal-spin-down.json`` (per run:
time to 1 % of the initial speed, peak temperature rise, mu range, heat audit) and
``thermal-spin-down.csv`` (the curves at 10 Hz). About 10 s on one core.
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

from physics import load_scene, simulate  # noqa: E402
from physics.metrics import RPM  # noqa: E402

SEIZED = {"bearing.seal_torque": 50.0, "effects.friction": "kinematic",
          "solver.output_rate": 1000.0}
CASES = (("heat off", {}),
         ("heat on, mu falls (-1e-3 /K)", {"effects.thermal": True}),
         ("heat on, mu rises (+2e-3 /K)", {"effects.thermal": True, "thermal.mu_slope": 2e-3}))
CSV_RATE = 10.0                  # Hz


def summary(r) -> dict:
    """Stop time (first sample below 1 % of the initial speed), RB1 heating and the heat audit."""
    w = r.rotor_speed
    below = np.flatnonzero(w < 0.01 * w[0])
    theta, mu = r.temperature_rise("RB1"), r.friction_coefficient("RB1")
    out = dict(time_to_1pct_speed_s=float(r.t[below[0]]) if len(below) else None,
               final_speed_rpm=float(w[-1] * RPM), max_temperature_rise_K=float(theta.max()),
               min_friction_coefficient=float(mu.min()), max_friction_coefficient=float(mu.max()),
               max_orbit_radius_um=float(np.hypot(*r.orbit("RB1").T).max() * 1e6))
    if r.has_thermal:
        e = r.energy()
        out.update(friction_work_J=float(e["friction_work"][-1]),
                   heat_stored_J=float(e["heat_stored"][-1]), heat_lost_J=float(e["heat_lost"][-1]))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/thermal-spin-down")
    ap.add_argument("--mu", type=float, default=0.3, help="contact.friction at ambient")
    ap.add_argument("--t-end", type=float, default=70.0, help="simulated time [s]")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    runs = {}
    for name, ov in tqdm(CASES, desc="spin-downs"):
        scene = load_scene("paper", {**SEIZED, **ov, "contact.friction": args.mu,
                                     "solver.t_end": args.t_end})
        runs[name] = simulate(scene)
    report = dict(scene="paper", overrides={**SEIZED, "contact.friction": args.mu,
                                            "solver.t_end": args.t_end},
                  cases={name: dict(overrides=ov, **summary(runs[name])) for name, ov in CASES})
    (out / "thermal-spin-down.json").write_text(json.dumps(report, indent=2))

    fig, axes = plt.subplots(3, 1, figsize=(8, 9), sharex=True, constrained_layout=True)
    for name, r in runs.items():
        axes[0].plot(r.t, r.rotor_speed * RPM, label=name)
        axes[1].plot(r.t, r.temperature_rise("RB1"))
        axes[2].plot(r.t, r.friction_coefficient("RB1"))
    axes[0].set_ylabel("rotor speed [rpm]")
    axes[1].set_ylabel("RB1 sleeve temperature rise [K]")
    axes[2].set_ylabel("RB1 friction coefficient μ")
    axes[2].set_xlabel("time [s]")
    axes[0].legend(fontsize=8)
    axes[0].set_title(f"spin-down in seized retainers, μ0 = {args.mu:g} (paper preset, "
                      "kinematic slip)")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.savefig(out / "thermal-spin-down.png", dpi=110)

    step = max(1, int(round(runs[CASES[0][0]].model.scene.solver.output_rate / CSV_RATE)))
    with open(out / "thermal-spin-down.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "t_s", "rotor_speed_rpm", "RB1_temperature_rise_K", "RB1_mu"])
        for name, r in runs.items():
            theta, mu = r.temperature_rise("RB1"), r.friction_coefficient("RB1")
            for i in range(0, len(r.t), step):
                w.writerow([name, f"{r.t[i]:.3f}", f"{r.rotor_speed[i] * RPM:.2f}",
                            f"{theta[i]:.4f}", f"{mu[i]:.5f}"])
    for name, c in report["cases"].items():
        stop = c["time_to_1pct_speed_s"]
        print(f"{name:32} stop (1 % speed) {'-' if stop is None else f'{stop:.1f} s':>8}, "
              f"RB1 +{c['max_temperature_rise_K']:.0f} K, mu {c['min_friction_coefficient']:.3f}"
              f"-{c['max_friction_coefficient']:.3f}")
    print(f"wrote {out}/thermal-spin-down.png, .json, .csv")


if __name__ == "__main__":
    main()
