"""A sudden unbalance change (physics/unbalance_change.py): on linear AMBs the rotor settles on
the steady synchronous orbit of the new unbalance (the closed form of physics.rotor), the
integration is split at the change, the energy audit closes across it, and the effect is off by
default, adds no state and refuses bad input by name."""
import cmath
import math

import numpy as np
import pytest

from physics import load_scene, simulate
from physics.model import build_model
from physics.rotor import steady_unbalance_orbit
from physics.equilibrium import levitated_state
from physics.simulate import Integrator
from physics.scene import SceneError
from physics.simulate import segments

from helpers import energy_residual

ON = {"effects.unbalance_change": True, "amb.off_time": 10.0}


def test_on_linear_ambs_the_rotor_settles_on_the_new_unbalances_synchronous_orbit():
    """Rigid rotor, symmetric linear AMBs (k, c per plane), no gravity: after the change the
    centre's orbit x + iy tends to Z e^{i(φ + β')}, (2k − M Ω² + i 2c Ω) Z = m_u' e' Ω², and
    before it to the old unbalance's; amplitude and phase within 0.5 %."""
    t_s, t_end = 0.2, 0.6                      # 8 decay times of the AMB mode after each
    scene = load_scene("paper", {**ON, "effects.gravity": False, "unbalance_change.time": t_s,
                                 "unbalance_change.mass": 0.008, "unbalance_change.angle_deg": 30.0,
                                 "solver.output_rate": 20000.0})
    r = simulate(scene, t_end=t_end)
    m = r.model
    Omega = scene.rotor.speed_rpm * math.pi / 30.0
    k, c, M = 2 * scene.amb.stiffness, 2 * scene.amb.damping, scene.rotor.mass
    for t, u, beta in ((t_s, scene.unbalance, scene.unbalance.angle_deg),
                       (t_end, scene.unbalance_change, scene.unbalance_change.angle_deg)):
        j = np.searchsorted(r.t, t) - 1        # the last sample before t
        z = complex(r.Y[j, m.index("x")], r.Y[j, m.index("y")])
        want = steady_unbalance_orbit(u.mass * u.radius, Omega, M, k, c) * cmath.exp(
            1j * (r.Y[j, m.index("phi")] + math.radians(beta)))
        assert abs(z) == pytest.approx(abs(want), rel=5e-3)
        assert abs(z - want) < 5e-3 * abs(want)
    assert r.Y[:, m.index("Omega")] == pytest.approx(Omega, rel=1e-12)     # no contact, no torque


def _xy(scene, split=True):
    """The centre's (x, y) at 601 samples over 30 ms, levitated: through the drivers' segments
    (split at the change), or in one integrator call across it."""
    model = build_model(scene)
    if split:
        r = simulate(scene, t_end=0.03)
        return r.Y[:, [model.index("x"), model.index("y")]]
    t = np.linspace(0.0, 0.03, 601)
    Y = np.empty((t.size, model.n_state))
    y = levitated_state(model)
    Y[0] = y
    Integrator(model).advance(y, 0.0, 0.03, model.controls(True), t, Y, 1)
    return Y[:, [model.index("x"), model.index("y")]]


def test_the_integration_is_split_at_the_change_which_is_as_accurate_as_a_tight_tolerance():
    """The drivers stop at t_s; at the default tolerance the orbit after the tenfold change
    stays within 0.2 % of a run at rtol 1e-10, no farther than a run stepping across t_s."""
    over = {**ON, "unbalance_change.time": 0.0123, "solver.output_rate": 20000.0}
    scene = load_scene("paper", over)
    assert (0.0, 0.0123, True) in segments(build_model(scene), 0.1)
    ref = _xy(load_scene("paper", {**over, "solver.rtol": 1e-10}))
    err = np.max(np.abs(_xy(scene) - ref))
    assert err < 2e-3 * np.max(np.abs(ref))
    assert err <= np.max(np.abs(_xy(scene, split=False) - ref))


def test_the_energy_audit_closes_across_the_change_and_the_drop_that_follows():
    """A tenfold unbalance at 50 ms while levitated, then the fault at 100 ms and the drop."""
    r = simulate(load_scene("paper", {"effects.unbalance_change": True,
                                      "unbalance_change.time": 0.05,
                                      "unbalance_change.mass": 0.01}), t_end=0.3)
    res, e = energy_residual(r)
    assert e["dissipated"][-1] > 1.0
    assert res.max() < 1e-5 * e["dissipated"][-1]


def test_off_by_default_no_state_and_nothing_changes():
    assert load_scene("paper").effects.unbalance_change is False
    on = build_model(load_scene("paper", ON))
    off = build_model(load_scene("paper", {"amb.off_time": 10.0}))
    assert on.names == off.names
    a = simulate(load_scene("paper"), t_end=0.05)
    b = simulate(load_scene("paper", {"unbalance_change.mass": 0.5}), t_end=0.05)   # off: unused
    assert np.array_equal(a.Y, b.Y)


def test_a_change_to_the_same_unbalance_changes_nothing():
    u = load_scene("paper").unbalance
    same = {**ON, "unbalance_change.mass": u.mass, "unbalance_change.radius": u.radius,
            "unbalance_change.angle_deg": u.angle_deg, "unbalance_change.time": 0.01}
    assert build_model(load_scene("paper", same)).param("unbalance_change.me") < 1e-18


@pytest.mark.parametrize("overrides, match", [
    ({"unbalance_change.mass": -1.0}, r"unbalance_change\.mass = -1.0 is out of range"),
    ({"unbalance_change.time": -0.1}, r"unbalance_change\.time"),
    ({"effects.unbalance_change": True, "effects.unbalance": False},
     r"effects\.unbalance_change = true needs effects\.unbalance = true"),
    ({"effects.unbalance_change": True, "unbalance.mass": 0.0}, r"unbalance\.mass x unbalance\.radius"),
])
def test_bad_input_is_refused_by_name(overrides, match):
    with pytest.raises(SceneError, match=match):
        load_scene("paper", overrides)


def test_on_a_flexible_rotor_the_audit_closes_across_the_change():
    """The difference acts at the unbalance station, whose elastic motion its power includes."""
    r = simulate(load_scene("paper-flexible", {"effects.unbalance_change": True,
                                               "unbalance_change.time": 0.03,
                                               "unbalance_change.mass": 0.05}), t_end=0.15)
    assert r.model.elastic_modes > 0
    res, e = energy_residual(r)
    assert res.max() < 1e-6 * e["dissipated"][-1]
