"""The episode view of an environment (``render_mode`` "rgb_array" or "human"): each step's
row of :data:`rotordrop_env.render.COLUMNS` and the orbits at its monitor samples, drawn by
:class:`rotordrop_env.render.Renderer` (imported on first use: Pillow, matplotlib)."""
from __future__ import annotations

import math

import gymnasium as gym
import numpy as np

from . import kernels as K


class EpisodeView:
    """Rendering of :class:`rotordrop_env.env.RotorDropEnv` (a mixin: it reads the
    environment's arrays ``_b``, ``model``, ``scene`` and settings)."""

    _renderer = None

    def _show_step(self) -> None:
        """Record the step for the episode view (and redraw it in "human" mode)."""
        if self._renderer is not None:
            self._record()
            if self.render_mode == "human":
                self.render()

    def _record(self, step: bool = True) -> None:
        """One row of the episode view (``rotordrop_env.render.COLUMNS``) and the orbits at the
        step's monitor samples (at reset: the present state only): the rotor axis at the
        retainer planes, a flexible rotor's elastic deflection included."""
        b = self._b
        y, M, model = b.y, b.M, self.model
        damping = ((y[model.state_index("RB1.Cs")], y[model.state_index("RB2.Cs")])
                   if model.has_state("RB1.Cs") else (math.nan, math.nan))
        amb = (M[K.M_POWER], M[K.M_CTRL_ON]) if self._relevitate else (math.nan, math.nan)
        states = b.Y_sub if step else y[None]
        orbit = np.empty((len(states), 4))              # the axis at RB1, RB2 (elastic included)
        K.retainer_orbits(states, b.P, b.I, orbit)
        self._renderer.add((self.time, b.out[K.O_FORCE], y[model.state_index("Omega")],
                            M[K.M_REV1], M[K.M_REV2],
                            M[K.M_WHIRL], *damping, *amb), orbit)

    def render(self):
        self._check_open("render")
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode='rgb_array' "
                            "or 'human' to gym.make")
            return None
        return self._ensure_renderer().draw()

    def _ensure_renderer(self):
        if self._renderer is None:
            from .render import Renderer
            title = f"{self.spec.id if self.spec is not None else type(self).__name__}  ·  " \
                    f"{self.base_scene.name} scene"
            self._renderer = Renderer(self.render_mode, title, self.episode_time, self.n_steps,
                                      self._b.dims[3], self._damping, self._relevitate)
            self._reset_view()
        return self._renderer

    def _reset_view(self) -> None:
        s = self.scene
        self._ensure_renderer().reset(s.contact.friction, s.contact.clearance, s.amb.air_gap)

    def _close_view(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
