"""Benchmark a policy from any library: as a Python function, a TorchScript file or an ONNX file.

    python docs/examples/foreign_policy.py            # writes foreign_policy.pt and .onnx beside it
    rotordrop evaluate --policy docs/examples/foreign_policy.py:TorchScriptActor \
        --env RotorDrop-Damping-v1 --episodes 5 --out out/foreign
    rotordrop benchmark --quick --policy docs/examples/foreign_policy.py:TorchScriptActor \
        --out out/foreign-bench

The actor here is a small torch network with seeded weights, standing in for one trained with
any library; what the benchmark needs is only a function from a batch of observations (float32,
as the environment returns them) to a batch of actions in [-1, 1].
"""
from pathlib import Path

import numpy as np

from agents.learning.foreign import onnx_policy, policy_controller, torchscript_policy

ENV = "RotorDrop-Damping-v1"            # the environment the actor was trained on
HERE = Path(__file__).resolve().parent


def make_actor():
    """The stand-in for your library's trained actor network (torch.nn.Module)."""
    import torch
    torch.manual_seed(0)
    return torch.nn.Sequential(torch.nn.Linear(14, 64), torch.nn.Tanh(),
                               torch.nn.Linear(64, 2), torch.nn.Tanh())


def export(actor, folder: Path = HERE) -> tuple[Path, Path]:
    """The actor as TorchScript (``torch.jit.script``) and as ONNX (``torch.onnx.export``, which
    needs the onnx package), with a variable batch size."""
    import torch
    pt, onnx = folder / "foreign_policy.pt", folder / "foreign_policy.onnx"
    torch.jit.script(actor).save(str(pt))
    torch.onnx.export(actor, (torch.zeros(1, 14),), str(onnx), input_names=["obs"],
                      output_names=["action"], dynamic_axes={"obs": {0: "batch"}}, dynamo=False)
    return pt, onnx


def always_stiff(obs: np.ndarray) -> np.ndarray:
    """Any Python function of an observation batch: here, both dampers at C_max."""
    return np.ones((len(obs), 2), dtype=np.float32)


# the classes `--policy docs/examples/foreign_policy.py:NAME` names
# (a function without memory acts alike at any step: this one runs at 0.2 ms, in the controller
# seat, where the max-damping baseline it copies runs)
FunctionActor = policy_controller(always_stiff, ENV, name="always-stiff-fn", control_dt=2e-4)
TorchScriptActor = policy_controller(torchscript_policy(HERE / "foreign_policy.pt"), ENV,
                                     name="foreign-torchscript")
OnnxActor = policy_controller(onnx_policy(HERE / "foreign_policy.onnx"), ENV,
                              name="foreign-onnx")


if __name__ == "__main__":
    for path in export(make_actor()):
        print(f"wrote {path}")
