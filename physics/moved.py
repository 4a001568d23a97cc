"""Old import paths of moved modules, kept for one release (docs/api/public.md lists them).

A package hands :func:`keep_old_paths` its table ``{old module: (new module, ...)}``; importing an
old path (``import agents.plant``, ``from agents.policies import load_shipped``) then warns with
a :class:`DeprecationWarning` naming the new path, and the old module forwards every attribute
to the new modules, in order (so a name that moved apart from its module is found too). An old
path that is a package's prefix (``physics.study``) covers its submodules
(``physics.study.run`` -> ``physics.runs.study.run``).
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import types
import warnings

#: the release that drops the old paths
REMOVED_IN = "2.0"


def forward(module: types.ModuleType, targets: tuple[str, ...], stacklevel: int = 2) -> None:
    """Make ``module`` (an old path) warn that it moved to ``targets`` and forward every
    attribute look-up to them, in order. ``stacklevel``: of the warning, counted from the
    caller of this function (the import machinery's frames are skipped by ``warnings``)."""
    new = " and ".join(targets)
    warnings.warn(f"{module.__name__} moved to {new}: import it from there (the old path goes "
                  f"in rotordrop {REMOVED_IN})", DeprecationWarning, stacklevel=stacklevel + 1)
    found = [importlib.import_module(t) for t in targets]

    def __getattr__(name: str):
        for t in found:
            if hasattr(t, name):
                return getattr(t, name)
        raise AttributeError(f"module {module.__name__!r} (moved to {new}) has no attribute "
                             f"{name!r}")

    if not hasattr(module, "__path__") and any(hasattr(t, "__path__") for t in found):
        module.__path__ = []                          # a package: its submodules resolve too
    names = sorted({n for t in found for n in getattr(t, "__all__", dir(t))
                    if not n.startswith("_")})
    module.__dict__.update(__getattr__=__getattr__, __all__=names, __dir__=lambda: names,
                           __doc__=f"Moved to {new}.")


class _Forwarder(importlib.abc.Loader):
    """Makes an old path's module (:func:`forward`)."""

    def __init__(self, targets: tuple[str, ...]):
        self.targets = targets

    def create_module(self, spec):
        return None                                   # an ordinary empty module

    def exec_module(self, module: types.ModuleType) -> None:
        forward(module, self.targets)                 # the warning points at the import line


class _OldPaths(importlib.abc.MetaPathFinder):
    """Finds the old paths of one table (and nothing else)."""

    def __init__(self, table: dict[str, tuple[str, ...]]):
        self.table = table

    def targets(self, name: str) -> tuple[str, ...] | None:
        if name in self.table:
            return self.table[name]
        for old, new in self.table.items():           # a moved package's submodules
            if len(new) == 1 and name.startswith(old + "."):
                return (new[0] + name[len(old):],)
        return None

    def find_spec(self, name, path=None, target=None):
        targets = self.targets(name)
        if targets is None:
            return None
        return importlib.util.spec_from_loader(name, _Forwarder(targets))


def keep_old_paths(table: dict[str, tuple[str, ...]]) -> None:
    """Make the old paths of ``table`` importable (idempotent). The finder goes last on
    ``sys.meta_path``: it costs nothing on the imports the other finders find. (An old path that
    names a directory that still exists, ``agents/policies/``, is found there first: its
    ``__init__.py`` calls :func:`forward` itself.)"""
    if not any(isinstance(f, _OldPaths) and f.table == table for f in sys.meta_path):
        sys.meta_path.append(_OldPaths(table))


#: physics's own moves: the run tools went to physics/runs/ (above the model)
PHYSICS_MOVES = {f"physics.{m}": (f"physics.runs.{m}",)
                 for m in ("accuracy", "backend", "plots", "store", "sweep", "study")}
