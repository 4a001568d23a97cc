"""Episode view: rotor orbit at both retainer planes with the clearance circle and the AMB
stator circle, and the contact-force trace. Created only when a render mode is set."""
from __future__ import annotations

import numpy as np

from physics.scene import Scene


class Renderer:
    def __init__(self, mode: str, scene: Scene, episode_time: float):
        import matplotlib
        if mode == "rgb_array":
            from matplotlib.backends.backend_agg import FigureCanvasAgg
            from matplotlib.figure import Figure
            self.fig = Figure(figsize=(8, 4), dpi=80)
            FigureCanvasAgg(self.fig)
            self.plt = None
        else:
            import matplotlib.pyplot as plt
            if matplotlib.get_backend().lower() == "agg":
                from gymnasium import logger
                logger.warn("render_mode='human' with matplotlib's non-interactive 'agg' backend "
                            "shows nothing; set MPLBACKEND (e.g. TkAgg) or use 'rgb_array'")
            plt.ion()
            self.plt = plt
            self.fig = plt.figure(figsize=(8, 4))
        self.mode = mode
        c, g = scene.contact.clearance * 1e6, scene.amb.air_gap * 1e6
        ax_o, ax_f = self.fig.subplots(1, 2, gridspec_kw=dict(width_ratios=(1, 1.4)))
        phi = np.linspace(0, 2 * np.pi, 181)
        ax_o.plot(c * np.cos(phi), c * np.sin(phi), "k-", lw=0.8, label="clearance")
        ax_o.plot(g * np.cos(phi), g * np.sin(phi), "r--", lw=0.8, label="AMB stator")
        self.l1, = ax_o.plot([], [], lw=0.8, label="RB1")
        self.l2, = ax_o.plot([], [], lw=0.8, label="RB2")
        lim = 1.1 * g
        ax_o.set(xlim=(-lim, lim), ylim=(-lim, lim), aspect="equal", xlabel="x [µm]", ylabel="y [µm]",
                 title="orbit at the retainer planes")
        ax_o.legend(fontsize=6, loc="upper right")
        self.lf, = ax_f.plot([], [], lw=0.8)
        ax_f.set(xlim=(0, episode_time * 1e3), xlabel="time after fault [ms]",
                 ylabel="peak contact force [N]", title="contact force")
        self.ax_f = ax_f
        self.fig.tight_layout()
        self.reset()

    def reset(self) -> None:
        self.t: list[float] = []
        self.orbit: list[list[float]] = []
        self.force: list[float] = []

    def add(self, t: float, orbit: list[float], force: float) -> None:
        self.t.append(t)
        self.orbit.append(orbit)
        self.force.append(force)

    def draw(self):
        o = np.asarray(self.orbit).reshape(-1, 4) * 1e6
        self.l1.set_data(o[:, 0], o[:, 1])
        self.l2.set_data(o[:, 2], o[:, 3])
        t = np.asarray(self.t) * 1e3
        self.lf.set_data(t, self.force)
        self.ax_f.set_ylim(0, max(1.0, 1.1 * max(self.force, default=1.0)))
        self.fig.canvas.draw()
        if self.mode == "rgb_array":
            return np.asarray(self.fig.canvas.buffer_rgba())[..., :3].copy()
        self.fig.canvas.flush_events()
        return None

    def close(self) -> None:
        if self.plt is not None:
            self.plt.close(self.fig)
