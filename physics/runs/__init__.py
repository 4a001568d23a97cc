"""The run tools above the physics model: batches of drops on threads (:mod:`~physics.runs.sweep`),
the store of finished drops (:mod:`~physics.runs.store`), the local and Ray backends
(:mod:`~physics.runs.backend`), the published studies (:mod:`~physics.runs.study`), the accuracy
study (:mod:`~physics.runs.accuracy`) and the figures (:mod:`~physics.runs.plots`).

They import the model (``physics.scene``, ``physics.simulate``, ``physics.metrics``, ...) and
never the command line (:mod:`physics.cli`), which sits above them (docs/architecture.md).
"""
from __future__ import annotations


class UsageError(ValueError):
    """A bad command-line argument that is not a scene parameter (one-line error, exit 2)."""
