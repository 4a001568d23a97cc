"""A transient external load (physics/external_load.py): on linear AMBs a held step deflects the
rotor by F / (2k) and tilts it by z_F F / (k Σ z_k²); a pulse's impulse changes a free rotor's
momentum by 2 F T / π (half-sine) or F (T − τ) (ramped step) on top of gravity's; the energy audit
closes through an overload and the drop after it; off by default, no state, bad input refused by
name."""
import math

import numpy as np
import pytest

from physics import load_scene, simulate
from physics.external_load import impulse, profile
from physics.model import build_model
from physics.scene import SceneError
from physics.simulate import segments

from helpers import energy_residual

ON = {"effects.external_load": True, "amb.off_time": 10.0}


def test_a_held_step_on_linear_ambs_gives_the_static_deflection_and_tilt():
    """F = 200 N along +x at z_F = 0.1 m, ramped over 20 ms and held for 0.5 s (the AMB mode
    decays in 50 ms), no gravity: x = F / (2k), a = z_F F / (k (z_1² + z_2²)) within 0.1 %."""
    F, zF, t0 = 200.0, 0.1, 0.01
    scene = load_scene("paper", {**ON, "effects.gravity": False, "effects.unbalance": False,
                                 "external_load.peak": F, "external_load.angle_deg": 0.0,
                                 "external_load.z": zF, "external_load.profile": "step",
                                 "external_load.ramp": 0.02, "external_load.start": t0,
                                 "external_load.duration": 0.6, "solver.output_rate": 1000.0})
    r = simulate(scene, t_end=0.5)
    m, k = r.model, scene.amb.stiffness
    z1, z2 = scene.positions.amb1, scene.positions.amb2
    assert r.Y[-1, m.index("x")] == pytest.approx(F / (2 * k), rel=1e-3)
    assert r.Y[-1, m.index("a")] == pytest.approx(zF * F / (k * (z1 ** 2 + z2 ** 2)), rel=1e-3)
    assert abs(r.Y[-1, m.index("y")]) < 1e-12
    assert np.all(r.Y[r.t < t0, m.index("x")] == 0.0)               # nothing before the load


@pytest.mark.parametrize("shape", [{"external_load.profile": "half_sine"},
                                   {"external_load.profile": "step", "external_load.ramp": 5e-4}])
def test_a_pulse_changes_a_free_rotors_momentum_by_its_impulse(shape):
    """AMBs off (effects.amb = none), gravity on, a 400 N, 2 ms pulse at 30° from t_0 = 0.5 ms:
    M v = impulse (cos θ, sin θ) − M g t (j 0, 1) at 3 ms (the rotor flies free: < 300 µm)."""
    F, T, theta, t0, t1 = 400.0, 2e-3, 30.0, 5e-4, 3e-3
    scene = load_scene("paper", {"effects.amb": "none", "effects.unbalance": False,
                                 "effects.external_load": True, "external_load.peak": F,
                                 "external_load.duration": T, "external_load.angle_deg": theta,
                                 "external_load.start": t0, "solver.rtol": 1e-10, **shape})
    r = simulate(scene, t_end=t1)
    m, M, g = r.model, scene.rotor.mass, scene.world.gravity
    J = impulse(scene)
    want = 2 * F * T / math.pi if shape["external_load.profile"] == "half_sine" else F * (T - 5e-4)
    assert J == pytest.approx(want, rel=1e-15)
    assert M * r.Y[-1, m.index("vx")] == pytest.approx(J * math.cos(math.radians(theta)), rel=1e-7)
    assert M * r.Y[-1, m.index("vy")] == pytest.approx(J * math.sin(math.radians(theta))
                                                       - M * g * t1, rel=1e-7)
    assert np.max(np.abs(r.Y[:, m.index("y")])) < scene.contact.clearance


def test_the_step_profile_ramps_holds_and_the_integration_stops_at_its_corners():
    scene = load_scene("paper", {**ON, "external_load.peak": 1.0, "external_load.profile": "step",
                                 "external_load.ramp": 0.002, "external_load.start": 0.01,
                                 "external_load.duration": 0.01})
    m = build_model(scene)
    for t, want in ((0.005, 0.0), (0.011, 0.5), (0.015, 1.0), (0.019, 0.5), (0.0201, 0.0)):
        assert profile(t, m.P, m.I) == pytest.approx(want, abs=1e-12)
    ends = [b for _, b, _ in segments(m, 1.0)]
    assert all(any(abs(e - t) < 1e-15 for e in ends) for t in (0.01, 0.012, 0.018, 0.02))


def test_the_energy_audit_closes_through_an_overload_and_the_drop_that_follows():
    """A 2 kN downward step for 20 ms (over the 600 N that closes the gap on the AMB springs)
    while levitated, then the fault and the drop: the load's work is booked, the audit closes."""
    r = simulate(load_scene("paper", {"effects.external_load": True, "external_load.peak": 2000.0,
                                      "external_load.profile": "step", "external_load.ramp": 1e-3,
                                      "external_load.start": 0.03, "external_load.duration": 0.02,
                                      "external_load.z": 0.2}), t_end=0.3)
    res, e = energy_residual(r)
    during = (r.t > 0.03) & (r.t < 0.05)
    assert np.max(r.contact_force("RB2")[during]) > 100.0      # pushed into its retainer bearing
    assert np.max(np.abs(e["external"][during])) > 0.1
    assert res.max() < 1e-5 * e["dissipated"][-1]


def test_off_by_default_no_state_and_nothing_changes():
    assert load_scene("paper").effects.external_load is False
    on = build_model(load_scene("paper", {**ON, "external_load.peak": 5.0}))
    off = build_model(load_scene("paper", {"amb.off_time": 10.0}))
    assert on.names == off.names
    a = simulate(load_scene("paper"), t_end=0.05)
    b = simulate(load_scene("paper", {"external_load.peak": 500.0, "external_load.start": 0.0}),
                 t_end=0.05)
    assert np.array_equal(a.Y, b.Y)


@pytest.mark.parametrize("overrides, match", [
    ({"external_load.peak": -1.0}, r"external_load\.peak = -1.0 is out of range"),
    ({"external_load.duration": 0.0}, r"external_load\.duration"),
    ({"external_load.profile": "square"}, r"external_load\.profile"),
    ({"effects.external_load": True}, r"needs external_load\.peak > 0"),
    ({"effects.external_load": True, "external_load.peak": 1.0, "external_load.profile": "step",
      "external_load.ramp": 0.01, "external_load.duration": 0.015}, r"external_load\.ramp = 0\.01"),
])
def test_bad_input_is_refused_by_name(overrides, match):
    with pytest.raises(SceneError, match=match):
        load_scene("paper", overrides)


def test_on_a_flexible_rotor_the_load_acts_at_the_unbalance_station_and_the_audit_closes():
    over = {"effects.external_load": True, "external_load.peak": 2000.0,
            "external_load.start": 0.03, "external_load.duration": 0.01}
    r = simulate(load_scene("paper-flexible", over), t_end=0.15)
    assert r.model.elastic_modes > 0
    res, e = energy_residual(r)
    assert res.max() < 1e-6 * e["dissipated"][-1]
    with pytest.raises(SceneError, match=r"external_load\.z = 0\.1 m: with rotor\.model = 'flexible'"):
        load_scene("paper-flexible", {**over, "external_load.z": 0.1})
