"""Gyroscopics exercised: the conical and cylindrical whirl frequencies of the rigid rotor on its
AMB springs versus spin, forward and backward, from simulated free responses against the
linearised rigid rotor's frequency equation (physics/campbell.py, spec §1), on the asymmetric
preset, whose offset centre of mass couples tilt and translation."""
import numpy as np
import pytest

from physics import load_scene, simulate
from physics.campbell import (SPRINGS_ONLY, free_response, identified_frequencies,
                              whirl_frequencies)

SPRINGS = {**SPRINGS_ONLY, "solver.rtol": 1e-9}
T_END = 4.0
RPM = np.pi / 30


def tilt_frequencies(scene, omega):
    """Whirl frequencies identified from a 4 s free response; asserts it never touched a
    retainer (the AMB springs are the only support)."""
    t, Y, m = free_response(scene, omega, T_END)
    a, b = Y[:, m.index("a")], Y[:, m.index("b")]
    for z in (scene.positions.rb1, scene.positions.rb2):
        reach = np.hypot(Y[:, m.index("x")] + z * a, Y[:, m.index("y")] + z * b)
        assert reach.max() < 0.5 * scene.contact.clearance
    return identified_frequencies(t, a, b)


@pytest.mark.parametrize("rpm", [0.0, 10000.0, 30000.0])
def test_whirl_frequencies_versus_spin_match_the_linearised_rigid_rotor(rpm):
    """Measured: agreement to 3e-7 (e.g. 30 000 rpm: -153.738, -97.281, 140.124, 545.370 rad/s)."""
    scene = load_scene("asymmetric", SPRINGS)
    expected = whirl_frequencies(scene, rpm * RPM)
    assert (expected > 0).sum() == 2 and (expected < 0).sum() == 2     # 2 forward, 2 backward
    np.testing.assert_allclose(tilt_frequencies(scene, rpm * RPM), expected, rtol=1e-4)


def test_spin_splits_the_conical_mode_into_a_rising_forward_and_a_falling_backward_whirl():
    """At 30 000 rpm the conical pair has split by far more than the identification error, in
    the direction the sign of the gyroscopic terms decides: without them (or with their sign
    flipped) the simulated frequencies would be the Omega = 0 ones (or mirrored)."""
    scene = load_scene("asymmetric", SPRINGS)
    still, spun = whirl_frequencies(scene, 0.0), whirl_frequencies(scene, 30000.0 * RPM)
    assert spun.max() > 1.5 * still.max() and -spun.min() < 0.8 * -still.min()
    assert tilt_frequencies(scene, 30000.0 * RPM).max() == pytest.approx(spun.max(), rel=1e-4)
    no_gyro = load_scene("asymmetric", {**SPRINGS, "effects.gyroscopic": False})
    np.testing.assert_allclose(tilt_frequencies(no_gyro, 30000.0 * RPM), still, rtol=1e-4)


def test_the_asymmetric_drop_tilts_and_its_gyroscopic_coupling_changes_the_impacts():
    """The paper preset is mirror-symmetric: its tilts stay exactly zero and RB1 and RB2 see the
    same forces. Moving the centre of mass 80 mm towards RB1 makes RB1 land harder (60 % of the
    weight), tilts the rotor by ~0.4 mrad, and the gyroscopic terms then change the second
    plane's impact by several percent."""
    sym = simulate(load_scene("paper"), t_end=0.3)
    assert np.abs(sym.state("a")).max() == 0.0 and np.abs(sym.state("b")).max() == 0.0
    asym = simulate(load_scene("asymmetric"), t_end=0.3)
    assert np.abs(asym.state("b")).max() > 2e-4
    f1, f2 = (asym.contact_force(p).max() for p in ("RB1", "RB2"))
    assert f1 > 1.3 * f2
    flat = simulate(load_scene("asymmetric", {"effects.gyroscopic": False}), t_end=0.3)
    assert abs(flat.contact_force("RB2").max() / f2 - 1.0) > 0.03


def test_the_campbell_example_writes_simulated_and_linearised_frequencies(tmp_path):
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path
    root = Path(__file__).resolve().parents[2]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]))
    subprocess.run([sys.executable, str(root / "docs/examples/campbell.py"), "--out", str(tmp_path),
                    "--max-rpm", "20000", "--points", "2"], check=True, capture_output=True,
                   cwd=root, env=env)
    rows = json.loads((tmp_path / "campbell.json").read_text())["speeds"]
    assert [r["rpm"] for r in rows] == [0.0, 20000.0]
    assert max(r["max_rel_difference"] for r in rows) < 1e-4
    assert (tmp_path / "campbell.png").stat().st_size > 10_000
