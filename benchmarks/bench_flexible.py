"""What a flexible rotor costs: the flexible drop against the rigid paper drop, in one run.

    python benchmarks/bench_flexible.py [--repeats 5] [--t-end 1.0] [--out docs/data]

writes ``bench-flexible.json`` and the table ``bench-flexible-table.txt`` (docs/scaling.md pastes
it) into ``--out``.

For each case: CPU seconds of the integration per simulated second (median of ``--repeats``
rounds after a JIT warm-up, one core), as a ratio to the rigid paper drop timed interleaved with
it (each round times case, rigid, rigid, case), the accepted and rejected steps, the cost of one rhs, and the
drop's floor ratio (integration time over accepted steps' rhs evaluations x ns per rhs,
benchmarks/bench_drop.py). Then the stability bound that explains the step count: DOPRI5 (the
adaptive solver) is stable on an undamped oscillator of frequency omega only for h omega <=
3.3 (its stability region on the imaginary axis), so a run whose highest retained mode is
omega_max needs at least ``t omega_max / 3.3`` steps, whatever its tolerance.
"""
from __future__ import annotations

import argparse
import json
import math
import platform
import statistics
from datetime import date
from pathlib import Path

from bench_drop import floor_ratio, ns_per_rhs
from physics import load_scene, simulate
from physics.model import build_model
from physics.simulate import warm_up

#: DOPRI5's stability limit on the imaginary axis (h omega), e.g. Hairer & Wanner, Solving ODEs
#: II, fig. IV.2.1: the boundary crosses the imaginary axis near 3.3
DOPRI5_IMAGINARY_LIMIT = 3.3

CASES = [
    ("rigid paper drop", "paper", {}),
    ("paper-flexible (default modes)", "paper-flexible", {}),
    ("paper-flexible with static modes", "paper-flexible", {"flexible.static_modes": True}),
    ("paper-flexible, static modes only", "paper-flexible",
     {"flexible.static_modes": True, "flexible.mode_cutoff_hz": 0.0}),
    ("machine-flexible (default modes)", "machine-flexible", {}),
    ("machine-flexible with static modes", "machine-flexible", {"flexible.static_modes": True}),
]


def paired_ratio(scene, reference, t_end: float, repeats: int) -> tuple[float, object, object]:
    """Median over ``repeats`` rounds of cpu(scene) / cpu(reference), the integration's thread
    CPU time (robust to other processes on the machine, which move the wall clock of a 30 ms
    drop by 2 x), each round timed in the order scene, reference, reference, scene, and the last
    run of each."""
    ratios = []
    for _ in range(repeats):
        a1 = simulate(scene, t_end=t_end)
        b1 = simulate(reference, t_end=t_end)
        b2 = simulate(reference, t_end=t_end)
        a2 = simulate(scene, t_end=t_end)
        ratios.append((a1.stats.cpu_time_s + a2.stats.cpu_time_s)
                      / (b1.stats.cpu_time_s + b2.stats.cpu_time_s))
    return statistics.median(ratios), a2, b2


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=9)
    ap.add_argument("--t-end", type=float, default=1.0)
    ap.add_argument("--out", default=None, help="write bench-flexible.json and "
                    "bench-flexible-table.txt into this directory")
    args = ap.parse_args()
    reference = load_scene("paper")
    for _, source, ov in CASES:
        warm_up(build_model(load_scene(source, ov)))
    out: dict = {"repeats": args.repeats, "t_end": args.t_end, "cases": {}}
    print(f"median of {args.repeats} rounds (ABBA) of {args.t_end:g} s drops; ratio = CPU "
          f"time over the rigid paper drop's")
    print(f"{'case':36}{'modes':>6}{'states':>7}{'ratio':>7}{'steps':>8}{'rejected':>9}"
          f"{'ns/rhs':>8}{'floor':>7}{'min steps':>10}")
    for name, source, ov in CASES:
        scene = load_scene(source, ov)
        ratio, r, _ = paired_ratio(scene, reference, args.t_end, args.repeats)
        model = r.model
        omega_max = 0.0
        if model.elastic_modes:
            from physics.flexible.shafts import drop_rotor
            omega_max = float(drop_rotor(scene).omega.max())
        floor = floor_ratio(scene, args.t_end, max(1, args.repeats // 2))
        min_steps = math.ceil(args.t_end * omega_max / DOPRI5_IMAGINARY_LIMIT)
        row = dict(elastic_modes=model.elastic_modes, n_state=model.n_state,
                   cpu_ratio_vs_rigid=ratio, wall_s_per_sim_s=r.stats.wall_time_s / args.t_end,
                   steps=r.stats.steps, rejected=r.stats.rejected_steps, ns_per_rhs=ns_per_rhs(r),
                   floor_ratio_wall=floor["floor_ratio_wall"],
                   floor_ratio_cpu=floor["floor_ratio_cpu"],
                   highest_mode_hz=omega_max / (2 * math.pi),
                   stability_min_steps=min_steps)
        out["cases"][name] = row
        print(f"{name:36}{row['elastic_modes']:6d}{row['n_state']:7d}{ratio:7.2f}"
              f"{row['steps']:8d}{row['rejected']:9d}{row['ns_per_rhs']:8.0f}"
              f"{row['floor_ratio_cpu']:7.2f}{min_steps:10d}")
    print(f"\nmin steps: t x omega_max / {DOPRI5_IMAGINARY_LIMIT} (DOPRI5's stability bound for the "
          f"highest retained mode); floor: CPU time over accepted steps' rhs x ns per rhs")
    if args.out:
        out.update(date=date.today().isoformat(), machine=platform.processor() or platform.machine())
        d = Path(args.out)
        d.mkdir(parents=True, exist_ok=True)
        (d / "bench-flexible.json").write_text(json.dumps(out, indent=1))
        (d / "bench-flexible-table.txt").write_text(table(out))
        print(f"wrote {d / 'bench-flexible.json'}, {d / 'bench-flexible-table.txt'}")


def table(out: dict) -> str:
    """The markdown table docs/scaling.md pastes (between its markers)."""
    lines = ["| case | elastic modes | states | CPU time / rigid drop | steps | rejected | "
             "highest mode | stability bound on steps | floor ratio (CPU) |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for name, r in out["cases"].items():
        top = f"{r['highest_mode_hz']:,.0f} Hz" if r["elastic_modes"] else "-"
        bound = f"{r['stability_min_steps']:,}" if r["elastic_modes"] else "-"
        lines.append(f"| {name} | {r['elastic_modes']} | {r['n_state']} | "
                     f"{r['cpu_ratio_vs_rigid']:.2f} | {r['steps']:,} | {r['rejected']:,} | {top} | "
                     f"{bound} | {r['floor_ratio_cpu']:.2f} |")
    lines.append(f"\n{out['t_end']:g} s drops (mu = 0.25), medians of {out['repeats']} rounds timed "
                 f"in the order case, rigid, rigid, case, {out.get('date', '')}: `python benchmarks/bench_flexible.py --out docs/data`.")
    return "\n".join(lines) + "\n"

if __name__ == "__main__":
    main()
