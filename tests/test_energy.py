"""Energy audit (spec §1): E_mech(t) + E_dissipated(t) - W_external(t) = E_mech(0)."""
import numpy as np
import pytest

from physics import load_scene, simulate

from helpers import energy_residual

LOSSLESS = {"effects.friction": "none", "contact.damping": 0.0, "bearing.damping": 0.0,
            "support.damping": 0.0, "effects.unbalance": False, "effects.bearing_friction": False,
            "amb.damping": 0.0, "solver.rtol": 1e-8}


def test_without_friction_and_damping_mechanical_energy_is_conserved():
    scene = load_scene("paper", LOSSLESS)
    r = simulate(scene, t_end=0.4)
    res, e = energy_residual(r)
    assert e["dissipated"][-1] == 0.0
    assert r.contact_force("RB1").max() > 1000.0                 # it did bounce hard
    drop_energy = scene.rotor.mass * scene.world.gravity * scene.contact.clearance
    post = r.t > scene.amb.off_time                              # AMBs off: no external work
    ep = e["mechanical"][post]
    assert np.ptp(ep) < 1e-3 * drop_energy
    assert res.max() < 1e-3 * drop_energy


@pytest.mark.parametrize("overrides", [{}, {"effects.friction": "kinematic"},
                                       {"effects.retainer_bearing": "linear"},
                                       {"effects.housing": False},
                                       {"contact.friction": 0.5}])
def test_energy_lost_equals_integrated_dissipated_power(overrides):
    r = simulate(load_scene("paper", overrides), t_end=0.4)
    res, e = energy_residual(r)
    assert e["dissipated"][-1] > 100.0                           # friction spun the sleeves up
    assert res.max() < 1e-5 * e["dissipated"][-1]


def test_kinematic_slip_friction_only_dissipates_while_paper_slip_can_feed_the_whirl():
    """The paper's slip ignores the whirl velocity, so its friction can do positive work."""
    kin = simulate(load_scene("paper", {"effects.friction": "kinematic", "contact.friction": 0.5}),
                   t_end=0.4).energy()["dissipated"]
    assert np.all(np.diff(kin) >= -1e-6 * kin[-1])          # dense-output interpolation noise
    pap = simulate(load_scene("paper", {"contact.friction": 0.5}), t_end=0.4).energy()["dissipated"]
    assert np.diff(pap).min() < 0.0
