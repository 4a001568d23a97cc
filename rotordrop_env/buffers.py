"""Preallocated arrays of one environment, or stacked (N, ...) for the batched VecEnv.

A batched VecEnv allocates one stack and hands each of its environments a row of views, so the
single-env step (:func:`~rotordrop_env.kernels.step_one`) and the batched step
(:func:`~rotordrop_env.kernels.step_batch`) read and write the very same memory.
"""
from __future__ import annotations

import numpy as np

from .kernels import N_C, N_M, N_O

FIELDS = ("act", "y", "P", "I", "U", "Z", "atol", "work", "t_sub", "Y_sub", "aux", "cur", "C", "M",
          "scale", "obs", "out")


class Buffers:
    """Arrays passed to the step kernels (see :mod:`rotordrop_env.kernels`), in kernel order."""

    def __init__(self, n_state: int, n_obs: int, n_act: int, n_sub: int, packed: dict[str, int],
                 n_envs: int | None = None, n_noise: int = 0):
        """``packed``: lengths of the physics' packed arrays ``P``, ``I``, ``U``, ``aux``
        (:attr:`physics.model.Model.sizes`); ``n_noise``: the rows of ``Z``, the most sensor
        noise samples inside one control step and the measurement's after it
        (:attr:`rotordrop_env.sensors.Sensing.n_noise`)."""
        lead = () if n_envs is None else (n_envs,)
        shapes = dict(act=(n_act,), y=(n_state,), P=(packed["P"],), I=(packed["I"],),
                      U=(packed["U"],), Z=(n_noise, 4), atol=(n_state,), work=(9, n_state), t_sub=(n_sub,),
                      Y_sub=(n_sub, n_state), aux=(packed["aux"],),
                      cur=(4,), C=(N_C,), M=(N_M,), scale=(n_obs,), obs=(n_obs,), out=(N_O,))
        for name in FIELDS:
            dtype = np.int64 if name == "I" else np.float64
            setattr(self, name, np.zeros(lead + shapes[name], dtype=dtype))
        self.dims = (n_state, n_obs, n_act, n_sub)
        self.n_noise = n_noise
        self.packed = dict(packed)

    def row(self, e: int) -> "Buffers":
        """Views of environment ``e``'s arrays in a stack."""
        view = object.__new__(Buffers)
        for name in FIELDS:
            setattr(view, name, getattr(self, name)[e])
        view.dims = self.dims
        view.n_noise = self.n_noise
        view.packed = self.packed
        return view

    def args(self) -> tuple:
        return tuple(getattr(self, name) for name in FIELDS)
