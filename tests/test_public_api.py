"""The import paths that moved in 1.0 work for one release: each old path imports with a
DeprecationWarning naming the new one and gives the same objects; a script sees the warning at
its own import line under Python's default filters."""
import importlib
import re
import importlib.metadata
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import agents
import physics
from physics.moved import PHYSICS_MOVES

ROOT = Path(__file__).resolve().parents[1]
MOVES = {**agents.MOVED, **PHYSICS_MOVES}


def fresh_import(name: str):
    for key in [k for k in sys.modules if k == name or k.startswith(name + ".")]:
        del sys.modules[key]
    return importlib.import_module(name)


@pytest.mark.parametrize("old", sorted(MOVES))
def test_an_old_path_warns_naming_the_new_one_and_gives_the_same_objects(old):
    pytest.importorskip("stable_baselines3")
    new = [importlib.import_module(t) for t in MOVES[old]]
    with pytest.warns(DeprecationWarning, match=rf"{old} moved to {MOVES[old][0]}.*2\.0"):
        shim = fresh_import(old)
    public = [n for t in new for n in getattr(t, "__all__", dir(t)) if not n.startswith("_")]
    assert set(public) <= set(shim.__all__)
    assert public or hasattr(shim, "__path__")                   # a package of submodules
    for name in public:
        owner = next(t for t in new if hasattr(t, name))
        assert getattr(shim, name) is getattr(owner, name), name
    with pytest.raises(AttributeError, match="moved to"):
        shim.no_such_name


def test_the_names_scripts_of_the_last_release_used():
    pytest.importorskip("stable_baselines3")
    from agents.control.plant import Plant
    from agents.learning.policies import load_shipped
    from agents.training.ship import ship_policy
    with pytest.warns(DeprecationWarning):
        old = fresh_import("agents.policies")
    assert (old.load_shipped, old.ship_policy) == (load_shipped, ship_policy)
    with pytest.warns(DeprecationWarning):
        assert fresh_import("agents.plant").Plant is Plant


def test_a_moved_packages_submodules_resolve():
    from physics.runs.study import run
    with pytest.warns(DeprecationWarning, match="physics.study.run moved to physics.runs.study.run"):
        old = fresh_import("physics.study.run")
    names = [n for n in dir(run) if not n.startswith("_")]
    assert names and all(getattr(old, n) is getattr(run, n) for n in names)


def test_an_old_path_that_exists_as_a_file_is_itself_a_forwarding_shim():
    for old in MOVES:
        path = ROOT.joinpath(*old.split("."))
        for file in (path.with_suffix(".py"), path / "__init__.py"):
            if file.exists():
                assert "forward(" in file.read_text() and MOVES[old][0] in file.read_text(), old


def test_the_finder_costs_nothing_on_imports_it_does_not_serve():
    finders = [getattr(f, "__name__", type(f).__name__) for f in sys.meta_path]
    assert "_OldPaths" in finders and finders.index("_OldPaths") > finders.index("PathFinder")


def test_a_script_sees_the_warning_at_its_import_line(tmp_path):
    script = tmp_path / "old_script.py"
    script.write_text("import physics\nfrom physics.sweep import *\n")
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(ROOT)}, timeout=300)
    assert done.returncode == 0, done.stderr
    assert (f"{script}:2: DeprecationWarning: physics.sweep moved to physics.runs.sweep"
            in done.stderr), done.stderr


def test_the_version_is_one_string_everywhere():
    changelog = (ROOT / "CHANGELOG.md").read_text()
    assert f"## {physics.__version__} " in changelog
    done = subprocess.run([sys.executable, "-m", "agents.cli", "--version"], capture_output=True,
                          text=True, cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)},
                          timeout=300)
    assert done.stdout.strip() == f"rotordrop {physics.__version__}"
    dist = importlib.metadata.distribution("rotordrop")     # installed from this tree: the same
    url = json.loads(dist.read_text("direct_url.json") or "{}").get("url", "")
    if url.rstrip("/").endswith(str(ROOT)):
        assert dist.version == physics.__version__


PUBLIC = ROOT / "docs" / "api" / "public.md"


def listed_names() -> list[str]:
    """The dotted names in the first column of the public page's tables (before 'Moved')."""
    text = PUBLIC.read_text().split("## Moved in 1.0")[0]
    cells = [row.split("|")[1] for row in text.splitlines() if row.startswith("| `")]
    return [n for cell in cells for n in re.findall(r"`([\w.]+)`", cell)]


def test_every_public_name_imports():
    pytest.importorskip("stable_baselines3")
    names = listed_names()
    assert len(names) > 30
    for name in names:
        module, attr = name, None
        while True:
            try:
                obj = importlib.import_module(module)
                break
            except ModuleNotFoundError:
                module, _, tail = module.rpartition(".")
                attr = tail if attr is None else f"{tail}.{attr}"
        for part in (attr.split(".") if attr else []):
            obj = getattr(obj, part)
        assert obj is not None, name


def test_the_api_reference_pages_document_only_public_names():
    listed = {n.rsplit(".", 1)[-1] for n in listed_names()}
    for page in (ROOT / "docs" / "api").glob("*.md"):
        for name in re.findall(r"^::: ([\w.]+)", page.read_text(), flags=re.M):
            assert name.rsplit(".", 1)[-1] in listed, f"{page.name}: {name}"


def test_the_moved_table_names_every_old_path():
    table = PUBLIC.read_text().split("## Moved in 1.0")[1]
    for old in MOVES:
        assert f"`{old}`" in table, old
