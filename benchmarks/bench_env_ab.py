"""Environment speed of two source trees, interleaved: A B A B ... in one run.

    python benchmarks/bench_env_ab.py TREE_A TREE_B [--rounds 5] [--episodes 2] [--n-envs 16]

Each round runs, for tree A and then tree B (each in a fresh process with that tree first on
``PYTHONPATH``), the env steps/s of :mod:`bench_env` (process CPU time, after a warm-up): the
passive and the damping environment through ``gym.make`` over whole 0.3 s episodes of the paper
scene (mu = 0.25, and mu = 0.5 through the backward whirl), and the batched VecEnv (N envs of
the damping env, one numba thread). It prints each figure's median over the rounds for A and B
and the median of the per-round ratios B / A (> 1: B is faster). Interleaving makes a machine
whose load changes during the run weigh on both trees alike.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

#: what one process of a round measures (run with the tree's benchmarks/ on sys.path)
MEASURE = r"""
import json, sys
import rotordrop_env, numba
from bench_env import _median, batched_rate, single_env_rate
episodes, n_envs = int(sys.argv[1]), int(sys.argv[2])
out = {}
for label, kw in (("mu=0.25", {}),
                  ("mu=0.5", {"overrides": {"contact.friction": 0.5}, "terminate_on_failure": False})):
    for env_id in ("RotorDrop-Passive-v1", "RotorDrop-Damping-v1"):
        out[f"{env_id} {label}"] = _median(single_env_rate(env_id, kw, episodes, False), 1)
out[f"batched N={n_envs} 1 thread"] = _median(batched_rate("RotorDrop-Damping-v1", {}, n_envs,
                                                            300, 1), 1)
print("RESULT " + json.dumps(out))
"""


def measure(tree: Path, episodes: int, n_envs: int) -> dict[str, float]:
    env = dict(os.environ, PYTHONPATH=str(tree), MPLBACKEND="Agg")
    run = subprocess.run([sys.executable, "-c", MEASURE, str(episodes), str(n_envs)], env=env,
                         cwd=tree / "benchmarks", capture_output=True, text=True, check=True)
    line = next(x for x in run.stdout.splitlines() if x.startswith("RESULT "))
    return json.loads(line[len("RESULT "):])


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("tree_a", type=Path, help="the reference source tree (A)")
    p.add_argument("tree_b", type=Path, help="the tree compared with it (B)")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--episodes", type=int, default=2, help="episodes per single-env figure")
    p.add_argument("--n-envs", type=int, default=16)
    p.add_argument("--json", default=None, help="write every round's figures to this file")
    args = p.parse_args(argv)
    rounds = []
    for r in range(args.rounds):
        a = measure(args.tree_a.resolve(), args.episodes, args.n_envs)
        b = measure(args.tree_b.resolve(), args.episodes, args.n_envs)
        rounds.append({"A": a, "B": b})
        print(f"round {r + 1}/{args.rounds}: " + ", ".join(
            f"{k}: {b[k] / a[k]:.3f}" for k in a), flush=True)
    print(f"env steps/s, median of {args.rounds} interleaved rounds (A = {args.tree_a}, "
          f"B = {args.tree_b}):")
    for key in rounds[0]["A"]:
        med_a = statistics.median(x["A"][key] for x in rounds)
        med_b = statistics.median(x["B"][key] for x in rounds)
        ratio = statistics.median(x["B"][key] / x["A"][key] for x in rounds)
        print(f"  {key:36s} A {med_a:9.0f}  B {med_b:9.0f}  B/A {ratio:.3f}")
    if args.json:
        Path(args.json).write_text(json.dumps(rounds, indent=2))
        print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
