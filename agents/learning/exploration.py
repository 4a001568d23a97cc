"""Initial exploration spread per action entry, for PPO's Gaussian policy.

SB3's ``log_std_init`` gives every action entry the same initial spread. In the supervisor
interface the entries differ: noise on the dampers costs reward at every step (a damper
command below C_max lets the bounce grow), while the gain scale and the radial offsets are
read by nothing before the PID is on, and the lift assist that pays lies half a clearance
away (``inner-loop-lift``: gain 0.5, offsets −0.5). With one small spread (std 0.14) the
runs of docs/experiments/2026-11-27-full-authority-from-max.md stopped at offsets of about −0.15. ``action_log_std`` sets the initial
log standard deviation of the named entries; the others keep ``log_std_init``. The spread is
still learned; it is only where training starts.

In a config (``rotordrop train``)::

    action_log_std: {gain: -1.0, offset_r1: -1.0, offset_r2: -1.0}

and as rl-zoo3 writes it (``python -m rl_zoo3.train``; :mod:`agents.learning.hyperparams` reads either
form)::

    callback:
      - agents.learning.exploration.ActionSpread: {log_std: {gain: -1.0, offset_r1: -1.0, offset_r2: -1.0}}

Only policies with a state-independent log std take it (PPO's ``MlpPolicy`` without gSDE).
A resumed run keeps the spread it learned.
"""
from __future__ import annotations

from stable_baselines3.common.callbacks import BaseCallback

from .config_checks import ConfigError, is_finite_number

#: allowed initial log standard deviations (std 0.007 ... 2.7 in the action's [-1, 1] units)
LOG_STD_RANGE = (-5.0, 1.0)


def check_action_log_std(log_std, action_names=None) -> dict[str, float]:
    """``log_std`` as {action entry: float}; ConfigError naming the entry unless it is a
    mapping of numbers in :data:`LOG_STD_RANGE` (and, given ``action_names``, of known
    entries)."""
    if not isinstance(log_std, dict) or not log_std:
        raise ConfigError(f"action_log_std must be a non-empty mapping {{action entry: log std}}, "
                          f"got {log_std!r}")
    lo, hi = LOG_STD_RANGE
    for name, value in log_std.items():
        if not is_finite_number(value) or not lo <= value <= hi:
            raise ConfigError(f"action_log_std.{name} = {value!r} must be a number in [{lo:g}, {hi:g}]")
        if action_names is not None and name not in action_names:
            raise ConfigError(f"action_log_std: {name!r} is not an action entry of this environment; "
                              f"its entries: {', '.join(action_names)}")
    return {str(k): float(v) for k, v in log_std.items()}


def set_action_log_std(policy, action_names, log_std: dict) -> None:
    """Write ``log_std`` (checked) into the named entries of ``policy.log_std``."""
    import torch
    param = getattr(policy, "log_std", None)
    if not isinstance(param, torch.nn.Parameter) or getattr(policy, "use_sde", False) \
            or param.shape != (len(action_names),):
        raise ConfigError("action_log_std needs a policy with one state-independent log std per "
                          "action entry (PPO's MlpPolicy without use_sde)")
    values = check_action_log_std(log_std, list(action_names))
    with torch.no_grad():
        for name, v in values.items():
            param[list(action_names).index(name)] = v


def zero_action_mean(policy) -> None:
    """Zero the last layer of ``policy``'s action mean (config key ``zero_start``): PPO's
    ``action_net``, the ``mu`` head of SAC, TQC, CrossQ and TD3 (and TD3's target actor), so
    the deterministic action is 0 for every observation until training moves it (the layer's
    gradients are the features', not zero). ConfigError for a policy without such a layer."""
    import torch
    heads = [getattr(policy, "action_net", None)]
    for actor in (getattr(policy, "actor", None), getattr(policy, "actor_target", None)):
        heads.append(getattr(actor, "mu", None))
    layers = [_last_linear(h) for h in heads if h is not None]
    if not layers or None in layers:
        raise ConfigError(f"zero_start: {type(policy).__name__} has no action-mean layer to zero")
    with torch.no_grad():
        for layer in layers:
            layer.weight.zero_()
            layer.bias.zero_()


def _last_linear(module):
    import torch
    linear = [m for m in module.modules() if isinstance(m, torch.nn.Linear)]
    return linear[-1] if linear else None


class ActionSpread(BaseCallback):
    """Sets the initial log std of the named action entries when training starts from scratch
    (rl-zoo3: ``callback: - agents.learning.exploration.ActionSpread: {log_std: {...}}``; in
    ``rotordrop train`` the key ``action_log_std``). A resumed model is left as it is."""

    def __init__(self, log_std: dict, verbose: int = 0):
        super().__init__(verbose)
        self.log_std = check_action_log_std(log_std)

    def _init_callback(self) -> None:
        if self.model.num_timesteps > 0:
            return
        names = self.training_env.get_attr("action_names", [0])[0]
        set_action_log_std(self.model.policy, names, self.log_std)

    def _on_step(self) -> bool:
        return True
