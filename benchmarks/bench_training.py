"""Training throughput: environment steps per second of SB3 on the batched rotor-drop env.

    python benchmarks/bench_training.py [--repeats 3] [--steps 16384] [--algos ppo sac]
                                        [--threads 1 2] [--json out.json]

For each algorithm and thread count (torch and numba threads, ``rotordrop train --threads``)
a short ``agents.training.train.train`` run on ``RotorDrop-Damping-v1`` with the shipped
hyperparameters (evaluation and checkpoints off) is timed; figures are medians of
``--repeats`` runs after a warm-up. Also the raw batched env with random actions
(``bench_env.batched_rate``, timed by the wall clock like the training runs), to separate the
physics from the learning cost. Numbers depend on the load of the machine: run it alone.
"""
from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time

import numba

import bench_env
from bench_env import batched_rate

ENV = "RotorDrop-Damping-v1"
ENV_KWARGS = dict(randomize=True, terminate_on_failure=False)
N_ENVS, ENV_STEPS = 8, 500


def env_steps_per_s(threads: int, repeats: int) -> float:
    """Median env steps per second of the batched env alone (random actions drawn up front)."""
    threads = min(threads, numba.config.NUMBA_NUM_THREADS)
    run = batched_rate(ENV, ENV_KWARGS, N_ENVS, ENV_STEPS, threads)
    run()                                                  # warm-up (compile / cache load)
    return statistics.median(run() for _ in range(repeats))


def train_steps_per_s(algo: str, steps: int, threads: int) -> float:
    from agents.training.train import train
    with tempfile.TemporaryDirectory() as d:
        cfg = f"{d}/bench.yaml"
        with open(cfg, "w") as fh:
            fh.write(f"{ENV}:\n  eval_freq: 0\n  checkpoint_freq: 0\n")
        res = train(ENV, algo, f"{d}/run", timesteps=steps, config=cfg, seed=0, threads=threads,
                    progress=False)
        return res.timesteps / res.wall_time_s


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--steps", type=int, default=16384)
    ap.add_argument("--algos", nargs="+", default=["ppo", "sac"])
    ap.add_argument("--threads", nargs="+", type=int, default=[1, 2])
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    bench_env.CLOCK = time.perf_counter                    # wall clock, as the training runs
    out = {}
    for th in args.threads:
        v = env_steps_per_s(th, args.repeats)
        out[f"env random actions, {th} thread(s)"] = v
        print(f"batched env ({N_ENVS} envs, random actions), {th} thread(s): {v:9.0f} steps/s",
              flush=True)
    for algo in args.algos:
        for th in args.threads:
            steps = args.steps
            train_steps_per_s(algo, 2048, th)               # warm-up
            v = statistics.median(train_steps_per_s(algo, steps, th) for _ in range(args.repeats))
            out[f"{algo} training, {th} thread(s)"] = v
            print(f"{algo} training ({steps} steps), {th} thread(s): {v:9.0f} steps/s", flush=True)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=1)


if __name__ == "__main__":
    main()
