"""Memory by frame stacking (config ``frame_stack``): training runs under SB3's ``VecFrameStack``
over the normalisation, and the saved policy stacks the observations itself, so that the project's
loader and plain SB3 act on single observations exactly as the network acted in training."""
import gymnasium as gym
import numpy as np
import pytest
import torch
import yaml

from agents.learning.config_checks import ConfigError
from agents.learning.hyperparams import algo_class, load_hyperparams, split
from agents.control.plant import Plant
from agents.learning.policies import LearnedPolicy
from agents.sb3_policy import FrameStack
from agents.training.train import train

torch.set_num_threads(1)
ENV = "RotorDrop-Damping-v1"


def test_frame_stack_keeps_the_newest_last_and_restarts_on_episode_start():
    fs = FrameStack(3)
    a, b, c = (np.full(2, v, dtype=np.float32) for v in (1.0, 2.0, 3.0))
    assert fs(a, [True]).tolist() == [0, 0, 0, 0, 1, 1]
    assert fs(b, [False]).tolist() == [0, 0, 1, 1, 2, 2]
    assert fs(c, [False]).tolist() == [1, 1, 2, 2, 3, 3]
    assert fs(a, [True]).tolist() == [0, 0, 0, 0, 1, 1]
    batch = FrameStack(2)
    batch(np.ones((2, 1)), [True, True])
    assert batch(np.full((2, 1), 5.0), [False, True]).tolist() == [[1, 5], [0, 5]]


@pytest.mark.parametrize("bad", [0, 65, 2.5, True, "4"])
def test_frame_stack_out_of_range_is_a_config_error_naming_it(tmp_path, bad):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml.safe_dump({ENV: {"policy": "MlpPolicy", "frame_stack": bad}}))
    with pytest.raises(ConfigError, match=r"frame_stack must be an integer in \[1, 64\]"):
        split(load_hyperparams("ppo", ENV, cfg))


#: tiny runs: PPO, and TQC (an off-policy replay buffer stores what VecNormalize saw)
ALGO_KEYS = {"ppo": {"n_steps": 64, "batch_size": 64, "n_epochs": 1},
             "tqc": {"learning_starts": 64, "batch_size": 32, "train_freq": 8, "gradient_steps": 1,
                     "buffer_size": 1000}}


@pytest.fixture(scope="module", params=sorted(ALGO_KEYS))
def stacked_run(tmp_path_factory, request):
    algo = request.param
    out = tmp_path_factory.mktemp(f"fs-{algo}")
    cfg = out / "fs.yaml"
    cfg.write_text(yaml.safe_dump({ENV: {
        "policy": "MlpPolicy", "n_envs": 2, **ALGO_KEYS[algo],
        "normalize": "dict(norm_obs=True, norm_reward=False)", "frame_stack": 3,
        "policy_kwargs": "dict(net_arch=[16, 16])", "residual": None,
        "env_kwargs": {"randomize": True}}}))
    train(ENV, algo, out / "run", timesteps=256, config=cfg, seed=3, progress=False,
          eval_freq=0, checkpoint_freq=0)
    return algo, out / "run"


def test_a_stacked_policy_acts_as_the_network_under_vec_frame_stack(stacked_run):
    from stable_baselines3.common.vec_env import DummyVecEnv, VecFrameStack, VecNormalize
    algo, stacked_run = stacked_run
    plain = algo_class(algo).load(stacked_run / "model.zip", device="cpu")
    project = LearnedPolicy.load(stacked_run / "model.zip")
    assert project.frame_stack == 3 and plain.policy.stack.n == 3
    assert plain.observation_space.shape[0] == plain.policy.obs_mean.shape[0] == 3 * 14
    venv = DummyVecEnv([lambda: gym.make(ENV, randomize=True)])
    venv.seed(11)
    fs = VecFrameStack(venv, 3)                   # as in training: normalised over the stack
    vn = VecNormalize.load(str(stacked_run / "vecnormalize.pkl"), fs)
    vn.training, vn.norm_reward = False, False
    obs, first, actions = vn.reset(), None, []
    project.bound(Plant.from_env(gym.make(ENV, randomize=True)))
    for t in range(25):
        net, _ = plain.policy.network_predict(obs, deterministic=True)
        raw = vn.get_original_obs()[:, -14:]              # the newest observation
        mine, _ = project.predict(raw[0], episode_start=np.array([t == 0]))
        theirs, _ = plain.predict(raw[0], episode_start=np.array([t == 0]), deterministic=True)
        assert np.array_equal(mine, net[0]) and np.array_equal(theirs, net[0])
        first = mine if t == 0 else first
        actions.append(mine)
        obs, *_ = vn.step(net)
    # the stack holds the episode: the same observation without episode_start acts otherwise
    newest = vn.get_original_obs()[0, -14:]
    again, _ = project.predict(newest, episode_start=np.array([False]))
    restart, _ = project.predict(newest, episode_start=np.array([True]))
    assert not np.array_equal(again, restart)
    assert len({a.tobytes() for a in actions}) > 1
