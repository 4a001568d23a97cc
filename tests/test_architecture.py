"""The layout of docs/architecture.md: one-way layers, no import circles, physics free of the rl
extra. The import-linter contracts in pyproject.toml hold, and they break when the layout does."""
import graphlib
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("physics", "rotordrop_env", "agents")
RL_EXTRA = ("gymnasium", "stable_baselines3", "torch")


def lint_imports(root: Path) -> subprocess.CompletedProcess:
    """``lint-imports`` on the tree at ``root`` (a fresh process: its packages, not the imported ones)."""
    code = ("import sys; from importlinter.cli import lint_imports; "
            "sys.exit(lint_imports(config_filename='pyproject.toml', no_cache=True, no_logo=True))")
    return subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(root)})


def test_the_import_contracts_hold():
    proc = lint_imports(ROOT)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "5 kept, 0 broken" in proc.stdout


LAYERS = "Layers: agents -> rotordrop_env -> physics, never upward"
AGENTS = "agents: cli -> research, training -> benchmarking -> learning -> control"
PHYSICS = "physics: the command line -> the run tools -> the model, never upward"
CORE = "physics imports neither the rl extra nor ray"
CIRCLES = "No import circles between the modules of a package"


@pytest.mark.parametrize("module, line, broken", [
    ("physics/scene.py", "import agents", LAYERS),
    ("rotordrop_env/layout.py", "from agents.control import plant", LAYERS),
    ("physics/metrics.py", "import torch", CORE),
    ("physics/metrics.py", "from .runs import plots", (PHYSICS, CIRCLES)),  # runs import the model
    ("physics/runs/store.py", "from .. import cli", (PHYSICS, CIRCLES)),   # cli imports runs
    ("physics/unplaced.py", "import numpy", PHYSICS),        # a module in no layer
    ("physics/runs/sweep.py", "import ray", CORE),
    ("agents/control/plant.py", "from ..benchmarking import score", (AGENTS, CIRCLES)),
    ("agents/research/oracle.py", "from ..training import train", AGENTS),  # independent layers
    ("agents/unplaced.py", "import numpy", AGENTS),                         # a module in no layer
    ("agents/control/plant.py", "from . import residual", CIRCLES),
    ("physics/runs/study/labels.py", "from . import report", CIRCLES),
])
def test_a_broken_layout_breaks_its_contract(tmp_path, module, line, broken):
    """A copy of the tree with one import added that the layout forbids: an upward import, the
    rl extra in physics, a circle."""
    for name in PACKAGES:
        shutil.copytree(ROOT / name, tmp_path / name, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path)
    with open(tmp_path / module, "a") as f:
        f.write(f"\n{line}  # added by the test\n")
    proc = lint_imports(tmp_path)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    verdicts = [re.sub(r" \(\d+ ignored imports?\)$", "", ln) for ln in proc.stdout.splitlines()]
    verdicts = [ln for ln in verdicts if ln.endswith(("KEPT", "BROKEN"))]
    broken = (broken,) if isinstance(broken, str) else broken
    assert [ln for ln in verdicts if ln.endswith("BROKEN")] == [f"{b} BROKEN" for b in broken], proc.stdout


def test_no_module_is_in_an_import_circle():
    """Stricter than the siblings contract: every module, package inits included (grimp's graph
    of imports anywhere in a module, also inside functions)."""
    import grimp
    graph = grimp.build_graph(*PACKAGES, cache_dir=None)
    order = graphlib.TopologicalSorter({m: graph.find_modules_directly_imported_by(m)
                                        for m in graph.modules})
    try:
        order.prepare()
    except graphlib.CycleError as exc:
        pytest.fail(f"import circle: {' -> '.join(exc.args[1])}")


BLOCK_RL_EXTRA = f"""
import importlib.abc, sys
class NoRlExtra(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in {RL_EXTRA!r}:
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
sys.meta_path.insert(0, NoRlExtra())
from agents.cli import main
sys.exit(main(sys.argv[1:]))
"""


def without_rl_extra(*args: str) -> subprocess.CompletedProcess:
    """``rotordrop ARGS`` in a Python that cannot import gymnasium, SB3 or torch."""
    return subprocess.run([sys.executable, "-c", BLOCK_RL_EXTRA, *args], cwd=ROOT,
                          capture_output=True, text=True)


def test_physics_commands_run_without_the_rl_extra():
    proc = without_rl_extra("params")
    assert proc.returncode == 0, proc.stderr
    assert "contact.friction" in proc.stdout and proc.stderr == ""


def test_an_rl_command_without_the_rl_extra_says_so_in_one_line(tmp_path):
    proc = without_rl_extra("evaluate", "--policy", "max-damping", "--env", "RotorDrop-Damping-v1",
                            "--episodes", "1", "--out", str(tmp_path))
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert "`rotordrop evaluate` needs" in proc.stderr and "rl extra" in proc.stderr
