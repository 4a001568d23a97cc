"""The home page's picture of a drop: the paper's rotor at μ = 0.3 with the stator contact on (so
the run stays physical where the rotor reaches the AMB air gap), its orbit at retainer bearing
RB1 whirling backward around the clearance circle (the housings give), and the rotor-sleeve
contact force.

    python docs/examples/home_drop.py            # simulates, writes the data, draws the figure
    python docs/examples/home_drop.py --draw     # only redraws the figure from the data

Data: ``docs/data/home-drop.csv`` (time since the fault [s], the rotor axis at RB1 [µm], the
contact force [N]; every 2nd output sample) and ``docs/data/home-drop.json`` (scene, overrides,
clearance, the run's backward-whirl verdict); figure: ``docs/img/home-drop.png``.
"""
from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path

import numpy as np

DOCS = Path(__file__).resolve().parents[1]
DATA, META, FIGURE = (DOCS / "data" / "home-drop.csv", DOCS / "data" / "home-drop.json",
                      DOCS / "img" / "home-drop.png")
SCENE, T_END, EVERY = "paper", 0.5, 2
OVERRIDES = {"contact.friction": 0.3, "effects.stator_contact": True}


def simulate_drop() -> tuple[dict, np.ndarray]:
    """(metadata, rows of t [s], x [µm], y [µm], F [N]) of the drop, from the fault on."""
    from physics import compute_metrics, load_scene, simulate
    result = simulate(load_scene(SCENE, OVERRIDES), t_end=T_END)
    after = result.t >= (result.t_fault or 0.0)
    xy = result.orbit("RB1")[after] * 1e6
    rows = np.column_stack([result.t[after] - (result.t_fault or 0.0), xy,
                            result.contact_force("RB1")[after]])[::EVERY]
    m = compute_metrics(result)
    meta = {"scene": SCENE, "overrides": OVERRIDES, "t_end_s": T_END, "every_nth_sample": EVERY,
            "clearance_um": result.model.scene.contact.clearance * 1e6,
            "backward_whirl": m["backward_whirl"], "warnings": m["warnings"],
            "peak_contact_force_N": m["planes"]["RB1"]["peak_contact_force_N"],
            "command": "python docs/examples/home_drop.py"}
    return meta, rows


def write(meta: dict, rows: np.ndarray, data: Path = DATA, meta_path: Path = META) -> None:
    with data.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["t_s", "x_um", "y_um", "contact_force_N"])
        w.writerows([[f"{v:.6g}" for v in row] for row in rows])
    meta_path.write_text(json.dumps(meta, indent=1, sort_keys=True) + "\n")


def read(data: Path = DATA, meta_path: Path = META) -> tuple[dict, np.ndarray]:
    return json.loads(meta_path.read_text()), np.loadtxt(data, delimiter=",", skiprows=1)


def draw(meta: dict, rows: np.ndarray, path: Path = FIGURE) -> Path:
    """Orbit with the clearance circle beside the contact force against time."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t, x, y, force = rows.T
    c = meta["clearance_um"]
    fig, (orbit, forces) = plt.subplots(1, 2, figsize=(11, 3.9), width_ratios=[1, 1.9],
                                        constrained_layout=True)
    a = np.linspace(0.0, 2.0 * np.pi, 361)
    orbit.plot(c * np.cos(a), c * np.sin(a), "k--", lw=1.0, label="clearance")
    orbit.plot(x, y, lw=0.4, color="C0")
    orbit.set(aspect="equal", xlabel="x [µm]", ylabel="y [µm]",
              title="rotor orbit at retainer bearing RB1")
    orbit.legend(loc="upper right", fontsize=8)
    forces.plot(1e3 * t, 1e-3 * force, lw=0.5, color="C3")
    forces.set(xlabel="time after the AMBs fail [ms]", ylabel="contact force [kN]",
               title=f"rotor-sleeve contact force at RB1 (μ = "
                     f"{meta['overrides']['contact.friction']:g}, stator contact on: "
                     f"{'backward whirl' if meta['backward_whirl'] else 'no backward whirl'})")
    forces.grid(alpha=0.3)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draw", action="store_true", help="only redraw the figure from the data")
    args = ap.parse_args()
    if not args.draw:
        write(*simulate_drop())
    print(f"wrote {draw(*read())}")
