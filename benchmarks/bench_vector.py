"""Gymnasium vector environment against the SB3 batched VecEnv: steps per second per core.

    python benchmarks/bench_vector.py [--env-id RotorDrop-Full-v1] [--n-envs 16] [--steps 600]
                                      [--repeats 7] [--command supervisor]

Both are the same numba batch (rotordrop_env.batch) on one thread (``n_threads=1``: the per-core
figure), stepped with the same seeded random actions through whole episodes and their
auto-resets (default episode 0.3 s = 300 steps). Runs alternate (vector, SB3, vector, ...) in
one process so that both see the same machine load; the figure is the median over ``--repeats``
pairs of the ratio of the two rates (vector / SB3, > 1: the vector env is faster), timed by the
process CPU time.
"""
from __future__ import annotations

import argparse
import statistics
import time

import gymnasium as gym
import numpy as np

import rotordrop_env
from rotordrop_env import make_batched

CLOCK = time.process_time


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--env-id", default="RotorDrop-Full-v1", choices=list(rotordrop_env.ENV_IDS))
    ap.add_argument("--n-envs", type=int, default=16)
    ap.add_argument("--steps", type=int, default=600)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--command", default="supervisor",
                    help="re-levitation envs' command mode (ignored by the others)")
    args = ap.parse_args(argv)
    kw = {"command": args.command} if "Relevitate" in args.env_id or "Full" in args.env_id else {}
    vec = gym.make_vec(args.env_id, num_envs=args.n_envs, vectorization_mode="vector_entry_point",
                       n_threads=1, **kw)
    sb3 = make_batched(args.env_id, args.n_envs, seed=0, n_threads=1, **kw)
    vec.action_space.seed(0)
    acts = [vec.action_space.sample() for _ in range(args.steps)]
    vec.reset(seed=0)
    sb3.reset()

    def rate(step) -> float:
        t0 = CLOCK()
        for a in acts:
            step(a)
        return args.steps * args.n_envs / (CLOCK() - t0)

    vec_step, sb3_step = vec.step, sb3.step
    rate(vec_step), rate(sb3_step)                      # warm-up (JIT, scenario caches)
    pairs = [(rate(vec_step), rate(sb3_step)) for _ in range(args.repeats)]
    ratios = [v / s for v, s in pairs]
    print(f"{args.env_id} {kw or ''} N = {args.n_envs}, one thread, {args.steps} batch steps x "
          f"{args.repeats} interleaved pairs (CPU time)")
    print(f"  gymnasium vector env: {statistics.median(v for v, _ in pairs):9.0f} env steps/s")
    print(f"  SB3 batched VecEnv:   {statistics.median(s for _, s in pairs):9.0f} env steps/s")
    print(f"  median ratio vector / SB3: {statistics.median(ratios):.3f} "
          f"(min {min(ratios):.3f}, max {max(ratios):.3f})")


if __name__ == "__main__":
    main()
