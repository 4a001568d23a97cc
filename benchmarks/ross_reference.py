"""Reference natural frequencies from ROSS 2.3.0 for tests/physics/flexible/test_flexible_ross.py.

    python3 -m venv /tmp/rossenv
    /tmp/rossenv/bin/pip install "ross-rotordynamics==2.3.0" "plotly<6"
    /tmp/rossenv/bin/python benchmarks/ross_reference.py

Builds two rotors in ROSS, saves each with ``Rotor.save`` to tests/data/<name>.toml, and writes
the first 4 forward and 4 backward lateral whirl frequencies at 0 and 10 000 rpm (``run_modal``,
``sparse=False``) to tests/data/ross_reference.json:

* ``ross_sample_rotor``: steel shaft 1.5 m x 50 mm in 6 Timoshenko elements (Cowper's shear
  coefficient), two 280 mm disks at nodes 2 and 4, linear isotropic bearings 1e6 N/m at nodes
  0 and 6;
* ``ross_thick_hollow_rotor``: a short thick hollow shaft (0.6 m, 120/60 mm, 8 elements with
  a 160/60 mm middle) where shear and the hollow-section coefficient matter, one disk at node 6,
  bearings 5e8 N/m at nodes 1 and 7.

ROSS's own whirl labels are "Mixed" for some modes; here a mode is forward when its forward
circular component dominates over all nodes (the measure of
physics.flexible.modal.whirl_direction). ROSS is kept out of the shared environment (it pins
numpy/scipy/plotly): run this only in its own venv.
"""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parents[1] / "tests" / "data"
JSON = DATA / "ross_reference.json"
SPEEDS = (0.0, 10_000 * 2 * math.pi / 60)  # rad/s
N_MODES = 4


def steel():
    import ross as rs
    return rs.Material(name="Steel", rho=7810.0, E=211e9, G_s=81.2e9)


def build_sample():
    """Slender solid shaft, two disks, soft bearings."""
    import ross as rs
    shaft = [rs.ShaftElement(L=0.25, idl=0.0, odl=0.05, material=steel(), shear_effects=True,
                             rotary_inertia=True, gyroscopic=True, shear_method_calc="cowper")
             for _ in range(6)]
    disks = [rs.DiskElement.from_geometry(n=n, material=steel(), width=0.07, i_d=0.05, o_d=0.28)
             for n in (2, 4)]
    bearings = [rs.BearingElement(n=n, kxx=1e6, kyy=1e6, cxx=0.0) for n in (0, 6)]
    return rs.Rotor(shaft, disks, bearings)


def build_thick_hollow():
    """Short thick hollow shaft (L/D ~ 5, elements L/D < 1): shear matters."""
    import ross as rs
    od = (0.12, 0.12, 0.12, 0.16, 0.16, 0.12, 0.12, 0.12)
    shaft = [rs.ShaftElement(L=0.075, idl=0.06, odl=d, material=steel(),
                             shear_method_calc="cowper") for d in od]
    disks = [rs.DiskElement(n=6, m=15.0, Id=0.08, Ip=0.14)]
    bearings = [rs.BearingElement(n=n, kxx=5e8, kyy=5e8, cxx=0.0) for n in (1, 7)]
    return rs.Rotor(shaft, disks, bearings)


ROTORS = {"ross_sample_rotor": build_sample, "ross_thick_hollow_rotor": build_thick_hollow}


def whirl_frequencies(rotor, speed: float, n_modes: int = N_MODES) -> dict:
    """First ``n_modes`` forward and backward lateral natural frequencies (rad/s) from ROSS."""
    modal = rotor.run_modal(speed, num_modes=4 * n_modes + 16, sparse=False)
    ndof = rotor.ndof
    x = np.arange(0, ndof, rotor.number_dof)
    y = x + 1
    fw, bw = [], []
    for i, wn in enumerate(modal.wn):
        if modal.shapes[i].mode_type != "Lateral":
            continue
        v = modal.evectors[:ndof, i]
        X, Y = v[x], v[y]
        f = np.sum(np.abs(X + 1j * Y) ** 2)
        b = np.sum(np.abs(X - 1j * Y) ** 2)
        (fw if f > b else bw).append(float(wn))
    if speed == 0.0:  # isotropic, not spinning: each frequency is a degenerate pair
        pairs = sorted(fw + bw)[::2]
        fw, bw = pairs, pairs
    return {"forward": sorted(fw)[:n_modes], "backward": sorted(bw)[:n_modes]}


def main() -> int:
    import ross
    ref = {"ross_version": ross.__version__, "unit": "rad/s",
           "command": "/tmp/rossenv/bin/python benchmarks/ross_reference.py",
           "speeds": list(SPEEDS), "rotors": {}}
    for name, build in ROTORS.items():
        rotor = build()
        toml = DATA / f"{name}.toml"
        toml.unlink(missing_ok=True)
        rotor.save(toml)
        ref["rotors"][name] = [whirl_frequencies(rotor, s) for s in SPEEDS]
    JSON.write_text(json.dumps(ref, indent=2) + "\n")
    print(json.dumps(ref, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
