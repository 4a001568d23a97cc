"""Figures of a drop (matplotlib, Agg backend, PNG), as in the paper's Figs. 3-5."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .model import PLANES  # noqa: E402
from .results import Result  # noqa: E402

RPM = 30.0 / np.pi


def plot_orbits(result: Result, path: Path, title: str = "") -> Path:
    """Rotor orbit at RB1 and RB2 after the fault with the static clearance circle (Fig. 3)."""
    c_um = result.model.scene.contact.clearance * 1e6
    fig, axes = plt.subplots(1, 2, figsize=(10, 5), constrained_layout=True)
    post = result.t >= (result.t_fault or 0.0)
    circ = np.linspace(0, 2 * np.pi, 361)
    for ax, p in zip(axes, PLANES):
        o = result.orbit(p)[post] * 1e6
        ax.plot(o[:, 0], o[:, 1], lw=0.5)
        ax.plot(c_um * np.cos(circ), c_um * np.sin(circ), "k--", lw=1, label="clearance")
        ax.set_aspect("equal")
        ax.set_xlabel("X [µm]")
        ax.set_ylabel("Y [µm]")
        ax.set_title(f"{p} {title}".strip())
        ax.legend(loc="upper right", fontsize=8)
    return _save(fig, path)


def plot_forces(result: Result, path: Path, title: str = "") -> Path:
    """Contact force at both retainer planes (Fig. 4)."""
    fig, ax = plt.subplots(figsize=(9, 4), constrained_layout=True)
    for p in PLANES:
        ax.plot(result.t, result.contact_force(p), lw=0.6, label=p)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("contact force F_r [N]")
    ax.set_title(f"Rotor-sleeve contact force {title}".strip())
    ax.legend()
    return _save(fig, path)


def plot_speeds(result: Result, path: Path, title: str = "") -> Path:
    """Rotor and sleeve spin speeds (Fig. 5)."""
    fig, ax = plt.subplots(figsize=(9, 4), constrained_layout=True)
    ax.plot(result.t, result.rotor_speed * RPM, "k", lw=1, label="rotor")
    for p in PLANES:
        ax.plot(result.t, result.sleeve_speed(p) * RPM, lw=1, label=f"sleeve {p}")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("speed [rpm]")
    ax.set_title(f"Spin speeds {title}".strip())
    ax.legend()
    return _save(fig, path)


def plot_housing(result: Result, path: Path, title: str = "") -> Path:
    """Housing displacement (X and Y) at both planes."""
    fig, ax = plt.subplots(figsize=(9, 4), constrained_layout=True)
    for p in PLANES:
        h = result.housing(p) * 1e6
        ax.plot(result.t, h[:, 0], lw=0.6, label=f"{p} X")
        ax.plot(result.t, h[:, 1], lw=0.6, label=f"{p} Y")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("housing displacement [µm]")
    ax.set_title(f"Housing motion {title}".strip())
    ax.legend(ncol=2, fontsize=8)
    return _save(fig, path)


def plot_drop(result: Result, out_dir: Path, title: str = "") -> list[Path]:
    out_dir = Path(out_dir)
    return [plot_orbits(result, out_dir / "orbits.png", title),
            plot_forces(result, out_dir / "contact_forces.png", title),
            plot_speeds(result, out_dir / "speeds.png", title),
            plot_housing(result, out_dir / "housing.png", title)]


def _save(fig, path: Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
