"""Dry whirl at the AMB stators: the paper drop at mu = 0.5 with the stator contact on its mount,
over the stator friction mu_st; writes the table docs/physics.md quotes.

    python docs/examples/dry_whirl_onset.py [--out docs/img] [--t-end 1.0]

Writes ``dry-whirl-onset.json`` (per mu_st: the AMB1 metrics of ``rotordrop drop``, with the time
the run left the stator law's validity) and ``dry-whirl-onset-table.txt`` (the table). A run past a
validity bound gets its values before that time, marked, never the values after. ~20 s.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from tqdm.auto import tqdm

from physics import compute_metrics, load_scene, simulate
from physics.metrics import valid_or_before

FRICTIONS = (0.0, 0.02, 0.05, 0.1, 0.3)
BASE = {"contact.friction": 0.5, "effects.stator_contact": True}


def row(mu_st: float, t_end: float) -> dict:
    m = compute_metrics(simulate(load_scene("paper", {**BASE, "stator.friction": mu_st}), t_end=t_end))
    a = m["amb_planes"]["AMB1"]
    get = lambda k: valid_or_before(a, k)          # noqa: E731
    return dict(stator_friction=mu_st, left_validity_at_s=a["left_validity_at_s"],
                max_displacement_um=get("max_displacement_um"),
                stator_peak_force_N=get("stator_peak_force_N"),
                stator_penetration_um=get("stator_penetration_um"),
                max_stator_displacement_um=get("max_stator_displacement_um"),
                validity_bound_um=a["validity_bound_um"],
                final_rotor_speed_rpm=m["final_rotor_speed_rpm"], backward_whirl=m["backward_whirl"])


def table(rows: list[dict]) -> str:
    out = ["| μ_st | AMB-plane orbit | peak stator force | into the stack | stator moves on its mount "
           "| left validity at | rotor speed at the end |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        left = r["left_validity_at_s"]
        mark = " ¹" if left is not None else ""
        out.append(f"| {r['stator_friction']:g} | {r['max_displacement_um']:.0f} µm{mark} | "
                   f"{r['stator_peak_force_N'] / 1e3:.1f} kN{mark} | {r['stator_penetration_um']:.0f} µm{mark} | "
                   f"{r['max_stator_displacement_um']:.0f} µm{mark} | "
                   f"{f'{left:.3f} s' if left is not None else 'never'} | "
                   + (f"{r['final_rotor_speed_rpm']:.0f} rpm |" if left is None else "n/a |"))
    bound = rows[0]["validity_bound_um"]
    out.append(f"\n¹ up to the time the run left the stator law's validity ({bound:.1f} µm into the "
               "stack); what follows is not computable.")
    return "\n".join(out) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/img")
    ap.add_argument("--t-end", type=float, default=1.0)
    a = ap.parse_args()
    rows = [row(mu, a.t_end) for mu in tqdm(FRICTIONS, desc="stator friction")]
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "dry-whirl-onset.json").write_text(json.dumps(rows, indent=1))
    (out / "dry-whirl-onset-table.txt").write_text(table(rows))
    print(table(rows))


if __name__ == "__main__":
    main()
