"""Campbell diagram of an example flexible rotor on its AMB springs: reduced model against full.

    python docs/examples/flexible_campbell.py [--rotor machine|paper] [--out out/flexible]
                                              [--max-rpm 30000] [--amb-stiffness 1e6]

The rotor (physics/flexible/examples.py) is held by linear isotropic springs at the AMB planes,
undamped. Lines: the modally reduced model (rigid modes, bending modes below 3 kHz, static
correction modes at the force planes); dots: the full finite-element model. Forward whirl
solid, backward dashed, with the 1x line. Writes ``campbell.png`` and ``campbell.json``
(frequencies in Hz per speed in rpm). A few seconds on one core.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from physics.flexible import assembly as asm  # noqa: E402
from physics.flexible import examples, modal  # noqa: E402

RPM = np.pi / 30
HZ = 1 / (2 * np.pi)
N_MODES = 4


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rotor", choices=("machine", "paper"), default="machine")
    ap.add_argument("--out", default="out/flexible")
    ap.add_argument("--max-rpm", type=float, default=30000.0)
    ap.add_argument("--amb-stiffness", type=float, default=1e6)
    args = ap.parse_args(argv)
    rotor = examples.machine_flexible() if args.rotor == "machine" else examples.paper_flexible()
    model = asm.assemble(rotor)
    k = args.amb_stiffness
    S = asm.support_matrix(model, [(model.planes[p], k, k) for p in ("amb1", "amb2")])
    red = modal.reduce(model, omega_cut=2 * np.pi * 3000)
    x, y = modal.model_whirl_dofs(model)
    rpm = np.linspace(0.0, args.max_rpm, 31)
    full = modal.campbell(model.M, model.G, model.K + S, rpm[::5] * RPM, N_MODES, x, y)
    reduced = modal.campbell(red.M, red.G, red.K + red.T.T @ S @ red.T, rpm * RPM, N_MODES, x, y,
                             T=red.T)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(7, 5))
    for j in range(N_MODES):
        ax.plot(rpm, reduced["forward"][:, j] * HZ, "C0-", label="forward" if j == 0 else None)
        ax.plot(rpm, reduced["backward"][:, j] * HZ, "C3--", label="backward" if j == 0 else None)
        ax.plot(rpm[::5], full["forward"][:, j] * HZ, "C0o", ms=4,
                label="full FE model" if j == 0 else None)
        ax.plot(rpm[::5], full["backward"][:, j] * HZ, "C3o", ms=4)
    ax.plot(rpm, rpm / 60, "k:", label="1x")
    ax.set_xlabel("speed [rpm]")
    ax.set_ylabel("whirl frequency [Hz]")
    ax.set_title(f"{rotor.name} on {k:g} N/m AMBs: reduced model ({red.size} DOF) "
                 f"vs full ({model.ndof} DOF)", fontsize=9)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "campbell.png", dpi=120)
    (out / "campbell.json").write_text(json.dumps({
        "rotor": rotor.name, "amb_stiffness": k, "rpm": rpm.tolist(),
        "forward_hz": (reduced["forward"] * HZ).tolist(),
        "backward_hz": (reduced["backward"] * HZ).tolist()}, indent=1) + "\n")
    print(f"wrote {out / 'campbell.png'} and {out / 'campbell.json'}")


if __name__ == "__main__":
    main()
