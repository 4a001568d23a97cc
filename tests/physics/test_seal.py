"""Seal cross-coupling (physics/seal.py): the load's analytic work on a whirl orbit, its place in
the energy audit, and that with the effect off it adds no state and leaves the drop as it was."""
import math

import numpy as np
import pytest

from physics import load_scene, simulate
from physics.model import build_model
from physics.scene import SceneError
from physics.seal import seal_load

from helpers import energy_residual


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_cross_coupling_feeds_a_forward_whirl_and_drains_a_backward_one(direction):
    """On a circular orbit of radius r at whirl speed w (sign: direction), the power is w r² k:
    positive on a forward orbit for k > 0 (the destabilising sign), and the direct stiffness K
    does no work over a revolution."""
    K, k, r, w, z = 3e6, 2e5, 1e-4, direction * 800.0, 0.25
    work, n = 0.0, 720
    for i in range(n):
        th = 2 * math.pi * i / n
        # the station's displacement and velocity carried by translation alone (a = b = 0)
        fx, fy, ma, mb, p = seal_load(z, K, k, r * math.cos(th), r * math.sin(th), 0.0, 0.0,
                                      -w * r * math.sin(th), w * r * math.cos(th), 0.0, 0.0)
        assert p == pytest.approx(w * r * r * k, rel=1e-9)
        assert (ma, mb) == (pytest.approx(z * fx), pytest.approx(z * fy))
        work += p
    assert np.sign(work) == direction
    # a tilt moves the station: F acts on x + z a
    fx, fy, *_ = seal_load(z, K, 0.0, 0.0, 0.0, 1e-4, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert fx == pytest.approx(-K * z * 1e-4) and fy == 0.0


def test_the_energy_audit_closes_with_the_seal_on():
    r = simulate(load_scene("paper", {"effects.seal": True, "seal.cross_stiffness": 5e5,
                                      "seal.direct_stiffness": 1e6, "seal.z": 0.3,
                                      "contact.friction": 0.3}), t_end=0.3)
    res, e = energy_residual(r)
    assert abs(e["external"][-1]) > 0.0
    assert res.max() < 1e-5 * e["dissipated"][-1]


def test_off_it_costs_nothing_and_bad_values_are_named():
    on, off = (build_model(load_scene("paper", {"effects.seal": v})) for v in (True, False))
    assert on.names == off.names                                  # no state either way
    a = simulate(load_scene("paper"), t_end=0.05)
    b = simulate(load_scene("paper", {"seal.cross_stiffness": 9e8}), t_end=0.05)   # off: unused
    assert np.array_equal(a.Y, b.Y)
    with pytest.raises(SceneError, match=r"seal\.cross_stiffness"):
        load_scene("paper", {"seal.cross_stiffness": 1e12})
