"""``rotordrop bc``: a behaviour-cloning baseline trained on a ``rotordrop dataset`` data set.

An MLP regresses the data set's actions on its observations (mean squared error, Adam, plain
torch). The network is the actor of a PPO ``MlpPolicy`` (two hidden tanh layers, a linear
output; deterministic ``predict`` returns that output clipped to the action space), and the
result is written in the project's self-contained policy format
(:mod:`agents.sb3_policy`): the observation normalisation (mean and variance of the training
observations) is inside the zip. So the cloned policy is a policy like any trained one:
``rotordrop evaluate --policy DIR/model.zip``, ``rotordrop benchmark --policy
DIR/model.zip``, the robust suite, ride-through, Ray tasks (it pickles as its path), and plain
``stable_baselines3.PPO.load`` all run it with no extra code. (A ``module:Class`` controller
loading a state dict would have needed a path to its weights that the benchmark has no way
to pass.) PPO's value head and ``log_std`` are left untrained: the zip is for acting.

Outputs in ``--out``: ``model.zip``, ``model.json`` and ``config.yaml`` (name, algorithm,
environment and its kwargs, so that both ``DIR`` and ``DIR/model.zip`` load with the display
name ``bc-<teacher>``), and ``bc.json`` (data set, fit: training and validation MSE against
the action variance, epochs, seconds).

    python3 -m agents.cli bc --dataset rotordrop/full/whirl-brake-v0 --root data/minari --out runs/bc
    python3 -m agents.training.imitation --dataset ... --out ...     # the same
"""
from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

from .dataset import episode_metadata, load, rotordrop_meta

HIDDEN = (256, 256)
EPOCHS = 40
BATCH = 256
LR = 1e-3
VALIDATION = 0.1            # fraction of the episodes held out (at least one when > 1 episode)
NORMALIZE = {"epsilon": 1e-8, "clip_obs": 10.0}


def dataset_arrays(ds, episodes=None) -> tuple[np.ndarray, np.ndarray]:
    """(observations (N, n_obs), actions (N, n_act)) of every step of ``episodes`` (default all):
    each action with the observation it was taken on (the last observation has none)."""
    obs, act = [], []
    for ep in ds.iterate_episodes(episodes):
        obs.append(np.asarray(ep.observations, dtype=np.float32)[:-1])
        act.append(np.asarray(ep.actions, dtype=np.float32).reshape(len(ep.rewards), -1))
    return np.concatenate(obs), np.concatenate(act)


def duplicate_columns(obs: np.ndarray, names) -> list[tuple[str, str]]:
    """Pairs of observations that are equal in every sample (and not constant): the data never
    tell them apart, so the clone cannot learn how to act when they differ. A symmetric
    teacher on the symmetric drop keeps the two bearing planes identical (x1 = x2, ...), and
    its clone then loses a tilting rotor; recording with sensor noise
    (``--env-kwarg sensor_noise=1e-6``) separates them (docs/datasets.md)."""
    pairs = []
    varying = [j for j in range(obs.shape[1]) if np.ptp(obs[:, j]) > 0]
    for a, i in enumerate(varying):
        for j in varying[a + 1:]:
            if np.array_equal(obs[:, i], obs[:, j]):
                pairs.append((names[i], names[j]))
    return pairs


def obs_statistics(obs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and variance per observation; a (near-)constant one keeps variance 1, so that
    it is only shifted (divided by ~0 it would map any new value to the clip)."""
    mean = obs.astype(np.float64).mean(axis=0)
    var = obs.astype(np.float64).var(axis=0)
    return mean, np.where(var < 1e-12, 1.0, var)


def _policy_model(env_id: str, env_kwargs: dict, hidden, meta: dict):
    """A PPO whose policy is the self-contained ``MlpPolicy`` (untrained)."""
    import torch as th
    from stable_baselines3 import PPO
    from ..control.plant import make_env
    from ..sb3_policy import RotorDropActorCriticPolicy
    env = make_env(env_id, **env_kwargs)
    model = PPO(RotorDropActorCriticPolicy, env, n_steps=64, batch_size=64, device="cpu",
                policy_kwargs=dict(net_arch=dict(pi=list(hidden), vf=[16]),
                                   activation_fn=th.nn.Tanh, log_std_init=-3.0, rotordrop=meta))
    return model, env


def mean_action(policy, x):
    """The actor's output (the deterministic action before clipping) for normalised ``x``."""
    features = policy.extract_features(x, policy.pi_features_extractor)
    return policy.action_net(policy.mlp_extractor.forward_actor(features))


def train_bc(dataset: str | Path, out: str | Path, root: str | Path | None = None,
             epochs: int = EPOCHS, hidden=HIDDEN, lr: float = LR, batch_size: int = BATCH,
             seed: int = 0, time_limit: float | None = None, threads: int = 1,
             name: str | None = None, progress: bool = True) -> dict:
    """Fit the cloned policy (module doc) on ``dataset`` (an id under ``root`` or a path) for
    ``epochs`` passes (or until ``time_limit`` seconds) and write it into ``out``. Returns the
    report written to ``bc.json``."""
    import torch as th
    from ..control.residual import RESIDUAL_SCALE
    if epochs < 1:
        raise ValueError(f"--epochs must be >= 1, got {epochs}")
    if batch_size < 1:
        raise ValueError(f"--batch-size must be >= 1, got {batch_size}")
    if seed < 0:
        raise ValueError(f"--seed must be >= 0, got {seed}")
    if not (lr > 0 and math.isfinite(lr)):
        raise ValueError(f"--lr must be a positive number, got {lr}")
    ds = load(dataset, root)
    meta = rotordrop_meta(ds)
    import gymnasium as gym
    if not isinstance(ds.action_space, gym.spaces.Box):
        raise ValueError(f"--dataset {ds.id}: behaviour cloning regresses continuous actions; "
                         f"its action space is {ds.action_space} (allowed: a Box)")
    th.manual_seed(seed)
    th.set_num_threads(max(1, threads))
    rng = np.random.default_rng(seed)
    n_eps = ds.total_episodes
    order = rng.permutation(n_eps)
    n_val = int(round(VALIDATION * n_eps)) if n_eps > 1 else 0
    n_val = min(max(n_val, 1 if n_eps > 1 else 0), n_eps - 1)
    val_eps, train_eps = sorted(order[:n_val].tolist()), sorted(order[n_val:].tolist())
    obs, act = dataset_arrays(ds, train_eps)
    mean, var = obs_statistics(obs)
    teacher = meta.get("policy_name", meta["policy"])
    name = name or f"bc-{teacher}"
    inside = dict(env_id=meta["env_id"], env_kwargs=dict(meta["env_kwargs"]), normalize=NORMALIZE,
                  residual=None, residual_scale=RESIDUAL_SCALE, memoryless=True)
    model, env = _policy_model(meta["env_id"], meta["env_kwargs"], hidden, inside)
    try:
        policy = model.policy
        policy.obs_mean.copy_(th.as_tensor(mean, dtype=th.float64))
        policy.obs_var.copy_(th.as_tensor(var, dtype=th.float64))
        x = th.as_tensor(policy.normalize_obs(obs))
        y = th.as_tensor(act)
        params = [*policy.mlp_extractor.policy_net.parameters(), *policy.action_net.parameters()]
        opt = th.optim.Adam(params, lr=lr)
        t0 = time.perf_counter()
        done = 0
        from tqdm.auto import tqdm
        for _ in tqdm(range(epochs), desc="bc epochs", unit="epoch", disable=not progress):
            perm = th.randperm(len(x))
            for i in range(0, len(x), batch_size):
                idx = perm[i:i + batch_size]
                loss = th.mean((mean_action(policy, x[idx]) - y[idx]) ** 2)
                opt.zero_grad()
                loss.backward()
                opt.step()
            done += 1
            if time_limit is not None and time.perf_counter() - t0 > time_limit:
                break
        fit_s = time.perf_counter() - t0
        names = list(env.unwrapped.obs_names)
        report = dict(name=name, teacher=teacher, dataset=ds.id, env_id=meta["env_id"],
                      env_kwargs=meta["env_kwargs"], episodes=dict(train=len(train_eps),
                                                                   validation=len(val_eps)),
                      samples=int(len(x)), hidden=list(hidden), lr=lr, batch_size=batch_size,
                      epochs=done, seed=seed, fit_s=fit_s,
                      train=fit_quality(policy, obs, act),
                      duplicate_observations=[list(p) for p in duplicate_columns(obs, names)])
        if val_eps:
            report["validation"] = fit_quality(policy, *dataset_arrays(ds, val_eps))
        report["validation_seeds"] = [episode_metadata(ds)[i]["seed"] for i in val_eps]
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        model.save(out / "model.zip")
    finally:
        env.close()
    from ..learning.hyperparams import dump_yaml
    from ..benchmarking.score import write_json
    load_meta = dict(name=name, algo="ppo", env_id=meta["env_id"], env_kwargs=meta["env_kwargs"],
                     notes=f"behaviour cloning of {teacher} on the data set {ds.id}")
    write_json(out / "model.json", load_meta, indent=1)
    dump_yaml(load_meta, out / "config.yaml")
    write_json(out / "bc.json", report, indent=1)
    report["out"] = str(out)
    return report


def fit_quality(policy, obs: np.ndarray, act: np.ndarray) -> dict:
    """MSE of the cloned policy's deterministic actions (as ``predict`` returns them, clipped)
    against ``act``, the actions' variance (summed over the dimensions, as the MSE is) and
    their ratio."""
    pred, _ = policy.predict(obs, deterministic=True)
    mse = float(np.mean(np.sum((np.asarray(pred, dtype=np.float64) - act) ** 2, axis=1)))
    var = float(np.sum(act.astype(np.float64).var(axis=0)))
    return dict(mse=mse, action_variance=var, mse_over_variance=mse / var if var > 0 else math.nan)


def register(sub) -> None:
    p = sub.add_parser("bc", help="behaviour cloning: fit an MLP policy to a rotordrop dataset "
                                  "(Minari) and save it as a policy the benchmark runs")
    add_arguments(p)
    p.set_defaults(func=cmd_bc)


def add_arguments(p) -> None:
    p.add_argument("--dataset", required=True,
                   help="Minari dataset id (under --root) or the data set's directory")
    p.add_argument("--root", default=None,
                   help="Minari datasets root (the --out of rotordrop dataset; default "
                        "$MINARI_DATASETS_PATH)")
    p.add_argument("--out", required=True, help="output directory (model.zip, bc.json)")
    p.add_argument("--epochs", type=int, default=EPOCHS, help=f"passes over the data (default {EPOCHS})")
    p.add_argument("--hidden", default=",".join(map(str, HIDDEN)),
                   help="hidden layer sizes (default 256,256)")
    p.add_argument("--lr", type=float, default=LR, help=f"Adam learning rate (default {LR:g})")
    p.add_argument("--batch-size", type=int, default=BATCH)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--time-limit", type=float, default=None, metavar="SECONDS",
                   help="stop after the epoch that passes this wall-clock budget")
    p.add_argument("--name", default=None, help="display name (default bc-<teacher>)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def parse_hidden(text: str) -> tuple[int, ...]:
    try:
        sizes = tuple(int(s) for s in text.split(",") if s.strip())
    except ValueError:
        sizes = ()
    if not sizes or any(s < 1 for s in sizes):
        raise ValueError(f"--hidden expects layer sizes >= 1 separated by commas, e.g. 256,256; "
                         f"got {text!r}")
    return sizes


def cmd_bc(args) -> int:
    try:
        r = train_bc(args.dataset, args.out, root=args.root, epochs=args.epochs,
                     hidden=parse_hidden(args.hidden), lr=args.lr, batch_size=args.batch_size,
                     seed=args.seed, time_limit=args.time_limit, name=args.name,
                     progress=not args.quiet)
    except (KeyError, ValueError, FileNotFoundError) as exc:
        print(f"rotordrop bc: error: {exc.args[0] if len(exc.args) == 1 else exc}", file=sys.stderr)
        return 2
    fit = r["train"]
    val = r.get("validation")
    print(f"{r['name']}: {r['samples']} samples ({r['episodes']['train']} episodes), {r['epochs']} "
          f"epochs in {r['fit_s']:.0f} s; MSE / action variance: train {fit['mse_over_variance']:.3f}"
          + (f", validation {val['mse_over_variance']:.3f}" if val else ""))
    if r["duplicate_observations"]:
        print("warning: observations equal in every sample (the data never tell them apart: "
              "where they differ, the clone acts on inputs it was not trained on; see "
              "docs/datasets.md): "
              + ", ".join("=".join(p) for p in r["duplicate_observations"]))
    print(f"wrote {Path(r['out']) / 'model.zip'}, bc.json; run it: python3 -m agents.cli "
          f"benchmark --quick --policy {Path(r['out']) / 'model.zip'}")
    return 0


def main(argv: list[str] | None = None) -> int:
    import argparse
    p = argparse.ArgumentParser(prog="python -m agents.training.imitation", description=__doc__.split("\n")[0])
    add_arguments(p)
    return cmd_bc(p.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
