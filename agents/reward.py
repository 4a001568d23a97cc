"""A training reward aligned with the benchmark's KPIs (config key ``reward: kpi``).

The environments' own reward sums per-step penalties (whirl revolutions, contact force,
displacement, effort). The benchmark scores episode *maxima* instead: the whirl verdict, the peak
contact force and the maximum displacement (:mod:`agents.score`). Agents trained on the per-step
reward found that lowering the support damping once a whirl had started lowered the summed
penalties while it raised the peak force. :class:`KpiReward` replaces the reward by the
decrease of a potential built from the running episode KPIs (``env.kpis()``),

    Φ_t = w_whirl · min(n*_t, 3) / 3 + w_verdict · [n*_t ≥ 3] + w_force · F*_t / F_0
          + w_disp · D*_t / D_0,
    r_t = −(Φ_t − Φ_{t−1}),

with n*_t = max_{τ≤t} n_back(τ) the peak net backward orbit revolutions (3 make a backward
whirl), F* the peak contact force and D* the maximum displacement so far. The benchmark counts
a whirl as a verdict (0 or 1 at 3 revolutions); the default ramp (``w_verdict`` 0) charges
2.9 revolutions almost as much as a whirl, so a policy can trade near misses for whirls at no
cost in reward. ``w_verdict`` moves part of the weight onto the verdict itself
(``w_whirl`` 0.25, ``w_verdict`` 0.75 still charge 1 for a whirl). The return of an episode is −Φ_T: minus the
benchmark cost of the episode's KPIs (with fixed references F_0, D_0 instead of the passive
drop's), so maximising it is what the benchmark rewards, and the reward is dense: it arrives in
the step in which a new peak or a backward revolution happens. Re-levitation tasks add
``w_relevitate`` once at re-levitation and ``−w_time · Δt / T_episode`` in every step before it,
so that the episode's return also holds the score's ``(1 − R) + T_R / T_episode`` term
(re-levitating sooner pays).
"""
from __future__ import annotations

import numpy as np
from stable_baselines3.common.vec_env import VecEnvWrapper

from physics.metrics import WHIRL_MIN_REVOLUTIONS

from .config_checks import ConfigError, check_keys, is_finite_number

PEAK_KEYS = ("kpi_peak_whirl_revolutions", "kpi_peak_contact_force_N", "kpi_max_displacement_um")
#: the ``reward_kwargs`` and their defaults
WEIGHTS = dict(w_whirl=1.0, w_verdict=0.0, w_force=0.5, w_disp=0.5, force_ref=1e4,
               disp_ref_um=800.0, w_relevitate=1.0, w_time=1.0)
REFERENCES = ("force_ref", "disp_ref_um")


def check_reward_kwargs(kwargs: dict) -> None:
    """ConfigError unless ``kwargs`` are known weights >= 0 and references > 0."""
    check_keys("reward_kwargs", kwargs, tuple(WEIGHTS))
    for key, value in kwargs.items():
        positive = key in REFERENCES
        if not (is_finite_number(value) and (value > 0.0 if positive else value >= 0.0)):
            raise ConfigError(f"reward_kwargs.{key} must be a finite number "
                              f"{'> 0' if positive else '>= 0'}, got {value!r}")


def kpi_potential(revs, force_N, disp_um, w_whirl: float, w_force: float, w_disp: float,
                  force_ref: float, disp_ref_um: float, w_verdict: float = 0.0):
    """Φ of the module docstring from the peak net backward revolutions, the peak contact force
    and the maximum displacement (floats or arrays)."""
    revs = np.asarray(revs, dtype=float)
    return (w_whirl * np.minimum(revs, WHIRL_MIN_REVOLUTIONS) / WHIRL_MIN_REVOLUTIONS
            + w_verdict * (revs >= WHIRL_MIN_REVOLUTIONS)
            + w_force * np.asarray(force_N) / force_ref + w_disp * np.asarray(disp_um) / disp_ref_um)


class KpiReward(VecEnvWrapper):
    """The KPI-aligned reward (see module docstring) on an SB3 VecEnv of rotor-drop
    environments: the batched VecEnv (config ``reward: kpi``) or SB3's DummyVecEnv /
    SubprocVecEnv of ``gym.make`` environments (rl-zoo3: ``vec_env_wrapper:
    agents.reward.KpiReward``, weights as its keyword arguments)."""

    def __init__(self, venv, **weights):
        super().__init__(venv)
        check_reward_kwargs(weights)
        w = {**WEIGHTS, **weights}
        self.w_relevitate = w.pop("w_relevitate")
        dt, horizon = (np.asarray(venv.get_attr(a), dtype=float) for a in ("dt", "episode_time"))
        self.time_cost = w.pop("w_time") * dt / horizon
        self.w = w
        self.phi = np.zeros(self.num_envs)

    def reset(self):
        obs = self.venv.reset()
        self.phi[:] = 0.0
        return obs

    def running_kpis(self) -> dict[str, np.ndarray]:
        """Every environment's running-maximum KPIs (the batched VecEnv has them as arrays)."""
        base = self.venv.unwrapped
        if hasattr(base, "running_kpis"):
            return base.running_kpis()
        kpis = self.venv.env_method("kpis")
        return {k: np.array([d[k] for d in kpis], dtype=float) for k in PEAK_KEYS}

    def step_wait(self):
        obs, _, dones, infos = self.venv.step_wait()
        peaks = self.running_kpis()
        for i in np.flatnonzero(dones):                # a done env is already reset
            for key in PEAK_KEYS:
                peaks[key][i] = infos[i][key]
        phi = kpi_potential(*(peaks[key] for key in PEAK_KEYS), **self.w)
        rewards = self.phi - phi
        if "relevitated" in infos[0]:
            success = np.array([i.get("reward_success", 0.0) > 0.0 for i in infos])
            pending = np.array([not i["relevitated"] for i in infos]) & ~success
            rewards += self.w_relevitate * success - self.time_cost * pending
        self.phi = np.where(dones, 0.0, phi)
        return obs, rewards.astype(np.float32), dones, infos


def make_kpi_reward(venv, **kwargs) -> KpiReward:
    """:class:`KpiReward` around ``venv``."""
    return KpiReward(venv, **kwargs)
