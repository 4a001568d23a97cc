"""Environment speed of two source trees, interleaved: A B A B ... in one run.

    python benchmarks/bench_env_ab.py TREE_A TREE_B [--rounds 5] [--steps 600] [--n-envs 16]
                                      [--control-dt 2e-4 ...]

Each round runs, for tree A and then tree B (each in a fresh process with that tree first on
``PYTHONPATH``), the cases of :mod:`bench_env` (taken from this script's directory for both
trees, so both run the same measuring code; process CPU time, after a warm-up): by default its
1 ms cases (:func:`bench_env.step_cases`: the passive and the damping environment, ``gym.make``
and unwrapped, on the paper scene at mu = 0.25 and at mu = 0.5 through the backward whirl, and
the damping env's batches), with ``--control-dt`` (repeatable) the controller seat at those
steps (:func:`bench_env.seat_cases`: the single env, the SB3 batch and the vector env per
core); both with ``Pendulum-v1`` timed in the same process. It prints each figure's median over
the rounds for A and B, the median of the per-round ratios B / A (> 1: B is faster) and each
tree's median ratio to Pendulum-v1. Interleaving makes a machine whose load changes during the
run weigh on both trees alike.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

#: the figures of one process, one round (bench_env from this script's directory): the 1 ms
#: cases (an empty list of control steps) or the controller seat's at each control step
MEASURE = r"""
import json, sys
sys.path.insert(0, sys.argv[4])
from bench_env import seat_cases, step_cases
n_envs, steps, dts = int(sys.argv[1]), int(sys.argv[2]), json.loads(sys.argv[3])
cases = ({f"{1e3 * dt:g} ms {name}": run for dt in dts
          for name, run in seat_cases(dt, n_envs, steps).items()}
         or {f"1 ms {name}": run for name, run in step_cases(n_envs, steps).items()})
print("RESULT " + json.dumps({name: run() for name, run in cases.items()}))
"""


def measure(tree: Path, n_envs: int, control_dts=(), steps: int = 600) -> dict[str, float]:
    env = dict(os.environ, PYTHONPATH=str(tree), MPLBACKEND="Agg")
    cmd = [sys.executable, "-c", MEASURE, str(n_envs), str(steps), json.dumps(list(control_dts)),
           str(Path(__file__).resolve().parent)]
    run = subprocess.run(cmd, env=env, cwd=tree / "benchmarks", capture_output=True, text=True,
                         check=True)
    line = next(x for x in run.stdout.splitlines() if x.startswith("RESULT "))
    return json.loads(line[len("RESULT "):])


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("tree_a", type=Path, help="the reference source tree (A)")
    p.add_argument("tree_b", type=Path, help="the tree compared with it (B)")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--n-envs", type=int, default=16)
    p.add_argument("--control-dt", type=float, action="append", default=[], metavar="SECONDS",
                   help="measure the controller seat at this control step (repeatable)")
    p.add_argument("--steps", type=int, default=None,
                   help="env steps of every environment per case (default 3000 with "
                        "--control-dt, else 600: two 0.3 s episodes)")
    p.add_argument("--json", default=None, help="write every round's figures to this file")
    args = p.parse_args(argv)
    rounds = []
    for r in range(args.rounds):
        a, b = (measure(tree.resolve(), args.n_envs, args.control_dt,
                        args.steps or (3000 if args.control_dt else 600))
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
        print(f"  {key:52s} A {med_a:9.0f}  B {med_b:9.0f}  B/A {ratio:.3f}")
    pend = [k for k in rounds[0]["A"] if k.endswith("Pendulum-v1")]
    print("ratio to Pendulum-v1 of the same process, median over the rounds:")
    for key in rounds[0]["A"]:
        ref = next(k for k in pend if key.startswith(k.split(" ms ")[0] + " ms "))
        if key != ref:
            a, b = (statistics.median(x[t][key] / x[t][ref] for x in rounds) for t in "AB")
            print(f"  {key:52s} A {a:.3f}x  B {b:.3f}x")
    if args.json:
        Path(args.json).write_text(json.dumps(rounds, indent=2))
        print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
