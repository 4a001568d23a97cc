"""Small helpers shared by the physics tests."""
import numpy as np

from physics.model import build_model
from physics.simulate import Integrator


def free_flight(scene, y0_updates: dict, t_end: float, n_out: int = 2001):
    """Integrate a scene from a custom state (name -> value) without AMBs; returns (t, Y, model)."""
    model = build_model(scene)
    y = np.zeros(model.n_state)
    for name, value in y0_updates.items():
        y[model.index(name)] = value
    t = np.linspace(0.0, t_end, n_out)
    Y = np.empty((n_out, model.n_state))
    Y[0] = y
    Integrator(model).advance(y, 0.0, t_end, model.controls(False), t, Y, 1)
    return t, Y, model
