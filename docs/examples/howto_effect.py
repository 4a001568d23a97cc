"""A force effect of one's own, run in one drop: the worked example of
docs/howto/physical-effect.md (tests/physics/test_howto_examples.py runs it).

The effect: a constant side load F = (fx, fy) on the rotor axis at the axial station z (a
process load, a magnetic pull). Like every effect it declares its slots, packs its parameters
and provides a force kernel that adds into the rotor's load; here it is registered in a
temporary registry (the registered effects plus this module), so nothing of the package
changes, and its right-hand side composes the registered effects' kernels with its own.
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from physics import load_scene
from physics.equilibrium import levitated_state
from physics.jit import njit, njit_borrow, njit_inline
from physics.layout import Layout
from physics.model import EFFECTS, N_AUX, build_model, close, loads
from physics.rotor import add_external, add_force_at

# --8<-- [start:effect]
#: the scene keys it reads (a registered effect has a scene group; this one takes arguments)
SCENE_KEYS = ()


def declare(layout) -> None:
    """Its slots: the load's components and station, with the constants its kernel reads."""
    layout.params.add_each("side_load.fx", "side_load.fy", "side_load.z",
                           consts=("P_SL_FX", "P_SL_FY", "P_SL_Z"))


def pack(fx: float, fy: float, z: float, P: np.ndarray, layout) -> None:
    """Its parameters, by name."""
    p = layout.params
    P[p["side_load.fx"]], P[p["side_load.fy"]], P[p["side_load.z"]] = fx, fy, z


@njit_inline
def force(y, P, I, load):
    """The load with the side load's force and moments added, and its power F . v at the
    station as external work (the energy audit)."""
    fx, fy, z = P[P_SL_FX], P[P_SL_FY], P[P_SL_Z]
    vx, vy = y[I[S_VX]] + z * y[I[S_VA]], y[I[S_VY]] + z * y[I[S_VB]]
    return add_external(add_force_at(load, z, fx, fy), fx * vx + fy * vy)
# --8<-- [end:effect]


# --8<-- [start:registry]
def registry() -> Layout:
    """A temporary registry: the registered effects and this one, laid out together. Its
    declarations come last and add parameters only, so every registered slot keeps its index
    (the compiled kernels stay valid); the constants are bound into this module alone."""
    layout = Layout.build(EFFECTS + (SimpleNamespace(declare=declare),))
    layout.bind(globals())
    return layout


@njit_borrow
def rhs(t, y, P, I, U, dy, aux):
    """The drop model's right-hand side with this effect: the registered effects' loads, this
    effect's force, then the rotor's equations of motion (what one line in physics.model.rhs
    does for a registered effect)."""
    load = loads(t, y, P, I, U, dy, aux)
    load = force(y, P, I, load)
    close(t, y, P, I, dy, aux, load)
# --8<-- [end:registry]


@njit
def _rk4(y, h, n, P, I, U, Y):
    """n classical Runge-Kutta steps of size h from t = 0, the state after each in Y."""
    k1, k2, k3, k4 = np.empty_like(y), np.empty_like(y), np.empty_like(y), np.empty_like(y)
    aux = np.zeros(N_AUX)
    t = 0.0
    for i in range(n):
        rhs(t, y, P, I, U, k1, aux)
        rhs(t + 0.5 * h, y + 0.5 * h * k1, P, I, U, k2, aux)
        rhs(t + 0.5 * h, y + 0.5 * h * k2, P, I, U, k3, aux)
        rhs(t + h, y + h * k3, P, I, U, k4, aux)
        y = y + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        t += h
        Y[i] = y
    return Y


# --8<-- [start:drop]
def drop(fx: float, fy: float, z: float, t_end: float = 0.005, h: float = 1e-5,
         overrides: dict | None = None):
    """The first ``t_end`` seconds of a drop (the AMBs off at t = 0) of the paper machine under
    the side load: (t, Y, model), fixed steps of ``h``."""
    scene = load_scene("paper", {"amb.off_time": 0.0, **(overrides or {})})
    model = build_model(scene)                    # the registered effects' arrays
    layout = registry()
    P = np.zeros(layout.params.size)
    P[:model.P.size] = model.P
    pack(fx, fy, z, P, layout)
    n = int(round(t_end / h))
    Y = _rk4(levitated_state(model), h, n, P, model.I, model.controls(False),
             np.empty((n, model.n_state)))
    return h * np.arange(1, n + 1), Y, model
# --8<-- [end:drop]


if __name__ == "__main__":
    t, Y, model = drop(200.0, 0.0, 0.0, overrides={"effects.unbalance": False})
    x = Y[:, model.state_index("x")]
    print(f"x after {t[-1] * 1e3:.1f} ms: {x[-1] * 1e6:.3f} µm (F t^2 / 2m:"
          f" {200.0 * t[-1] ** 2 / (2 * model.param('rotor.mass')) * 1e6:.3f} µm)")
