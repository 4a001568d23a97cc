"""The contact laws against their kinematic definitions, read from the recorded motion alone.

The energy audit integrates the forces the kernel applies, so a force that is wrong but books its
own power closes it; these checks instead rebuild the law's argument from the output samples
(finite differences of the recorded positions, the recorded speeds) and compare the recorded
force with the law of the spec (docs/physics.md, eqs. 14-19). A short, finely sampled drop: an
error shows here as a wrong number long before it could make the run blow up.
"""
import math

import numpy as np
import pytest

from physics import load_scene, simulate
from physics.contact import smooth_sign

T_END = 0.16          # s: the fault at 0.1 s, the first impacts and the sleeve spin-up
RATE = 100e3          # Hz: finite differences of the positions to well within the slip
# a sleeve 10 x lighter than the preset's spins up to rolling within the run: the friction law is
# then seen on both sides of rolling, sliding and at the rolling speed
LIGHT_SLEEVE = {"sleeve.spin_inertia": 1.5e-4}


@pytest.fixture(scope="module")
def drop():
    return simulate(load_scene("paper", {"solver.output_rate": RATE, **LIGHT_SLEEVE}), t_end=T_END)


def kinematic_slip(r, plane: str) -> np.ndarray:
    """The contact's slip speed r Omega + v_t - R omega_s [m/s] from the recorded motion: v_t the
    rate of the rotor's position relative to the sleeve (central differences) along the contact
    tangent t = (-n_y, n_x), n the unit vector from the sleeve centre to the rotor axis."""
    scene = r.model.scene
    e = r.orbit(plane) - r.sleeve(plane)
    n = e / np.hypot(e[:, 0], e[:, 1])[:, None]
    de = np.gradient(e, r.t, axis=0)
    vt = -n[:, 1] * de[:, 0] + n[:, 0] * de[:, 1]
    radius = scene.rotor.journal_radius
    bore = radius + scene.contact.clearance
    return radius * r.rotor_speed + vt - bore * r.sleeve_speed(plane)


def test_the_friction_force_follows_the_kinematic_slip(drop):
    """F_mu = mu F_r sign_s(slip) (eq. 19, kinematic slip) at every contact sample, with the slip
    rebuilt from the recorded positions and speeds: the sign wherever the slip is beyond the
    regularisation (and the finite-difference error), the magnitude mu F_r there."""
    r, scene = drop, drop.model.scene
    v_l = scene.contact.threshold_rpm * math.pi / 30.0 * scene.rotor.journal_radius
    for p in ("RB1", "RB2"):
        f_r, f_mu = r.contact_force(p), r.friction_force(p)
        slip = kinematic_slip(r, p)
        on = (f_r > 10.0) & (r.t > r.t_fault)
        on[[0, -1]] = False                                  # central differences only
        clear = on & (np.abs(slip) > 5.0 * v_l)
        rolling = on & (np.abs(slip) < v_l)
        assert clear.sum() > 500 and rolling.sum() > 500     # sliding, then rolling
        expect = scene.contact.friction * f_r * np.array([smooth_sign(s, v_l) for s in slip])
        np.testing.assert_allclose(f_mu[clear], expect[clear], rtol=1e-3, atol=1.0)
        assert np.all(np.abs(f_mu[on]) <= scene.contact.friction * f_r[on] * (1 + 1e-9))


def test_the_sleeve_follows_its_friction_torque(drop):
    """J_s d omega_s / dt = R F_mu - drag (the sleeve's spin equation) with the recorded force and
    the recorded speed: the sleeve speeds up where the friction pushes it, with the torque's
    rate, to the drag (a few percent of the friction torque while it slides)."""
    r, scene = drop, drop.model.scene
    bore = scene.rotor.journal_radius + scene.contact.clearance
    for p in ("RB1", "RB2"):
        dws = np.gradient(r.sleeve_speed(p), r.t)
        torque = bore * r.friction_force(p)
        sliding = (np.abs(torque) > 20.0) & (r.t > r.t_fault)
        sliding[[0, -1]] = False
        assert sliding.sum() > 50
        ratio = scene.sleeve.spin_inertia * dws[sliding] / torque[sliding]
        assert np.median(ratio) == pytest.approx(1.0, abs=0.1)
        assert np.mean(np.sign(dws[sliding]) == np.sign(torque[sliding])) > 0.95


def test_the_support_takes_the_dashpot_and_spring_force(drop):
    """The housing's equation m_h h'' = -K_s h - C_s h' - F_b + m_h g with every term read from the
    record: h'' and h' by finite differences of the recorded housing position, F_b the retainer
    bearing's force on the housing from the sleeve's equation (m_s s'' = F_contact + F_b_on_sleeve,
    the bearing's force on the housing is its reaction). Per axis, x and y: the dashpot term
    C_s h' is the one that balances it."""
    r, scene = drop, drop.model.scene
    if scene.effects.sleeve_inertia is False:
        pytest.skip("needs the sleeve's own dynamics")
    m_h, m_s = scene.support.housing_mass, scene.sleeve.mass
    k, c = scene.support.stiffness, scene.support.damping
    g = np.array([0.0, -scene.world.gravity]) if scene.effects.gravity else np.zeros(2)
    for p in ("RB1", "RB2"):
        h, s = r.housing(p), r.sleeve(p)
        vh = np.gradient(h, r.t, axis=0)
        ah = np.gradient(vh, r.t, axis=0)
        # total force on housing + sleeve: the support's and the contact's (and gravity)
        e = r.orbit(p) - s
        n = e / np.hypot(e[:, 0], e[:, 1])[:, None]
        t = np.stack([-n[:, 1], n[:, 0]], axis=1)
        f_contact = r.contact_force(p)[:, None] * n + r.friction_force(p)[:, None] * t
        vs = np.gradient(s, r.t, axis=0)
        as_ = np.gradient(vs, r.t, axis=0)
        support = m_h * ah + m_s * as_ - f_contact - (m_h + m_s) * g
        sel = slice(int(np.searchsorted(r.t, r.t_fault)) + 2, -2)
        for axis in (0, 1):
            # the spring and dashpot coefficients that explain the support force, per axis
            A = -np.stack([h[sel, axis], vh[sel, axis]], axis=1)
            (k_fit, c_fit), *_ = np.linalg.lstsq(A, support[sel, axis], rcond=None)
            assert k_fit == pytest.approx(k, rel=0.02), axis
            assert c_fit == pytest.approx(c, rel=0.1), axis
