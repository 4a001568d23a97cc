"""Figures of a drop (matplotlib, Agg backend, PNG), as in the paper's Figs. 3-5."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..ball_bearing import max_contact_pressure  # noqa: E402
from ..metrics import (ISO76_C0_PRESSURE, RPM, friction_heat, rating_pressure,  # noqa: E402
                      retainer_loading)
from ..model import F_RB, F_STATOR, PLANES, RB_SM  # noqa: E402
from ..results import AMB_PLANES, Result  # noqa: E402


def orbit_panel(ax, result: Result, plane: str, lw: float = 0.5, circle_lw: float = 1.0,
                **circle) -> None:
    """Rotor orbit at ``plane`` after the fault [µm] with the static clearance circle (Fig. 3);
    ``circle`` holds further style of the dashed circle (e.g. its legend label)."""
    o = result.orbit(plane)[result.t >= (result.t_fault or 0.0)] * 1e6
    ax.plot(o[:, 0], o[:, 1], lw=lw)
    c_um = result.model.scene.contact.clearance * 1e6
    a = np.linspace(0, 2 * np.pi, 361)
    ax.plot(c_um * np.cos(a), c_um * np.sin(a), "k--", lw=circle_lw, **circle)
    ax.set_aspect("equal")
    ax.set_xlabel("X [µm]")


def plot_orbits(result: Result, path: Path, title: str = "") -> Path:
    """Rotor orbit at RB1 and RB2 after the fault with the static clearance circle (Fig. 3)."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 5), constrained_layout=True)
    for ax, p in zip(axes, PLANES):
        orbit_panel(ax, result, p, label="clearance")
        ax.set_ylabel("Y [µm]")
        ax.set_title(f"{p} {title}".strip())
        ax.legend(loc="upper right", fontsize=8)
    return save_figure(fig, path)


def plot_amb_planes(result: Result, path: Path, title: str = "") -> Path:
    """Rotor orbit at AMB1 and AMB2 over the run with the stator's air-gap circle (amb.air_gap),
    the samples in stator contact marked (stator force > 0 with ``effects.stator_contact``, else
    every sample at or beyond the gap) and, with the effect, the stator contact force."""
    modelled = bool(result.model.I[F_STATOR])
    fig = plt.figure(figsize=(10, 8.5 if modelled else 5), constrained_layout=True)
    grid = fig.add_gridspec(2 if modelled else 1, 2, height_ratios=(2, 1) if modelled else None)
    gap_um = result.model.scene.amb.air_gap * 1e6
    a = np.linspace(0, 2 * np.pi, 361)
    for i, p in enumerate(AMB_PLANES):
        ax = fig.add_subplot(grid[0, i])
        o = result.amb_orbit(p) * 1e6
        ax.plot(o[:, 0], o[:, 1], lw=0.5)
        ax.plot(gap_um * np.cos(a), gap_um * np.sin(a), "k--", lw=1.0, label="air gap (stator)")
        touch = (result.stator_force(p) > 0.0) if modelled else (np.hypot(o[:, 0], o[:, 1]) >= gap_um)
        ax.plot(o[touch, 0], o[touch, 1], "r.", ms=2, label="stator contact")
        ax.set_aspect("equal")
        ax.set_xlabel("X [µm]")
        ax.set_ylabel("Y [µm]")
        ax.set_title(f"{p} {title}".strip())
        ax.legend(loc="upper right", fontsize=8)
    if modelled:
        ax = fig.add_subplot(grid[1, :])
        for p in AMB_PLANES:
            ax.plot(result.t, result.stator_force(p), lw=0.6, label=p)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("stator contact force [N]")
        ax.legend(fontsize=8)
    return save_figure(fig, path)


def plot_time_series(t, series: dict, ylabel: str, title: str, path: Path, **style) -> Path:
    """One figure of several labelled time series against t."""
    fig, ax = plt.subplots(figsize=(9, 4), constrained_layout=True)
    for label, values in series.items():
        ax.plot(t, values, lw=style.get("lw", 0.8), label=label)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(ylabel)
    ax.set_title(title.strip())
    ax.legend(ncol=style.get("ncol", 1), fontsize=8)
    return save_figure(fig, path)


def plot_forces(result: Result, path: Path, title: str = "") -> Path:
    """Contact force at both retainer planes (Fig. 4)."""
    return plot_time_series(result.t, {p: result.contact_force(p) for p in PLANES},
                            "contact force F_r [N]", f"Rotor-sleeve contact force {title}", path, lw=0.6)


def plot_speeds(result: Result, path: Path, title: str = "") -> Path:
    """Rotor and sleeve spin speeds (Fig. 5)."""
    series = {"rotor": result.rotor_speed * RPM}
    series.update({f"sleeve {p}": result.sleeve_speed(p) * RPM for p in PLANES})
    return plot_time_series(result.t, series, "speed [rpm]", f"Spin speeds {title}", path, lw=1.0)


def plot_housing(result: Result, path: Path, title: str = "") -> Path:
    """Housing displacement (X and Y) at both planes."""
    series = {}
    for p in PLANES:
        h = result.housing(p) * 1e6
        series[f"{p} X"], series[f"{p} Y"] = h[:, 0], h[:, 1]
    return plot_time_series(result.t, series, "housing displacement [µm]", f"Housing motion {title}",
                            path, lw=0.6, ncol=2)


def plot_retainer(result: Result, path: Path, title: str = "") -> Path:
    """Retainer-bearing loading after the fault (the whole run without one): bearing load (and
    the worst ball's load), the worst ball-race Hertz pressure against :func:`pressure_levels`
    (Sopanen-Mikkola bearing only) and the cumulative friction heat at the rotor-sleeve contact
    (physics.metrics). The legend's s0 is over the plotted samples ("-" without load)."""
    post = result.t >= (result.t_fault or 0.0)
    t = result.t[post]
    balls = result.model.I[F_RB] == RB_SM
    bearing = result.model.scene.bearing
    fig, axes = plt.subplots(3 if balls else 2, 1, figsize=(9, 8 if balls else 5.5), sharex=True,
                             constrained_layout=True)
    for i, p in enumerate(PLANES):
        s0 = retainer_loading(result, p, post)["static_safety_factor"]
        axes[0].plot(t, result.bearing_load(p)[post], lw=0.6, color=f"C{i}",
                     label=f"{p} bearing load (s0 = {'-' if s0 is None else f'{s0:.1f}'})")
        if balls:
            q = result.max_ball_load(p)[post]
            axes[0].plot(t, q, lw=0.6, ls="--", color=f"C{i}", label=f"{p} worst ball")
            axes[1].plot(t, 1e-6 * max_contact_pressure(bearing, q), lw=0.6, color=f"C{i}", label=p)
        axes[-1].plot(t, friction_heat(result, p, post), lw=1.0, color=f"C{i}", label=p)
    axes[0].set_ylabel("load [N]")
    axes[0].set_title(f"Retainer-bearing loading {title}".strip())
    if balls:
        for (label, mpa), ls in zip(pressure_levels(bearing).items(), ("--", ":")):
            axes[1].axhline(mpa, color="k", ls=ls, lw=0.8, label=label)
        axes[1].set_ylabel("worst ball-race pressure [MPa]")
    axes[-1].set_ylabel("contact friction heat [J]")
    axes[-1].set_xlabel("time [s]")
    for ax in axes:
        ax.legend(fontsize=7, ncol=2)
        ax.grid(alpha=0.3)
    return save_figure(fig, path)


def pressure_levels(bearing) -> dict[str, float]:
    """Reference lines of the pressure panel [MPa] by legend label: the model's pressure at
    s0 = 1 (:func:`physics.metrics.rating_pressure`) and ISO 76's nominal level."""
    p0 = rating_pressure(bearing) * 1e-6
    return {f"s0 = 1 (C0 = {bearing.static_load_rating * 1e-3:g} kN): {p0:.0f} MPa": p0,
            f"ISO 76 nominal C0 level {ISO76_C0_PRESSURE * 1e-6:.0f} MPa": ISO76_C0_PRESSURE * 1e-6}


def plot_thermal(result: Result, path: Path, title: str = "") -> Path:
    """effects.thermal: each sleeve's temperature rise and its friction coefficient mu(theta)."""
    fig, axes = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True, constrained_layout=True)
    for p in PLANES:
        axes[0].plot(result.t, result.temperature_rise(p), lw=1.0, label=p)
        axes[1].plot(result.t, result.friction_coefficient(p), lw=1.0, label=p)
    axes[0].set_ylabel("sleeve temperature rise [K]")
    axes[0].set_title(f"Sleeve heating {title}".strip())
    axes[1].set_ylabel("friction coefficient μ")
    axes[1].set_xlabel("time [s]")
    for ax in axes:
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
    return save_figure(fig, path)


def plot_mode_shapes(result: Result, path: Path, title: str = "") -> Path:
    """A flexible rotor's retained elastic modes (physics/flexible/floating.py): the x
    displacement of each along the shaft, scaled to a largest |x| of 1, with the retainer, AMB and
    unbalance stations and each mode's free-free frequency; the same numbers in a CSV next to
    the PNG (``z_m``, then one column per mode)."""
    from ..flexible.shafts import drop_rotor
    scene = result.model.scene
    fm = drop_rotor(scene)
    z = fm.fe.z
    shapes = fm.basis[0::2, 2:].copy()
    for j in range(fm.n_modes):
        k = int(np.argmax(np.abs(shapes[:, j])))
        shapes[:, j] /= shapes[k, j]
    names = [f"{'bending' if j < fm.n_bending else 'static correction'} {j + 1}: "
             f"{fm.omega[j] / (2 * np.pi):.1f} Hz" for j in range(fm.n_modes)]
    fig, ax = plt.subplots(figsize=(11, 5), constrained_layout=True)
    for j, name in enumerate(names):
        ax.plot(z, shapes[:, j], "-" if j < fm.n_bending else "--", lw=1.2, label=name)
    p = scene.positions
    for stations, label, style in (((p.rb1, p.rb2), "retainer", dict(color="k", ls="-")),
                                   ((p.amb1, p.amb2), "AMB", dict(color="C7", ls="-.")),
                                   ((scene.unbalance.z,), "unbalance", dict(color="C3", ls=":"))):
        for i, zs in enumerate(stations):
            ax.axvline(zs, lw=1.0, label=label if i == 0 else None, **style)
    ax.axhline(0.0, color="0.6", lw=0.5)
    ax.set_xlabel("z from the centre of mass [m]")
    ax.set_ylabel("x displacement (largest = 1)")
    ax.set_title(f"Elastic modes of the shaft {scene.flexible.shaft!r} (E x "
                 f"{scene.flexible.modulus_scale:g}; free-free, floating frame) {title}".strip(),
                 fontsize=10)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    ax.grid(alpha=0.3)
    header = ",".join(["z_m"] + [n.split(":")[0].replace(" ", "_") + "_" + n.split(": ")[1]
                                 .replace(" ", "_") for n in names])
    np.savetxt(Path(path).with_suffix(".csv"), np.column_stack([z, shapes]), delimiter=",",
               header=header, comments="", fmt="%.8g")
    return save_figure(fig, path)


def plot_drop(result: Result, out_dir: Path, title: str = "") -> list[Path]:
    out_dir = Path(out_dir)
    paths = [plot_orbits(result, out_dir / "orbits.png", title),
             plot_forces(result, out_dir / "contact_forces.png", title),
             plot_speeds(result, out_dir / "speeds.png", title),
             plot_housing(result, out_dir / "housing.png", title),
             plot_retainer(result, out_dir / "retainer.png", title),
             plot_amb_planes(result, out_dir / "amb_planes.png", title)]
    if result.has_thermal:
        paths.append(plot_thermal(result, out_dir / "thermal.png", title))
    if result.model.scene.rotor.model == "flexible":
        paths.append(plot_mode_shapes(result, out_dir / "mode_shapes.png", title))
        paths.append(paths[-1].with_suffix(".csv"))
    return paths


def save_figure(fig, path: Path) -> Path:
    """Write ``fig`` as PNG (110 dpi, creating the directory) and close it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
