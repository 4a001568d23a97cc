"""Policies from other libraries (agents.learning.foreign, docs/examples/foreign_policy.py):
a function, a TorchScript file and an ONNX file drive the environment as the network they came
from does; a function commanding C_max is the max-damping baseline, drop for drop; bad actions
stop with one line naming the policy; evaluate and benchmark take the example's classes."""
import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from agents.benchmarking.rollout import check_actor, run_episodes
from agents.control.controllers import BASELINES, make_controller
from agents.control.plant import ControllerError
from agents.learning.foreign import ForeignPolicy, policy_controller, torchscript_policy

ROOT = Path(__file__).resolve().parents[3]
EXAMPLE = ROOT / "docs" / "examples" / "foreign_policy.py"
ENV = "RotorDrop-Damping-v1"
SHORT = {"episode_time": 0.1}


def example():
    spec = importlib.util.spec_from_file_location("foreign_policy_example", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def kpis(make_actor, seeds=(0, 1)):
    return [e.kpis for e in run_episodes(ENV, make_actor, seeds, SHORT)]


def test_a_function_commanding_c_max_is_the_max_damping_baseline_drop_for_drop():
    ex = example()
    assert kpis(lambda plant: ex.FunctionActor(plant)) == kpis(
        lambda plant: make_controller(BASELINES["max-damping"], plant))


def test_torchscript_and_onnx_files_act_as_the_network_they_were_exported_from(tmp_path):
    torch = pytest.importorskip("torch")
    pytest.importorskip("onnx")
    pytest.importorskip("onnxruntime")
    from agents.learning.foreign import onnx_policy
    ex = example()
    net = ex.make_actor()
    pt, onnx = ex.export(net, tmp_path)
    obs = np.random.default_rng(0).uniform(-1, 1, (64, 14)).astype(np.float32)
    with torch.no_grad():
        want = net(torch.as_tensor(obs)).numpy()
    for fn in (torchscript_policy(pt), onnx_policy(onnx),          # fresh exports
               torchscript_policy(ex.HERE / "foreign_policy.pt"),     # the committed files
               onnx_policy(ex.HERE / "foreign_policy.onnx")):
        got = fn(obs)
        assert got.shape == (64, 2) and np.allclose(got, want, atol=1e-6)
    assert np.ptp(want) > 0.1                                      # it does act on the input
    # in an episode: the same drops from either file
    a = kpis(lambda plant: ex.TorchScriptActor(plant))
    b = kpis(lambda plant: ex.OnnxActor(plant))
    for x, y in zip(a, b):
        assert x["backward_whirl"] == y["backward_whirl"]
        assert x["peak_contact_force_N"] == pytest.approx(y["peak_contact_force_N"], rel=1e-3)


@pytest.mark.parametrize("policy, words", [
    (lambda obs: np.ones((len(obs), 3)), ["'bad'", "shape (1, 3)", "takes (1, 2)"]),
    (lambda obs: np.full((len(obs), 2), np.nan), ["'bad'", "non-finite"]),
    (lambda obs: 1 / 0, ["'bad'", "ZeroDivisionError"]),
])
def test_a_broken_policy_stops_with_one_line_naming_it(policy, words):
    cls = policy_controller(policy, ENV, name="bad")
    with pytest.raises(ControllerError) as err:
        check_actor(ENV, cls, SHORT)
    assert all(w in str(err.value) for w in words), str(err.value)


def test_a_missing_file_is_named_when_the_policy_first_acts(tmp_path):
    cls = policy_controller(torchscript_policy(tmp_path / "none.pt"), ENV, name="gone")
    with pytest.raises(ControllerError, match=r"'gone'.*none\.pt: no such file"):
        check_actor(ENV, cls, SHORT)


@pytest.mark.parametrize("kw, message", [
    (dict(command="auto"), r"command = 'auto': allowed None, 'supervisor'"),
    (dict(name="my policy"), r"name = 'my policy': a leaderboard name without spaces"),
    (dict(policy="model.pt"), r"policy = 'model.pt': allowed a function"),
])
def test_bad_arguments_are_refused(kw, message):
    args = dict(policy=lambda obs: obs, env_id=ENV, name="ok") | kw
    with pytest.raises(ValueError, match=message):
        policy_controller(**args)


def test_it_runs_only_in_its_own_environment_and_seat():
    from agents.control.controllers import controller_env_kwargs
    from agents.control.plant import plant_of
    cls = policy_controller(lambda obs: obs, "RotorDrop-Full-v1", name="sup", command="supervisor")
    assert issubclass(cls, ForeignPolicy)
    assert cls.seat == "supervisor"             # the PID's supervisor, at the seat's 1 ms step
    assert controller_env_kwargs(cls, "RotorDrop-Full-v1") == {"command": "supervisor",
                                                               "control_dt": 1e-3}
    fast = policy_controller(lambda obs: obs, "RotorDrop-Full-v1", name="fast",
                             command="continuous", control_dt=2e-4)
    assert fast.seat == "controller"            # raw currents at 0.2 ms: inside the controller
    with pytest.raises(ValueError, match="no seat runs control_dt = 0.5 ms"):
        policy_controller(lambda obs: obs, "RotorDrop-Full-v1", name="odd",
                          command="continuous", control_dt=5e-4)
    assert cls.supports(plant_of("RotorDrop-Full-v1", command="supervisor"))
    assert not cls.supports(plant_of(ENV))


def test_evaluate_takes_the_example_class(tmp_path):
    done = subprocess.run(
        [sys.executable, "-m", "agents.cli", "evaluate", "--policy",
         f"{EXAMPLE}:TorchScriptActor", "--env", ENV, "--episodes", "1", "--no-passive",
         "--no-plots", "--out", str(tmp_path)],
        capture_output=True, text=True, timeout=600, cwd=ROOT,
        env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stderr[-2000:]
    assert "foreign-torchscript" in (tmp_path / "kpis.json").read_text()


def test_the_benchmark_runs_it_in_its_own_task_only(tmp_path):
    from agents.benchmarking.benchmark import benchmark
    report = benchmark(tmp_path, quick=True, policies=[f"{EXAMPLE}:FunctionActor"],
                       max_scenarios=1, plots=False, progress=False)
    tasks = {r["task"] for r in report["rows"] if r["controller"] == "always-stiff-fn"}
    assert tasks == {"damping"}
    rows = {r["controller"]: r for r in report["rows"] if r["task"] == "damping"}
    same = lambda row: {k: v for k, v in row.items() if k != "controller"}    # noqa: E731
    assert same(rows["always-stiff-fn"]) == same(rows["max-damping"])     # C_max, drop for drop
