"""Actors that run a designed controller and replace its AMB currents once the power is back:
the open-loop current corrections that ``rotordrop oracle --interface currents`` and
``rotordrop research whirl-bound`` search over."""
from __future__ import annotations

import numpy as np

from rotordrop_env.layout import CURRENT_ACTIONS

from .controllers import controller_class, make_controller
from .plant import Plant


class CurrentOverride:
    """An actor (SB3 ``predict``, one environment): the baseline controller, its AMB currents
    replaced by ``override(obs, currents)`` once the power is back; ``self.k`` counts the
    control steps since then."""

    def __init__(self, plant: Plant, baseline: str):
        self.plant, self.base = plant, make_controller(controller_class(baseline), plant)
        self.cols = [plant.action_names.index(n) for n in CURRENT_ACTIONS]
        self.k = -1

    def override(self, obs: np.ndarray, currents: np.ndarray) -> np.ndarray:
        return currents

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        a, _ = self.base.predict(obs, episode_start=episode_start)
        if episode_start is not None and np.any(episode_start):
            self.k = -1
        if self.plant.power_available(obs)[0]:
            self.k += 1
            a = a.copy()
            a[0, self.cols] = self.override(obs, a[0, self.cols])
        return a, state


class OpenLoopCorrection(CurrentOverride):
    """The baseline's currents plus ``theta[i]`` during segment i (``steps`` control steps each)
    after the power returns, clipped to the current limit."""

    def __init__(self, plant: Plant, baseline: str, steps: int, theta: np.ndarray):
        super().__init__(plant, baseline)
        self.steps, self.theta = steps, theta

    def override(self, obs, currents):
        seg = self.k // self.steps
        return np.clip(currents + self.theta[seg], -1.0, 1.0) if seg < len(self.theta) else currents
