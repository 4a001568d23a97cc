"""rotordrop physics: AMB rotor drop onto ball-bearing retainer bearings (Kärkkäinen et al.).

Typical use::

    from physics import load_scene, simulate, compute_metrics
    result = simulate(load_scene("paper", {"contact.friction": 0.5}))
    print(compute_metrics(result)["planes"]["RB1"]["backward_whirl"])
"""
#: the release (pyproject.toml reads it from here; CHANGELOG.md lists what each release changed)
__version__ = "1.0.0"

from .scene import Scene, SceneError, load_scene, parameter_table, preset_names
from .model import Model, build_model
from .simulate import IntegrationError, simulate
from .results import Result
from .metrics import compute_metrics
from .moved import PHYSICS_MOVES, keep_old_paths

keep_old_paths(PHYSICS_MOVES)

__all__ = ["__version__", "Scene", "SceneError", "load_scene", "parameter_table", "preset_names", "Model",
           "build_model", "simulate", "IntegrationError", "Result", "compute_metrics"]
