"""Rendering speed: frames per second of ``env.render()`` (``render_mode="rgb_array"``), and
its cost as a multiple of one environment step timed in the same run.

    python benchmarks/bench_render.py [--repeats 5] [--frames 200] [--json out.json]

``RotorDrop-Full-v1`` (the view with the most labels: damping and AMB lines too), paper scene at
μ = 0.5 run through its backward whirl (``terminate_on_failure=False``), default 1 ms control
step. A frame's cost grows with the recorded trace, so frames are timed after 10, 150 and 300
steps (the end of the 0.3 s episode). Also timed: a whole episode of steps without a render
mode and with ``rgb_array`` (recording one row per step, drawing nothing), so the recording
overhead is visible. Medians of ``--repeats`` runs after a warm-up, process CPU time.
"""
from __future__ import annotations

import argparse
import json
import statistics
import time

import gymnasium as gym
import numpy as np

import rotordrop_env  # noqa: F401  (registers the ids)

CLOCK = time.process_time
KW = dict(overrides={"contact.friction": 0.5}, terminate_on_failure=False)
ACTION = np.zeros(3, np.float32)


def _median(fn, repeats: int) -> float:
    fn()
    return statistics.median(fn() for _ in range(repeats))


def episode_rate(render_mode: str | None):
    """Steps per second over a whole episode (reset included)."""
    env = gym.make("RotorDrop-Full-v1", render_mode=render_mode, **KW)

    def run():
        t0 = CLOCK()
        env.reset(seed=0)
        steps = 0
        done = False
        while not done:
            _, _, te, tr, _ = env.step(ACTION)
            done, steps = te or tr, steps + 1
        return steps / (CLOCK() - t0)
    return run


def frame_rate(steps: int, frames: int):
    """render() calls per second with ``steps`` steps recorded."""
    env = gym.make("RotorDrop-Full-v1", render_mode="rgb_array", **KW)
    env.reset(seed=0)
    for _ in range(steps):
        env.step(ACTION)
    env.render()                                     # fonts and background once

    def run():
        t0 = CLOCK()
        for _ in range(frames):
            env.render()
        return frames / (CLOCK() - t0)
    return run


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--frames", type=int, default=200)
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    plain = _median(episode_rate(None), args.repeats)
    recording = _median(episode_rate("rgb_array"), args.repeats)
    out = {"steps_per_s": plain, "steps_per_s_recording": recording, "frames_per_s": {}}
    print(f"env steps/s (Full env, μ = 0.5 whirl):  {plain:9.0f} without render mode, "
          f"{recording:9.0f} with rgb_array (recording {1e6 / recording - 1e6 / plain:.1f} µs/step)")
    print(f"{'render() after':>16} {'frames/s':>9} {'ms/frame':>9} {'x one env step':>15}")
    for steps in (10, 150, 300):
        fps = _median(frame_rate(steps, args.frames), args.repeats)
        out["frames_per_s"][steps] = fps
        print(f"{steps:>10} steps {fps:9.0f} {1e3 / fps:9.2f} {plain / fps:15.1f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=2)
    return out


if __name__ == "__main__":
    main()
