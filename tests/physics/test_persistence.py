"""The end-state classifier (physics/persistence.py) on constructed orbits whose state is known
by construction, and on the bi-stable preset: the same machine ends contact-free without a
shock and in a forward synchronous rub after one (two histories, two end states)."""
import math

import numpy as np
import pytest

from physics import load_scene, simulate
from physics.metrics import WHIRL_MIN_REVOLUTIONS
from physics.persistence import (END_STATES, RUB_CONTACT_FRACTION, UNDECIDED, classify,
                                 end_state)

C = 300e-6                     # clearance [m]
OMEGA = 400.0                  # spin [rad/s]
T = np.linspace(0.0, 0.1, 2001)


def _orbit(radius, whirl_ratio, t=T):
    """A circular orbit of ``radius`` whirling at ``whirl_ratio`` x the spin."""
    a = whirl_ratio * OMEGA * t
    r = np.broadcast_to(radius, t.shape)
    return np.column_stack([r * np.cos(a), r * np.sin(a)])


def _state(radius, whirl_ratio, k=2e8):
    orbit = _orbit(radius, whirl_ratio)
    pen = np.hypot(orbit[:, 0], orbit[:, 1]) - C
    return classify(T, orbit, pen, k * np.maximum(pen, 0.0), np.full(T.shape, OMEGA), C, "RB1")


def test_a_centred_synchronous_orbit_is_contact_free_with_whirl_ratio_one():
    s = _state(0.5 * C, 1.0)
    assert s.label == "contact_free"
    assert s.contact_fraction == 0.0 and s.mean_contact_force == 0.0
    assert s.whirl_ratio == pytest.approx(1.0, rel=1e-3)
    assert s.mean_orbit_radius == pytest.approx(0.5 * C)


def test_an_orbit_beyond_the_clearance_whirling_forward_is_a_forward_rub():
    s = _state(1.1 * C, 1.0)
    assert s.label == "forward_rub" and s.contact_fraction == 1.0
    assert s.mean_contact_force == pytest.approx(2e8 * 0.1 * C)
    # forward revolutions count negative in the whirl rule: 0.1 s x 400 rad/s / 2 pi
    assert s.backward_revolutions == pytest.approx(-0.1 * OMEGA / (2 * math.pi), rel=1e-3)


def test_a_backward_orbit_in_contact_is_a_backward_whirl_by_the_whirl_rule():
    s = _state(1.05 * C, -0.5)
    assert s.label == "backward_whirl"
    assert s.backward_revolutions >= WHIRL_MIN_REVOLUTIONS
    assert s.whirl_ratio == pytest.approx(-0.5, rel=1e-3)


def test_a_rotor_pressed_on_one_side_without_whirling_is_pressed_not_a_rub():
    s = _state(1.02 * C, 0.0)
    assert s.label == "pressed" and s.contact_fraction == 1.0 and abs(s.whirl_ratio) < 1e-12


def test_contact_on_a_minority_of_the_samples_is_intermittent():
    """An orbit whose radius passes the clearance on a share of the window below
    RUB_CONTACT_FRACTION (a bouncing rotor)."""
    radius = C * (0.9 + 0.15 * np.sin(2 * math.pi * 50 * T))        # beyond C 1/3 of the time
    orbit = _orbit(radius, 1.0)
    pen = radius - C
    s = classify(T, orbit, pen, 2e8 * np.maximum(pen, 0), np.full(T.shape, OMEGA), C)
    assert 0.0 < s.contact_fraction < RUB_CONTACT_FRACTION
    assert s.label == "intermittent"


def test_the_labels_are_ordered_worst_first():
    assert END_STATES[0] == "backward_whirl" and END_STATES[-1] == "contact_free"


def test_bad_input_names_what_is_wrong():
    orbit = _orbit(C, 1.0)
    with pytest.raises(ValueError, match="at least"):
        classify(T[:5], orbit[:5], T[:5], T[:5], T[:5], C)
    with pytest.raises(ValueError, match=r"orbit \(N, 2\)"):
        classify(T, orbit[:, :1], T, T, T, C)
    with pytest.raises(ValueError, match="clearance"):
        classify(T, orbit, T, T, T, -1.0)


@pytest.fixture(scope="module")
def histories():
    """The bi-stable preset with and without its 10 g shock (0.4 s each)."""
    scene = load_scene("amb-persistent")
    return {shock: simulate(scene.with_overrides({"effects.base_excitation": shock}))
            for shock in (False, True)}


def test_the_same_machine_ends_contact_free_or_in_a_forward_rub_by_its_history(histories):
    """amb-persistent: without the shock the PID holds the rotor contact-free on its 225 µm
    unbalance orbit; after the shock the same machine rubs synchronously at both sleeves."""
    free, rub = end_state(histories[False]), end_state(histories[True])
    assert free.label == "contact_free" and free.whirl_ratio == pytest.approx(1.0, abs=0.01)
    assert 0.6 * C < free.mean_orbit_radius < 0.9 * C
    assert rub.label == "forward_rub" and rub.contact_fraction == 1.0
    assert rub.whirl_ratio == pytest.approx(1.0, abs=0.01)
    assert rub.mean_contact_force > 1000.0


def test_end_state_refuses_a_window_outside_the_run(histories):
    for window in (0.0, -0.1, 0.5):
        with pytest.raises(ValueError, match="window"):
            end_state(histories[True], window)


def test_a_run_that_left_validity_without_whirling_is_undecided():
    """The paper machine's soft support lets the shock carry the rotor to the AMB air gap: the
    motion after it is not the model's, so the end state is undecided."""
    scene = load_scene("amb-persistent", {"support.stiffness": 5e7})
    assert end_state(simulate(scene)).label == UNDECIDED
