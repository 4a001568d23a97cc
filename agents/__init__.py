"""Controllers, SB3 training, evaluation and benchmark for the rotor-drop environments
(docs/agents.md). Heavy dependencies (SB3, torch) are imported where they are used."""
from physics.moved import keep_old_paths

#: modules that moved into the concept packages in 1.0 (importable from the old path, with a
#: DeprecationWarning, until 2.0; docs/api/public.md)
_NEW_HOME = {
    "control": ("controllers", "open_loop", "plant", "residual"),
    "learning": ("config_checks", "exploration", "hyperparams", "reward"),
    "benchmarking": ("benchmark", "evaluate", "plots", "ray_search", "results", "ride_through",
                     "robust", "rollout", "score", "search", "tune"),
    "training": ("dataset", "imitation", "learning_curves", "seeds", "train", "training_env",
                 "validation"),
    "research": ("oracle",),
}
MOVED = {f"agents.{m}": (f"agents.{pkg}.{m}",) for pkg, ms in _NEW_HOME.items() for m in ms}
# ship_policy left the policy-file module for agents.training.ship; the old path is the folder
# of the policy files, whose __init__.py forwards (the finder never sees it)
MOVED["agents.policies"] = ("agents.learning.policies", "agents.training.ship")
keep_old_paths(MOVED)
