"""Other RL libraries train on the environments (optional extra ``clients``: skrl, TorchRL,
Tianshou; skipped when not installed): TorchRL's GymWrapper reads every info key (its spec
inferred from the reset and the steps, so keys and types must never change) and passes
``check_env_specs``; skrl's PPO trains on the Gymnasium vector environment; Tianshou's trainers
(PPO in-process, SAC on spawned workers) run through many episode ends with every info key in
the replay buffer and no NaN in it. A few thousand steps each."""
import functools
import warnings

import gymnasium as gym
import pytest

import rotordrop_env  # noqa: F401


def test_torchrl_reads_every_info_key_and_trains_ppo(tmp_path):
    pytest.importorskip("torchrl")
    import torch
    from tensordict.nn import NormalParamExtractor, TensorDictModule
    from torch import nn
    from torchrl.collectors import Collector
    from torchrl.envs import GymWrapper
    from torchrl.envs.utils import check_env_specs
    from torchrl.modules import ProbabilisticActor, TanhNormal, ValueOperator
    from torchrl.objectives import ClipPPOLoss
    from torchrl.objectives.value import GAE
    warnings.simplefilter("ignore")
    torch.manual_seed(0)
    made = gym.make("RotorDrop-Full-v1", command="supervisor", episode_time=0.05, reward="kpi")
    info_keys = set(made.reset(seed=0)[1])
    env = GymWrapper(made)
    env.auto_register_info_dict()
    check_env_specs(env)
    n_obs = env.observation_spec["observation"].shape[-1]
    n_act = env.action_spec.shape[-1]
    actor = nn.Sequential(nn.Linear(n_obs, 32), nn.Tanh(), nn.Linear(32, 2 * n_act),
                          NormalParamExtractor())
    policy = ProbabilisticActor(
        TensorDictModule(actor, in_keys=["observation"], out_keys=["loc", "scale"]),
        spec=env.action_spec, in_keys=["loc", "scale"], distribution_class=TanhNormal,
        distribution_kwargs={"low": -1.0, "high": 1.0}, return_log_prob=True)
    value = ValueOperator(nn.Sequential(nn.Linear(n_obs, 32), nn.Tanh(), nn.Linear(32, 1)),
                          in_keys=["observation"])
    collector = Collector(env, policy, frames_per_batch=500, total_frames=2000)
    advantage = GAE(gamma=0.99, lmbda=0.95, value_network=value)
    loss = ClipPPOLoss(policy, value)
    opt = torch.optim.Adam(loss.parameters(), 3e-4)
    before = [p.detach().clone() for p in actor.parameters()]
    frames, ends = 0, 0
    for td in collector:
        assert info_keys <= set(td["next"].keys())                # every info key, every step
        assert (td["next", "cost"] >= 0).all() and not td["next", "kpi_relevitation_time_s"].isnan().any()
        advantage(td)
        terms = loss(td)
        total = terms["loss_objective"] + terms["loss_critic"] + terms["loss_entropy"]
        opt.zero_grad()
        total.backward()
        opt.step()
        frames += td.numel()
        ends += int(td["next", "done"].sum())
    collector.shutdown()
    assert frames == 2000 and ends >= 30                          # 50-step episodes
    assert any(not torch.equal(a, b) for a, b in zip(actor.parameters(), before))


def test_skrl_ppo_trains_on_the_vector_env(tmp_path):
    pytest.importorskip("skrl")
    import torch
    from skrl.agents.torch.ppo import PPO, PPO_CFG
    from skrl.envs.wrappers.torch import wrap_env
    from skrl.memories.torch import RandomMemory
    from skrl.models.torch import DeterministicMixin, GaussianMixin, Model
    from skrl.trainers.torch import SequentialTrainer
    from torch import nn

    class Policy(GaussianMixin, Model):
        def __init__(self, observation_space, action_space, device):
            Model.__init__(self, observation_space=observation_space, action_space=action_space,
                           device=device)
            GaussianMixin.__init__(self, clip_actions=True)
            self.net = nn.Sequential(nn.Linear(self.num_observations, 32), nn.Tanh(),
                                     nn.Linear(32, self.num_actions))
            self.log_std = nn.Parameter(torch.full((self.num_actions,), -1.0))

        def compute(self, inputs, role=""):
            return self.net(inputs["observations"]), {"log_std": self.log_std}

    class Value(DeterministicMixin, Model):
        def __init__(self, observation_space, action_space, device):
            Model.__init__(self, observation_space=observation_space, action_space=action_space,
                           device=device)
            DeterministicMixin.__init__(self)
            self.net = nn.Sequential(nn.Linear(self.num_observations, 32), nn.Tanh(), nn.Linear(32, 1))

        def compute(self, inputs, role=""):
            return self.net(inputs["observations"]), {}

    warnings.simplefilter("ignore")
    torch.manual_seed(0)
    venv = gym.make_vec("RotorDrop-Damping-v1", num_envs=8, vectorization_mode="vector_entry_point",
                        episode_time=0.05, reward="kpi")
    env = wrap_env(venv, wrapper="gymnasium")
    assert env.num_envs == 8
    models = {"policy": Policy(env.observation_space, env.action_space, "cpu"),
              "value": Value(env.observation_space, env.action_space, "cpu")}
    cfg = PPO_CFG(rollouts=32, learning_epochs=2, mini_batches=2)
    cfg.experiment.directory = str(tmp_path)
    cfg.experiment.write_interval = 0
    cfg.experiment.checkpoint_interval = 0
    agent = PPO(models=models, memory=RandomMemory(memory_size=32, num_envs=8, device="cpu"),
                observation_space=env.observation_space, action_space=env.action_space,
                device="cpu", cfg=cfg)
    before = [p.detach().clone() for p in models["policy"].parameters()]
    SequentialTrainer(env=env, agents=agent, cfg={"timesteps": 300, "headless": True,
                                                   "disable_progressbar": True,
                                                   "close_environment_at_exit": False}).train()
    assert any(not torch.equal(a, b) for a, b in zip(models["policy"].parameters(), before))
    assert venv.unwrapped.get_attr("time")[0] < 0.05               # 300 steps: 6 episodes each
    venv.close()


def test_a_cleanrl_style_ppo_loop_trains_on_the_vector_env():
    """docs/examples/cleanrl_ppo.py: one-file PPO (no RL library) on gym.make_vec's
    vector_entry_point with the KPI reward; the SAME_STEP autoreset hands over each ended
    episode's KPIs in final_info and its final observation for the truncation bootstrap."""
    import importlib.util
    from pathlib import Path
    import numpy as np
    path = Path(__file__).resolve().parents[2] / "docs" / "examples" / "cleanrl_ppo.py"
    spec = importlib.util.spec_from_file_location("cleanrl_ppo", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    hist = mod.train("RotorDrop-Damping-v1", num_envs=8, total_timesteps=2048, num_steps=64,
                     seed=0, episode_time=0.05, log=lambda *_: None)
    assert len(hist["losses"]) == 4 and np.isfinite(hist["losses"]).all()
    ended = [k for ks in hist["kpis"] for k in ks]
    assert len(ended) >= 8                                   # every env finished episodes
    assert all(np.isfinite(list(k.values())).all() and "kpi_backward_whirl" in k for k in ended)
    assert all(r is None or np.isfinite(r) for r in hist["returns"])


def _tianshou_nets(obs_space, act_space, q):
    """A 32-unit actor (mean and state-independent sigma) and critics: two Q(s, a) for SAC
    (``q``), one V(s) for PPO."""
    from torch import nn
    from tianshou.utils.net.common import Net
    from tianshou.utils.net.continuous import ContinuousActorProbabilistic, ContinuousCritic
    actor = ContinuousActorProbabilistic(
        preprocess_net=Net(state_shape=obs_space.shape, hidden_sizes=[32], activation=nn.Tanh),
        action_shape=act_space.shape, unbounded=True)
    critic = [ContinuousCritic(preprocess_net=Net(
        state_shape=obs_space.shape, action_shape=act_space.shape if q else 0, concat=q,
        hidden_sizes=[32], activation=nn.Tanh)) for _ in range(2 if q else 1)]
    return actor, critic


def _check_tianshou_buffer(buf, info_keys, episode_time, min_ends):
    """No NaN anywhere in the buffer (the collector's own check raises MalformedBufferError
    too), every info key in it, and the ended episodes' final-step KPIs (not the reset's)."""
    import numpy as np
    assert len(buf) > 0 and not buf.hasnull()
    assert set(buf.info.keys()) == info_keys | {"env_id"}
    batch = buf[buf.sample_indices(0)]                   # every stored step of every env
    done = batch.done.astype(bool)
    assert done.sum() >= min_ends
    info = batch.info
    assert np.isfinite(batch.rew).all()
    np.testing.assert_allclose(info["kpi_episode_time_s"][done], episode_time, atol=1e-9)
    relev = info["kpi_relevitation_time_s"][done]
    assert ((relev == -1.0) | (relev >= 0.0)).all()      # the sentinel, never NaN


def test_tianshou_ppo_trains_through_episode_ends_on_full_supervisor():
    """Tianshou 2.0's OnPolicyTrainer with PPO on a DummyVectorEnv of the Full environment with
    the supervisor command: 20 episode ends in training, then a collect checked as a buffer."""
    pytest.importorskip("tianshou")
    import torch
    from torch.distributions import Independent, Normal
    from tianshou.algorithm import PPO
    from tianshou.algorithm.modelfree.reinforce import ProbabilisticActorPolicy
    from tianshou.algorithm.optim import AdamOptimizerFactory
    from tianshou.data import Collector, VectorReplayBuffer
    from tianshou.env import DummyVectorEnv
    from tianshou.trainer import OnPolicyTrainerParams
    warnings.simplefilter("ignore")
    torch.manual_seed(0)
    make = functools.partial(gym.make, "RotorDrop-Full-v1", command="supervisor",
                             episode_time=0.05, reward="kpi")       # 50 steps an episode
    info_keys = set(make().reset(seed=0)[1])
    envs = DummyVectorEnv([make] * 4)
    envs.seed(0)
    obs_space, act_space = envs.observation_space[0], envs.action_space[0]
    actor, (critic,) = _tianshou_nets(obs_space, act_space, q=False)
    policy = ProbabilisticActorPolicy(
        actor=actor, dist_fn=lambda loc_scale: Independent(Normal(*loc_scale), 1),
        action_space=act_space)
    algo = PPO(policy=policy, critic=critic, optim=AdamOptimizerFactory(lr=3e-4))
    buf = VectorReplayBuffer(1000, len(envs))
    collector = Collector(algo, envs, buf, raise_on_nan_in_buffer=True)
    before = [p.detach().clone() for p in actor.parameters()]
    stats = algo.run_training(OnPolicyTrainerParams(
        training_collector=collector, max_epochs=1, epoch_num_steps=1000,
        collection_step_num_env_steps=500, update_step_num_repetitions=2, batch_size=250,
        show_progress=False, verbose=False))
    assert stats.train_step == 1000 and stats.train_episode == 20
    assert any(not torch.equal(a, b) for a, b in zip(actor.parameters(), before))
    collector.reset_buffer()                              # on-policy: emptied after each update
    collector.collect(n_step=400)                         # 100 steps each: 2 episode ends each
    _check_tianshou_buffer(buf, info_keys, 0.05, min_ends=8)
    envs.close()


def test_tianshou_sac_trains_on_spawned_workers_in_damping():
    """Tianshou 2.0's OffPolicyTrainer with SAC on a SubprocVectorEnv whose workers are spawned
    (a fresh interpreter that never imported rotordrop_env: the "rotordrop_env:" prefix of the id
    registers it); the replay buffer keeps every step, so it is checked after training."""
    pytest.importorskip("tianshou")
    import torch
    from tianshou.algorithm import SAC
    from tianshou.algorithm.modelfree.sac import SACPolicy
    from tianshou.algorithm.optim import AdamOptimizerFactory
    from tianshou.data import Collector, VectorReplayBuffer
    from tianshou.env import SubprocVectorEnv
    from tianshou.trainer import OffPolicyTrainerParams
    warnings.simplefilter("ignore")
    torch.manual_seed(0)
    make = functools.partial(gym.make, "rotordrop_env:RotorDrop-Damping-v1", episode_time=0.05,
                             reward="kpi")
    info_keys = set(make().reset(seed=0)[1])
    envs = SubprocVectorEnv([make] * 2, context="spawn")
    try:
        envs.seed(0)
        obs_space, act_space = envs.observation_space[0], envs.action_space[0]
        actor, (critic, critic2) = _tianshou_nets(obs_space, act_space, q=True)
        opt = AdamOptimizerFactory(lr=1e-3)
        algo = SAC(policy=SACPolicy(actor=actor, action_space=act_space), policy_optim=opt,
                   critic=critic, critic_optim=opt, critic2=critic2, critic2_optim=opt)
        buf = VectorReplayBuffer(1000, len(envs))
        collector = Collector(algo, envs, buf, exploration_noise=True,
                              raise_on_nan_in_buffer=True)
        before = [p.detach().clone() for p in actor.parameters()]
        stats = algo.run_training(OffPolicyTrainerParams(
            training_collector=collector, max_epochs=1, epoch_num_steps=600,
            collection_step_num_env_steps=100, update_step_num_gradient_steps_per_sample=0.1,
            batch_size=64, show_progress=False, verbose=False))
        assert stats.train_step == 600 and stats.train_episode == 12
        assert any(not torch.equal(a, b) for a, b in zip(actor.parameters(), before))
        _check_tianshou_buffer(buf, info_keys, 0.05, min_ends=12)
    finally:
        envs.close()
