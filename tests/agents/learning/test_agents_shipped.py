"""The policies shipped in agents/policies/: loadable by name, documented, acting in their env
(what ppo-full does physically: tests/agents/control/test_agents_controllers.py)."""
import numpy as np
import pytest

from agents.control.plant import Plant, make_env
from agents.learning.policies import load_shipped, shipped_names


def test_three_policies_ship_with_their_recipe():
    assert {"ppo-damping", "ppo-relevitate", "ppo-full"} <= set(shipped_names())
    for name in shipped_names():
        pol = load_shipped(name)
        assert name.split("-")[0] == pol.algo
        assert pol.meta["command"].startswith(f"rotordrop train --env {pol.env_id} --algo {pol.algo}")
        # the shipped seed: 0, or the best of several by validation score (named in the command)
        assert f"--seed {pol.meta['seed']}" in pol.meta["command"] and pol.meta["learning_curve"]


@pytest.mark.parametrize("name", shipped_names())
def test_shipped_policy_command_names_the_config_that_gave_its_hyperparameters(name):
    """The command of a shipped policy's JSON, parsed as rotordrop train parses it, resolves to
    the hyperparameters its run recorded (agents/configs/<algo>.yaml, an env-id block or the
    policy's named entry)."""
    import argparse
    import ast
    import shlex
    from agents.cli import build_parser
    from agents.learning.hyperparams import RUN_DEFAULTS
    from agents.training.train import resolve_config
    pol = load_shipped(name)
    argv = shlex.split(pol.meta["command"].split("#")[0])
    assert argv[:2] == ["rotordrop", "train"] and "--config" in argv
    args = build_parser().parse_args(argv[1:])
    assert args.config.startswith(f"agents/configs/{pol.algo}.yaml") and args.seed == pol.meta["seed"]
    hp = resolve_config(args.env, args.algo, args.config, args.timesteps, args.n_envs,
                        eval_freq=args.eval_freq, n_eval_episodes=args.eval_episodes,
                        checkpoint_freq=args.save_freq)
    recorded = pol.meta["hyperparams"]
    recorded = ast.literal_eval(recorded) if isinstance(recorded, str) else recorded
    assert {**RUN_DEFAULTS, **hp} == {**RUN_DEFAULTS, **recorded}


@pytest.mark.parametrize("name", ["ppo-damping", "ppo-relevitate", "ppo-full", "ppo-full-scratch",
                                  "sac-full-scratch", "sac-robust-full-scratch",
                                  "ppo-robust-full-scratch", "ppo-hard-currents",
                                  "ppo-hard-currents-noisy"])
def test_shipped_policy_acts_inside_the_action_space(name):
    pol = load_shipped(name)
    kw = {k: v for k, v in pol.env_kwargs.items() if k not in ("randomize", "randomization")}
    env = make_env(pol.env_id, **{**kw, "episode_time": 0.02})
    pol.bound(Plant.from_env(env))
    obs, _ = env.reset(seed=0)
    done = False
    while not done:
        a, _ = pol.predict(obs)
        assert env.action_space.contains(np.asarray(a, dtype=env.action_space.dtype))
        obs, _, term, trunc, _ = env.step(a)
        done = term or trunc

