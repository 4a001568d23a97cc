"""Speed of this tree against another checkout of the project, interleaved: rhs cost and floor ratio.

    python benchmarks/bench_ab.py OTHER_TREE [--rounds 21] [--scene paper] [--set KEY=VALUE ...]

Starts one worker process per tree (each imports its own tree's physics and compiles its kernels),
then asks them in turn, A B A B ..., for one measurement each: the ns per rhs evaluation over the
states of a short drop (``bench_drop.ns_per_rhs``), and every ``--floor-every`` rounds the floor ratio
of a drop (``bench_drop.floor_ratio``, CPU clock) and a drop's CPU time, and with ``--env ID`` an
environment's steps/s (``bench_env.single_env_rate``). Prints the median of the per-round ratios
this tree / other tree, so that load from other processes moves both sides alike.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent

WORKER = r"""
import json, sys, time
sys.path.insert(0, sys.argv[1] + "/benchmarks")
from bench_drop import floor_ratio, ns_per_rhs
from physics import load_scene, simulate
scene = load_scene(sys.argv[2], json.loads(sys.argv[3]))
result = simulate(scene, t_end=float(sys.argv[4]))
ns_per_rhs(result)
print("ready", flush=True)
envs = {}
for line in sys.stdin:
    if line.startswith("rhs"):
        print(json.dumps(ns_per_rhs(result, clock=time.thread_time)), flush=True)
    elif line.startswith("env "):
        import rotordrop_env  # noqa: F401  (registers the ids)
        from bench_env import single_env_rate
        run = envs.setdefault(line.split()[1], single_env_rate(line.split()[1], {}, 2, True))
        print(json.dumps(run()), flush=True)
    elif line.startswith("floor"):
        f = floor_ratio(scene, float(sys.argv[4]), 1)
        drop = simulate(scene, t_end=float(sys.argv[4]))
        print(json.dumps([f["floor_ratio_cpu"], drop.stats.cpu_time_s]), flush=True)
"""


def _start(tree: Path, scene: str, overrides: dict, t_end: float) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=str(tree))
    p = subprocess.Popen([sys.executable, "-c", WORKER, str(tree), scene, json.dumps(overrides),
                          str(t_end)], cwd=tree, env=env, stdin=subprocess.PIPE,
                         stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "ready", f"worker of {tree} failed"
    return p


def _ask(p: subprocess.Popen, what: str):
    p.stdin.write(what + "\n")
    p.stdin.flush()
    return json.loads(p.stdout.readline())


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("other", type=Path, help="the other checkout (e.g. the main branch's)")
    ap.add_argument("--rounds", type=int, default=21)
    ap.add_argument("--floor-every", type=int, default=3)
    ap.add_argument("--scene", default="paper")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="scene override (JSON value, else a string)")
    ap.add_argument("--t-end", type=float, default=0.3)
    ap.add_argument("--env", action="append", default=[], metavar="ID",
                    help="also time this environment's steps/s (unwrapped, 2 episodes per round)")
    args = ap.parse_args(argv)
    overrides = {}
    for item in args.set:
        key, _, value = item.partition("=")
        try:
            overrides[key] = json.loads(value)
        except json.JSONDecodeError:
            overrides[key] = value
    a = _start(HERE, args.scene, overrides, args.t_end)
    b = _start(args.other.resolve(), args.scene, overrides, args.t_end)
    rhs, floor, cpu = [], [], []
    env_rates = {e: [] for e in args.env}
    for i in range(args.rounds):
        first, second = (a, b) if i % 2 == 0 else (b, a)        # alternate which goes first
        x, y = _ask(first, "rhs"), _ask(second, "rhs")
        rhs.append(x / y if first is a else y / x)
        if i % args.floor_every == 0:
            x, y = _ask(first, "floor"), _ask(second, "floor")
            if first is b:
                x, y = y, x
            floor.append(x[0] / y[0])
            cpu.append(x[1] / y[1])
        for e in args.env:
            x, y = _ask(first, "env " + e), _ask(second, "env " + e)
            env_rates[e].append(x / y if first is a else y / x)
    for p in (a, b):
        p.stdin.close()
        p.wait()
    print(json.dumps({"scene": args.scene, "overrides": overrides, "rounds": args.rounds,
                      "rhs_ratio_median": statistics.median(rhs),
                      "rhs_ratio_quartiles": statistics.quantiles(rhs, n=4),
                      "floor_ratio_ratio_median": statistics.median(floor),
                      "drop_cpu_time_ratio_median": statistics.median(cpu),
                      "floor_rounds": len(floor),
                      "env_steps_per_s_ratio_median": {e: statistics.median(r)
                                                       for e, r in env_rates.items()}},
                     indent=1))


if __name__ == "__main__":
    main()
