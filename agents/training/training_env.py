"""The training VecEnv: batched rotor-drop environments (``rotordrop_env``) with episode
statistics, optionally the KPI-aligned reward (:mod:`agents.learning.reward`) and a residual on a
baseline controller (:mod:`agents.control.residual`), as the config keys ``reward`` and ``residual`` of
:mod:`agents.learning.hyperparams` ask. Above :mod:`agents.control.plant`, which residual and the controllers
build on."""
from __future__ import annotations


def make_vec_env(env_id: str, n_envs: int, seed: int, env_kwargs: dict, monitor_file=None,
                 reward: str = "env", reward_kwargs: dict | None = None,
                 residual: str | dict | None = None, residual_scale: float | None = None):
    """The batched SB3 VecEnv of ``rotordrop_env`` with episode statistics (``VecMonitor``);
    ``reward="kpi"`` makes the environments' reward the KPI-aligned one (env kwarg
    ``reward="kpi"``, :mod:`rotordrop_env.reward`), ``residual`` makes the agent's action a
    correction of that baseline controller's."""
    from stable_baselines3.common.vec_env import VecMonitor
    from rotordrop_env import BatchedRotorDropVecEnv
    if reward == "kpi":
        from ..learning.reward import check_reward_kwargs
        check_reward_kwargs(reward_kwargs or {})
        env_kwargs = dict(env_kwargs, reward="kpi", reward_kwargs=dict(reward_kwargs or {}))
    venv = BatchedRotorDropVecEnv(env_id, n_envs, seed=seed, **env_kwargs)
    if residual:
        from ..control.residual import make_residual
        venv = make_residual(venv, residual, **({} if residual_scale is None else
                                                {"scale": residual_scale}))
    return VecMonitor(venv, filename=str(monitor_file) if monitor_file else None,
                      info_keywords=("kpi_backward_whirl", "kpi_peak_contact_force_N"))
