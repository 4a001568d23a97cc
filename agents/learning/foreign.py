"""Policies from any library as controller classes that ``rotordrop evaluate`` and ``benchmark``
take (``--policy my_policy.py:Class``; docs/howto/benchmark-any-policy.md).

A foreign policy maps a batch of the environment's own observations (float32, normalised, as
``env.step`` returns them) to a batch of its actions (in ``[-1, 1]``, or 0/1 for a discrete
``Relevitate`` command). :func:`policy_controller` wraps such a function as a
:class:`ForeignPolicy` class bound to the environment it was trained on; :func:`torchscript_policy`
and :func:`onnx_policy` make the function from a TorchScript or an ONNX file. The benchmark runs
the class in that environment's task only, in the seat its ``command`` names, and every check of
a controller applies (an action of the wrong shape, a NaN, an exception: one line naming it).
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np

from ..control.controllers import Controller
from ..control.plant import ControllerError
from ..control.seats import seat_for_kwargs

#: the channel that selects each re-levitation command (``controllers.command_for``)
_COMMAND_CHANNEL = {None: (), "continuous": ("currents",), "supervisor": ("gain",),
                    "discrete": ("levitate",)}


class ForeignPolicy(Controller):
    """A policy from outside rotordrop acting on one environment's observations and actions
    (made by :func:`policy_controller`; ``policy`` is the batch function)."""

    name = "foreign"
    env_id = ""
    command: str | None = None
    sensors = False                # it reads whatever the environment observes
    memoryless = False             # (its own state, if any, is the policy's business)
    policy: Callable[[np.ndarray], np.ndarray] | None = None

    @classmethod
    def supports(cls, plant) -> bool:
        """Only the environment it was trained on (its observation and action sizes)."""
        return plant.env_id == cls.env_id

    def act(self, obs: np.ndarray) -> np.ndarray:
        action = np.asarray(type(self).policy(np.asarray(obs, dtype=np.float32)))
        shape = (len(obs),) if self.plant.discrete else (len(obs), len(self.plant.action_names))
        if action.shape != shape:
            raise ControllerError(f"policy {self.name!r}: returned actions of shape "
                                  f"{action.shape}, {self.env_id} takes {shape} for this batch")
        if not np.isfinite(action).all():
            raise ControllerError(f"policy {self.name!r}: returned a non-finite action")
        self.t += self.plant.control_dt
        return action.astype(np.int64) if self.plant.discrete else np.clip(action, -1.0, 1.0)


def policy_controller(policy: Callable[[np.ndarray], np.ndarray], env_id: str, name: str,
                      command: str | None = None,
                      control_dt: float | None = None) -> type[ForeignPolicy]:
    """A controller class running ``policy`` (batch of observations -> batch of actions) in
    ``env_id``. ``command``: the re-levitation command it was trained with (env kwarg
    ``command`` of the Relevitate and Full tasks: ``"supervisor"``, ``"continuous"`` or
    ``"discrete"``; None for the Damping task); ``control_dt``: its control step [s] (None: the
    environment's 1 ms). ``name`` is its row on the leaderboard."""
    if command not in _COMMAND_CHANNEL:
        raise ValueError(f"command = {command!r}: allowed None, 'supervisor', 'continuous' or "
                         f"'discrete'")
    if not name or any(c.isspace() or c in "|`" for c in name):
        raise ValueError(f"name = {name!r}: a leaderboard name without spaces, '|' or '`'")
    if not callable(policy):
        raise ValueError(f"policy = {policy!r}: allowed a function of a batch of observations")
    # its seat is where its command and step run (a learned row's rule): 1 ms over the PID is
    # the supervisor's, 0.1-0.2 ms raw currents the controller's; a step no seat runs is refused
    seat = seat_for_kwargs({"command": command, "control_dt": control_dt or 1e-3}).name
    return type(f"Foreign_{name.replace('-', '_')}", (ForeignPolicy,),
                {"name": name, "env_id": env_id, "command": command, "control_dt": control_dt,
                 "seat": seat,
                 "needs": _COMMAND_CHANNEL[command], "policy": staticmethod(policy),
                 "__doc__": f"{name}: a foreign policy in {env_id}"})


def torchscript_policy(path: str | Path) -> Callable[[np.ndarray], np.ndarray]:
    """The batch function of a TorchScript module saved with ``torch.jit.save``: float32
    observations in, actions out (on the CPU, no gradients). The file is read at the first call
    (so a module that defines the class imports before the file exists)."""
    def load():
        import torch
        module = torch.jit.load(str(_existing(path)), map_location="cpu").eval()

        def act(obs: np.ndarray) -> np.ndarray:
            with torch.no_grad():
                return module(torch.as_tensor(obs)).numpy()
        return act
    return _on_first_call(load)


def onnx_policy(path: str | Path) -> Callable[[np.ndarray], np.ndarray]:
    """The batch function of an ONNX model with one input (the observation batch) and the
    action batch as its first output, run by onnxruntime on the CPU (extra ``onnx``); the file
    is read at the first call."""
    def load():
        import onnxruntime
        session = onnxruntime.InferenceSession(str(_existing(path)),
                                               providers=["CPUExecutionProvider"])
        (inp,) = session.get_inputs()
        return lambda obs: session.run(None, {inp.name: obs})[0]
    return _on_first_call(load)


def _on_first_call(load: Callable[[], Callable]) -> Callable[[np.ndarray], np.ndarray]:
    loaded: list[Callable] = []

    def act(obs: np.ndarray) -> np.ndarray:
        if not loaded:
            loaded.append(load())
        return loaded[0](obs)
    return act


def _existing(path: str | Path) -> Path:
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"policy file {path}: no such file")
    return path
