"""Environment speed of two source trees, interleaved: A B A B ... in one run.

    python benchmarks/bench_env_ab.py TREE_A TREE_B [--rounds 5] [--episodes 2] [--n-envs 16]
                                      [--control-dt 2e-4 ...]

Each round runs, for tree A and then tree B (each in a fresh process with that tree first on
``PYTHONPATH``), the env steps/s of :mod:`bench_env` (process CPU time, after a warm-up): the
passive and the damping environment through ``gym.make`` over whole 0.3 s episodes of the paper
scene (mu = 0.25, and mu = 0.5 through the backward whirl), and the batched VecEnv (N envs of
the damping env, one numba thread). It prints each figure's median over the rounds for A and B
and the median of the per-round ratios B / A (> 1: B is faster). Interleaving makes a machine
whose load changes during the run weigh on both trees alike.

With ``--control-dt`` (repeatable) each process instead measures the controller seat at those
steps (:func:`bench_env.seat_cases`, taken from this script's directory for both trees, so both
run the same measuring code): Pendulum-v1, the single env, the SB3 batch and the vector env per
core; it prints the per-round ratios B / A and each tree's median ratio to Pendulum-v1.
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

#: the controller seat's figures (bench_env.seat_cases) of one process, one round
MEASURE_SEAT = r"""
import json, sys
sys.path.insert(0, sys.argv[4])
from bench_env import seat_cases
n_envs, steps = int(sys.argv[1]), int(sys.argv[2])
out = {}
for dt in json.loads(sys.argv[3]):
    for name, run in seat_cases(dt, n_envs, steps).items():
        out[f"{1e3 * dt:g} ms {name}"] = run()
print("RESULT " + json.dumps(out))
"""


def measure(tree: Path, episodes: int, n_envs: int, control_dts=(), steps: int = 3000
            ) -> dict[str, float]:
    env = dict(os.environ, PYTHONPATH=str(tree), MPLBACKEND="Agg")
    cmd = [sys.executable, "-c", MEASURE, str(episodes), str(n_envs)]
    if control_dts:
        cmd = [sys.executable, "-c", MEASURE_SEAT, str(n_envs), str(steps),
               json.dumps(list(control_dts)), str(Path(__file__).resolve().parent)]
    run = subprocess.run(cmd, env=env, cwd=tree / "benchmarks", capture_output=True, text=True,
                         check=True)
    line = next(x for x in run.stdout.splitlines() if x.startswith("RESULT "))
    return json.loads(line[len("RESULT "):])


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("tree_a", type=Path, help="the reference source tree (A)")
    p.add_argument("tree_b", type=Path, help="the tree compared with it (B)")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--episodes", type=int, default=2, help="episodes per single-env figure")
    p.add_argument("--n-envs", type=int, default=16)
    p.add_argument("--control-dt", type=float, action="append", default=[], metavar="SECONDS",
                   help="measure the controller seat at this control step (repeatable)")
    p.add_argument("--steps", type=int, default=3000, help="env steps per controller-seat run")
    p.add_argument("--json", default=None, help="write every round's figures to this file")
    args = p.parse_args(argv)
    rounds = []
    for r in range(args.rounds):
        a, b = (measure(tree.resolve(), args.episodes, args.n_envs, args.control_dt, args.steps)
                for tree in (args.tree_a, args.tree_b))
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
    pend = [k for k in rounds[0]["A"] if k.endswith("Pendulum-v1")]
    if pend:
        print("ratio to Pendulum-v1 of the same process, median over the rounds:")
        for key in rounds[0]["A"]:
            ref = next(k for k in pend if key.startswith(k.split(" ms ")[0] + " ms "))
            if key != ref:
                a, b = (statistics.median(x[t][key] / x[t][ref] for x in rounds) for t in "AB")
                print(f"  {key:36s} A {a:.3f}x  B {b:.3f}x")
    if args.json:
        Path(args.json).write_text(json.dumps(rounds, indent=2))
        print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
