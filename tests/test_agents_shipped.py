"""The policies shipped in agents/policies/: loadable by name, documented, and doing their job."""
import numpy as np
import pytest

from agents.controllers import Passive
from agents.plant import Plant, make_env
from agents.policies import load_shipped, shipped_names
from agents.rollout import run_episodes


def test_three_policies_ship_with_their_recipe():
    assert {"ppo-damping", "ppo-relevitate", "ppo-full"} <= set(shipped_names())
    for name in shipped_names():
        pol = load_shipped(name)
        assert name.split("-")[0] == pol.algo
        assert pol.meta["command"].startswith(f"rotordrop train --env {pol.env_id} --algo {pol.algo}")
        assert pol.meta["seed"] == 0 and pol.meta["learning_curve"]


@pytest.mark.parametrize("name", ["ppo-damping", "ppo-relevitate", "ppo-full"])
def test_shipped_policy_acts_inside_the_action_space(name):
    pol = load_shipped(name)
    kw = {k: v for k, v in pol.env_kwargs.items() if k not in ("randomize", "randomization")}
    env = make_env(pol.env_id, **{**kw, "episode_time": 0.02})
    pol.bound(Plant.from_env(env))
    obs, _ = env.reset(seed=0)
    pol.reset(1)
    done = False
    while not done:
        a, _ = pol.predict(obs)
        assert env.action_space.contains(np.asarray(a, dtype=env.action_space.dtype))
        obs, _, term, trunc, _ = env.step(a)
        done = term or trunc


def test_ppo_full_stops_a_whirl_the_passive_drop_runs_into():
    """mu = 0.46 (not a benchmark, tuning or validation friction), power back at 50 ms: the
    passive drop whirls; ppo-full keeps the peak below 3 net backward revolutions, re-levitates,
    and its peak contact force is below passive."""
    pol = load_shipped("ppo-full")
    kw = dict(overrides={"contact.friction": 0.46}, episode_time=0.2, terminate_on_failure=False,
              command="continuous")
    ep = run_episodes("RotorDrop-Full-v0", pol.bound, [0], kw)[0].kpis
    passive = run_episodes("RotorDrop-Passive-v0", Passive, [0],
                           {k: v for k, v in kw.items() if k != "command"})[0].kpis
    assert passive["backward_whirl"]
    assert not ep["backward_whirl"] and ep["relevitated"]
    assert ep["peak_contact_force_N"] < passive["peak_contact_force_N"]

