"""The example rotors: the paper's rigid-body properties and their stated bending modes."""
import math

import numpy as np
import pytest

from physics.flexible import assembly as asm
from physics.flexible import examples, modal

RUN = 10_000 * 2 * math.pi / 60
K_AMB = 1e6  # N/m per AMB and axis (spec preset)
HZ = 1 / (2 * math.pi)


def first_bending(rotor):
    model = asm.assemble(rotor)
    ff = modal.free_free_frequencies(model)[4] * HZ
    S = asm.support_matrix(model, [(model.planes[p], K_AMB, K_AMB) for p in ("amb1", "amb2")])
    red = modal.reduce(model, omega_cut=2 * math.pi * 3000)
    x, y = modal.model_whirl_dofs(model)
    c = modal.campbell(red.M, red.G, red.K + red.T.T @ S @ red.T, [RUN], 3, x, y, T=red.T)
    # modes 0, 1: rigid cylindrical and conical on the AMBs; 2: first bending
    return ff, c["forward"][0, 2] * HZ, c["backward"][0, 2] * HZ


@pytest.mark.parametrize("make", [examples.paper_flexible, examples.machine_flexible])
def test_rigid_body_properties_are_the_papers(make):
    rotor = make()
    p = asm.rigid_properties(rotor)
    assert p["mass"] == pytest.approx(97.3, rel=1e-12)
    assert p["I_d"] == pytest.approx(2.82, rel=1e-12)
    assert p["I_p"] == pytest.approx(0.39, rel=1e-12)
    assert p["z_cg"] == pytest.approx(0.0, abs=1e-12)
    disk = rotor.disks[0]
    assert disk.mass > 0 and disk.I_d >= disk.I_p / 2 > 0  # a physical thick disk
    model = asm.assemble(rotor)
    assert {k: float(model.z[v]) for k, v in model.planes.items()} == pytest.approx(
        {"amb1": -0.28, "amb2": 0.28, "rb1": -0.38, "rb2": 0.38, "unb1": 0.0})


def test_paper_flexible_first_bending_mode():
    ff, fw, bw = first_bending(examples.paper_flexible())
    assert (ff, fw, bw) == pytest.approx((740.5, 744.1, 737.3), rel=5e-4)
    assert fw / (RUN * HZ) > 4


def test_machine_flexible_first_forward_bending_between_1_5_and_3_x_running_speed():
    ff, fw, bw = first_bending(examples.machine_flexible())
    assert (ff, fw, bw) == pytest.approx((399.2, 402.2, 399.6), rel=5e-4)
    assert 1.5 < fw / (RUN * HZ) < 3.0


def test_shaft_heavier_than_the_paper_rotor_is_refused():
    with pytest.raises(ValueError, match=r"disks\[0\].I_d = -\d"):
        examples.matched_rotor(0.1, 0.16, 0.4, "too-heavy")


@pytest.mark.parametrize("make", [examples.paper_flexible, examples.machine_flexible])
def test_stiff_limit_is_the_rigid_rotor_of_the_paper_scene(make):
    """E x 1000: the reduced flexible model on the paper scene's AMB springs whirls at the rigid
    rotor's frequencies of physics/campbell.py (same scene, same sign convention: forward
    positive) at 0 and 10 000 rpm."""
    from dataclasses import replace

    from physics import campbell, load_scene
    scene = load_scene("paper")
    stiff = replace(asm.STEEL, E=asm.STEEL.E * 1000, G_s=asm.STEEL.G_s * 1000)
    model = asm.assemble(make(stiff))
    k = scene.amb.stiffness
    S = asm.support_matrix(model, [(model.planes[p], k, k) for p in ("amb1", "amb2")])
    red = modal.reduce(model, n_bending=2)
    x, y = modal.model_whirl_dofs(model)
    for omega in (1.0, RUN):
        rigid = campbell.whirl_frequencies(scene, omega)
        c = modal.campbell(red.M, red.G, red.K + red.T.T @ S @ red.T, [omega], 2, x, y, T=red.T)
        assert np.sort(c["forward"][0]) == pytest.approx(np.sort(rigid[rigid > 0]), rel=1e-4)
        assert np.sort(c["backward"][0]) == pytest.approx(np.sort(-rigid[rigid < 0]), rel=1e-4)


def test_the_flexible_campbell_example_writes_its_diagram(tmp_path):
    """docs/examples/flexible_campbell.py: the machine rotor's first forward bending line at
    10 000 rpm is the stated 402 Hz, and the figure is written."""
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path
    root = Path(__file__).resolve().parents[3]
    env = dict(os.environ,
               PYTHONPATH=os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]))
    subprocess.run([sys.executable, str(root / "docs/examples/flexible_campbell.py"), "--out",
                    str(tmp_path), "--max-rpm", "30000"], check=True, capture_output=True,
                   cwd=root, env=env)
    data = json.loads((tmp_path / "campbell.json").read_text())
    i = data["rpm"].index(10000.0)
    assert data["forward_hz"][i][2] == pytest.approx(402.2, rel=5e-4)
    assert (tmp_path / "campbell.png").stat().st_size > 10_000
