"""Campbell diagram of the rigid rotor on its AMB springs: simulated against linearised.

    python docs/examples/campbell.py [--scene asymmetric] [--out out/campbell] [--max-rpm 30000]

For spin speeds from 0 to ``--max-rpm`` the rotor of ``--scene`` is held by its AMBs as undamped
springs (no gravity, unbalance or friction), kicked, and its four whirl frequencies are read
from the simulated tilt a + ib (FFT, signed: forward > 0); the lines are the roots of the
linearised rigid rotor's frequency equation (physics/campbell.py). Writes ``campbell.png`` and
``campbell.json`` (both per speed). About 15 s on one core.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from tqdm.auto import tqdm  # noqa: E402

from physics import load_scene  # noqa: E402
from physics.campbell import (SPRINGS_ONLY, free_response, identified_frequencies,  # noqa: E402
                              whirl_frequencies)

RPM = np.pi / 30
HZ = 1 / (2 * np.pi)
T_END = 4.0                      # s of free response per speed (resolution ~0.25 Hz before fit)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="asymmetric")
    ap.add_argument("--out", default="out/campbell")
    ap.add_argument("--max-rpm", type=float, default=30000.0)
    ap.add_argument("--points", type=int, default=7, help="simulated speeds")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
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
    for j, label in enumerate(labels):
        ax.plot(speeds, np.abs(lines[:, j]), ls="--" if lines[0, j] < 0 else "-",
                label=f"{label} (linearised)")
    for r in rows:
        ax.plot([r["rpm"]] * 4, np.abs(r["simulated_hz"]), "ko", ms=4)
    ax.plot([], [], "ko", ms=4, label="simulated free response")
    ax.plot(speeds, speeds / 60.0, "k:", lw=0.8, label="1x spin")
    ax.set_xlabel("spin speed [rpm]")
    ax.set_ylabel("|whirl frequency| [Hz]")
    ax.set_ylim(0, 1.1 * np.abs(lines).max())
    ax.set_title(f"Campbell diagram, {args.scene} preset on its AMB springs")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.savefig(out / "campbell.png", dpi=110)
    worst = max(r["max_rel_difference"] for r in rows)
    print(f"largest simulated/linearised difference {worst:.1e}; wrote {out}/campbell.png, .json")


if __name__ == "__main__":
    main()
