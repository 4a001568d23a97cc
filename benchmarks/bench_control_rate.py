"""What a realistic control rate costs: the raw-current law at control steps of 0.1-1 ms.

    python3 benchmarks/bench_control_rate.py [--repeats 3] [--episode-time 0.15]
                                             [--dts 1e-3,2e-4,1e-4] [--clock cpu|wall]

A digital AMB controller samples at 10-20 kHz; the environments' default control step is 1 ms.
This runs ``whirl-brake`` (PD on the raw coil currents, ``RotorDrop-Full-v1``,
``command="continuous"``) on the paper scene's drop for each control step ``control_dt``,
without and with the sensing of the robust suite's middle (``sensor_delay`` 0.1 ms,
``sensor_noise`` 0.5 µm: the delay's Padé states and one noise sample per step), and prints the
medians over ``--repeats`` whole episodes on one environment (reset, steps and the law's
actions; after a warm-up) of env steps per second and simulated seconds per second of CPU (or
wall) time, each as a ratio to the 1 ms step's in the same run, and (``/none``) to the same step without sensing. Whether the episode re-levitates
is printed too (the law's gains were tuned at 1 ms).
No timing is asserted anywhere.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from agents.control.controllers import controller_env_kwargs  # noqa: E402
from agents.control.controllers import BASELINES  # noqa: E402
from agents.control.plant import Plant  # noqa: E402
from agents.benchmarking.rollout import _episode, make_env  # noqa: E402

ENV = "RotorDrop-Full-v1"
LAW = "whirl-brake"
SENSING = {"none": {}, "delay 0.1 ms + noise 0.5 µm": dict(sensor_delay=1e-4, sensor_noise=5e-7)}


def measure(dt: float, sensing: dict, episode_time: float, repeats: int, clock) -> dict:
    """Median time of whole episodes (reset + steps + the controller's actions) on one env."""
    cls = BASELINES[LAW]
    kw = dict(controller_env_kwargs(cls, ENV), control_dt=dt, episode_time=episode_time,
              terminate_on_failure=False, **sensing)
    env = make_env(ENV, **kw)
    plant = Plant.from_env(env)
    _episode(env, plant, cls(plant), 0, False)                # warm-up: compile, fault state
    times, ep = [], None
    for _ in range(repeats):
        t0 = clock()
        ep = _episode(env, plant, cls(plant), 0, False)
        times.append(clock() - t0)
    env.close()
    t = statistics.median(times)
    return dict(steps=ep.length, steps_per_s=ep.length / t, sim_per_s=ep.length * dt / t,
                relevitated=bool(ep.kpis.get("relevitated")))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--episode-time", type=float, default=0.15)
    ap.add_argument("--dts", default="1e-3,2e-4,1e-4", help="control steps [s], the first the reference")
    ap.add_argument("--clock", choices=("cpu", "wall"), default="cpu")
    args = ap.parse_args(argv)
    clock = time.process_time if args.clock == "cpu" else time.perf_counter
    dts = [float(v) for v in args.dts.split(",")]
    print(f"{LAW} on {ENV}, paper scene, episode {args.episode_time:g} s, median of "
          f"{args.repeats} ({args.clock} clock); ratios to control_dt = {dts[0]:g} s, same sensing")
    print(f"{'sensing':30s} {'control_dt':>10s} {'steps':>6s} {'steps/s':>9s} {'ratio':>6s} "
          f"{'sim s/s':>8s} {'ratio':>6s} {'/none':>6s} relevitated")
    plain = {}
    for name, sensing in SENSING.items():
        ref = None
        for dt in dts:
            m = measure(dt, sensing, args.episode_time, args.repeats, clock)
            ref = ref or m
            base = plain.setdefault(dt, m)          # the same step without sensing
            print(f"{name:30s} {dt * 1e3:8.2f}ms {m['steps']:6d} {m['steps_per_s']:9.0f} "
                  f"{m['steps_per_s'] / ref['steps_per_s']:6.2f} {m['sim_per_s']:8.3f} "
                  f"{m['sim_per_s'] / ref['sim_per_s']:6.2f} "
                  f"{m['steps_per_s'] / base['steps_per_s']:6.2f} {m['relevitated']}")


if __name__ == "__main__":
    main()
