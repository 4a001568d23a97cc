"""A CleanRL-style PPO in one file on the Gymnasium vector environment (no RL library).

    python docs/examples/cleanrl_ppo.py [--env-id RotorDrop-Damping-v1] [--num-envs 16]
                                        [--total-timesteps 200000] [--seed 0]

The loop of CleanRL's ``ppo_continuous_action.py`` (rollout of ``num_steps`` per environment,
GAE, clipped surrogate with minibatches), reduced to what this task needs: the environments'
observations are normalised already, actions live in [-1, 1], and the benchmark-aligned KPI
reward comes with ``reward="kpi"``. The vector environment autoresets in the same step
(``AutoresetMode.SAME_STEP``): the step that ends an episode returns the next episode's first
observation, with the ended episode's KPIs in ``info["final_info"]``; the value of the final
observation bootstraps a time-limit truncation. Prints the mean episode return and the
benchmark's KPIs of the finished episodes after every update.
"""
from __future__ import annotations

import argparse

import gymnasium as gym
import numpy as np
import torch
from torch import nn

import rotordrop_env  # noqa: F401  (registers the ids)


def layer(n_in: int, n_out: int, std: float = np.sqrt(2)) -> nn.Linear:
    lin = nn.Linear(n_in, n_out)
    nn.init.orthogonal_(lin.weight, std)
    nn.init.zeros_(lin.bias)
    return lin


class Agent(nn.Module):
    """Gaussian policy with a state-independent log std, and a value function."""

    def __init__(self, n_obs: int, n_act: int, hidden: int = 64):
        super().__init__()
        self.critic = nn.Sequential(layer(n_obs, hidden), nn.Tanh(), layer(hidden, hidden),
                                    nn.Tanh(), layer(hidden, 1, 1.0))
        self.mean = nn.Sequential(layer(n_obs, hidden), nn.Tanh(), layer(hidden, hidden),
                                  nn.Tanh(), layer(hidden, n_act, 0.01))
        self.log_std = nn.Parameter(torch.full((n_act,), -0.5))

    def value(self, obs):
        return self.critic(obs).squeeze(-1)

    def act(self, obs, action=None):
        dist = torch.distributions.Normal(self.mean(obs), self.log_std.exp())
        if action is None:
            action = dist.sample()
        return action, dist.log_prob(action).sum(-1), dist.entropy().sum(-1), self.value(obs)


def train(env_id: str = "RotorDrop-Damping-v1", num_envs: int = 16, total_timesteps: int = 200_000,
          num_steps: int = 64, seed: int = 0, lr: float = 3e-4, gamma: float = 0.99,
          gae_lambda: float = 0.95, epochs: int = 4, minibatches: int = 4, clip: float = 0.2,
          ent_coef: float = 0.0, vf_coef: float = 0.5, max_grad_norm: float = 0.5,
          log=print, **env_kwargs) -> dict:
    """Train; returns the history ``{"returns", "kpis", "losses"}`` (one entry per update)."""
    torch.manual_seed(seed)
    torch.set_num_threads(1)
    envs = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point",
                        reward="kpi", randomize=True, **env_kwargs)
    n_obs, n_act = envs.single_observation_space.shape[0], envs.single_action_space.shape[0]
    agent = Agent(n_obs, n_act)
    opt = torch.optim.Adam(agent.parameters(), lr=lr, eps=1e-5)
    obs_buf = torch.zeros(num_steps, num_envs, n_obs)
    act_buf = torch.zeros(num_steps, num_envs, n_act)
    logp_buf, rew_buf, done_buf, val_buf = (torch.zeros(num_steps, num_envs) for _ in range(4))
    obs, _ = envs.reset(seed=seed)
    obs = torch.as_tensor(obs)
    history = {"returns": [], "kpis": [], "losses": []}
    ep_return = np.zeros(num_envs)
    for update in range(max(total_timesteps // (num_steps * num_envs), 1)):
        finished, kpis = [], []
        for t in range(num_steps):
            with torch.no_grad():
                action, logp, _, value = agent.act(obs)
            step = envs.step(np.clip(action.numpy(), -1.0, 1.0))
            next_obs, reward, terminated, truncated, info = step
            reward = torch.as_tensor(reward, dtype=torch.float32)
            ended = terminated | truncated
            if truncated.any():                     # bootstrap a time limit from the final obs
                final = torch.as_tensor(np.stack([info["final_obs"][i] if truncated[i]
                                                  else np.zeros(n_obs, np.float32)
                                                  for i in range(num_envs)]))
                with torch.no_grad():
                    reward += gamma * agent.value(final) * torch.as_tensor(truncated)
            ep_return += step[1]
            for i in np.flatnonzero(ended):
                finished.append(ep_return[i])
                ep_return[i] = 0.0
                kpis.append({k: float(v[i]) for k, v in info["final_info"].items()
                             if k.startswith("kpi_") and not k.startswith("_")})
            obs_buf[t], act_buf[t], logp_buf[t], val_buf[t] = obs, action, logp, value
            rew_buf[t], done_buf[t] = reward, torch.as_tensor(terminated | truncated,
                                                              dtype=torch.float32)
            obs = torch.as_tensor(next_obs)
        with torch.no_grad():                       # GAE over the rollout
            adv = torch.zeros_like(rew_buf)
            last, next_value = 0.0, agent.value(obs)
            for t in reversed(range(num_steps)):
                nonterminal = 1.0 - done_buf[t]
                nv = next_value if t == num_steps - 1 else val_buf[t + 1]
                delta = rew_buf[t] + gamma * nv * nonterminal - val_buf[t]
                last = delta + gamma * gae_lambda * nonterminal * last
                adv[t] = last
            ret = adv + val_buf
        b_obs, b_act = obs_buf.reshape(-1, n_obs), act_buf.reshape(-1, n_act)
        b_logp, b_adv, b_ret = logp_buf.reshape(-1), adv.reshape(-1), ret.reshape(-1)
        batch = b_obs.shape[0]
        for _ in range(epochs):
            for mb in torch.randperm(batch).chunk(minibatches):
                _, logp, entropy, value = agent.act(b_obs[mb], b_act[mb])
                ratio = (logp - b_logp[mb]).exp()
                a = (b_adv[mb] - b_adv[mb].mean()) / (b_adv[mb].std() + 1e-8)
                pg = torch.max(-a * ratio, -a * ratio.clamp(1 - clip, 1 + clip)).mean()
                loss = pg + vf_coef * 0.5 * ((value - b_ret[mb]) ** 2).mean() \
                    - ent_coef * entropy.mean()
                opt.zero_grad()
                loss.backward()
                nn.utils.clip_grad_norm_(agent.parameters(), max_grad_norm)
                opt.step()
        history["losses"].append(float(loss))
        history["returns"].append(float(np.mean(finished)) if finished else None)
        history["kpis"].append(kpis)
        if finished:
            whirl = np.mean([k["kpi_backward_whirl"] for k in kpis])
            log(f"update {update + 1}: {len(finished)} episodes, mean return "
                f"{np.mean(finished):.3f}, whirl rate {whirl:.2f}")
    envs.close()
    return history


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--env-id", default="RotorDrop-Damping-v1")
    ap.add_argument("--num-envs", type=int, default=16)
    ap.add_argument("--total-timesteps", type=int, default=200_000)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    train(a.env_id, a.num_envs, a.total_timesteps, seed=a.seed)


if __name__ == "__main__":
    main()
