"""Small helpers shared by the tests."""
import warnings

import numpy as np

from physics.model import build_model
from physics.simulate import Integrator


def free_flight(scene, y0_updates: dict, t_end: float, n_out: int = 2001):
    """Integrate a scene from a custom state (name -> value) without AMBs; returns (t, Y, model)."""
    model = build_model(scene)
    y = np.zeros(model.n_state)
    for name, value in y0_updates.items():
        y[model.index(name)] = value
    t = np.linspace(0.0, t_end, n_out)
    Y = np.empty((n_out, model.n_state))
    Y[0] = y
    Integrator(model).advance(y, 0.0, t_end, model.controls(False), t, Y, 1)
    return t, Y, model


def energy_residual(result):
    """Energy audit (spec §1): |E_mech + E_dissipated - W_external - (its value at t = 0)| at each
    sample [J], and the energy series of ``result.energy()``."""
    e = result.energy()
    balance = e["mechanical"] + e["dissipated"] - e["external"]
    return np.abs(balance - balance[0]), e


def phys(env, obs, name: str) -> float:
    """Physical (SI) value of observation ``name`` of one observation of a rotor-drop env, read
    the way the controllers read it (``agents.control.plant.Plant.get``)."""
    from agents.control.plant import Plant
    return Plant.from_env(env).get(np.atleast_2d(obs), name)[0]


def run_env_checkers(make_env) -> None:
    """Gymnasium's and SB3's environment checkers, each on the env ``make_env()`` returns
    (their warnings about the intended infinite Box bounds are silenced)."""
    from gymnasium.utils.env_checker import check_env as gym_check_env
    from stable_baselines3.common.env_checker import check_env as sb3_check_env
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        gym_check_env(make_env())
        sb3_check_env(make_env())


def check_tuned_records(suite, validation_seeds: list[int]) -> dict:
    """Every designed law tuned on ``suite`` (agents/benchmarking/tuned): tuned under the
    current environment and sensing, on ``validation_seeds`` (first, last), with at least a
    learned configuration's selection budget, never worse than its start. Returns the records."""
    from agents.benchmarking.tune_designed import laws_for, load_records, stale
    records = load_records(suite)
    assert set(records) <= set(laws_for(suite))
    for name, rec in records.items():
        assert stale(suite, name) == [], (name, stale(suite, name))
        b = rec["budget"]
        assert b["validation_episodes"] >= b["learned_selection_episodes"]
        assert b["validation_seeds"] == validation_seeds
        assert rec["validation_score"] >= rec["start_validation_score"] - 1e-9
    return records
