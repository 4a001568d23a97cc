"""Gyroscopics exercised: the conical and cylindrical natural frequencies of the rigid rotor on
its AMB springs versus spin, forward and backward, against the linearised rigid rotor (spec §1),
on the asymmetric preset, whose offset centre of mass couples tilt and translation."""
import numpy as np
import pytest

from physics import load_scene, simulate

from helpers import free_flight

# the AMBs as undamped linear springs, nothing else acting: no gravity, unbalance or friction
SPRINGS = {"effects.gravity": False, "effects.unbalance": False, "effects.friction": "none",
           "amb.damping": 0.0, "solver.rtol": 1e-9, "solver.output_rate": 2000.0}
T_END = 4.0


def linearised_frequencies(scene, omega: float) -> np.ndarray:
    """Whirl frequencies [rad/s] of a rigid rotor on isotropic springs k at z_1, z_2 (the AMBs),
    signed: > 0 forward (with the spin), < 0 backward. With Z = x + iy, psi = a + ib and
    e^{i w t}: (k11 - m w^2) (k22 - I_d w^2 + I_p Omega w) - k12^2 = 0, k11 = sum k,
    k12 = sum k z, k22 = sum k z^2 (from m Z'' + k11 Z + k12 psi = 0 and
    I_d psi'' - i I_p Omega psi' + k12 Z + k22 psi = 0)."""
    r, k = scene.rotor, scene.amb.stiffness
    z = np.array([scene.positions.amb1, scene.positions.amb2])
    k11, k12, k22 = 2 * k, k * z.sum(), k * (z ** 2).sum()
    m, Id, Ip = r.mass, r.diametral_inertia, r.polar_inertia
    quartic = np.polymul([-m, 0.0, k11], [-Id, Ip * omega, k22]) - np.array([0, 0, 0, 0, k12 ** 2])
    roots = np.roots(quartic)
    assert np.abs(roots.imag).max() < 1e-6 * np.abs(roots).max()     # undamped: real
    return np.sort(roots.real)


def identified_frequencies(t, a, b, n: int = 4) -> np.ndarray:
    """The n strongest whirl frequencies [rad/s] in the tilt signal psi = a + ib (Hann window,
    8x zero padding, parabolic peak interpolation): > 0 forward, < 0 backward."""
    psi = (a + 1j * b) * np.hanning(len(t))
    nfft = 8 * len(t)
    spec = np.abs(np.fft.fftshift(np.fft.fft(psi, nfft)))
    w = np.fft.fftshift(np.fft.fftfreq(nfft, t[1] - t[0])) * 2 * np.pi
    peaks = [i for i in range(1, nfft - 1) if spec[i - 1] < spec[i] >= spec[i + 1]]
    peaks = sorted(peaks, key=lambda i: -spec[i])[:n]
    dw = w[1] - w[0]
    out = []
    for i in peaks:
        l, c, r = np.log(spec[i - 1:i + 2])
        out.append(w[i] + 0.5 * dw * (l - r) / (l - 2 * c + r))
    return np.sort(out)


def free_response(scene, omega: float):
    """Tilt response of the spinning rotor held by the AMB springs after a kick in tilt rate and
    lateral velocity (small enough never to touch the retainers)."""
    t, Y, m = free_flight(scene, {"Omega": omega, "va": 0.05, "vb": 0.02, "vx": 0.004},
                          T_END, int(T_END * 2000) + 1, amb_power=True)
    return t, Y[:, m.index("a")], Y[:, m.index("b")], Y, m


@pytest.mark.parametrize("rpm", [0.0, 10000.0, 30000.0])
def test_whirl_frequencies_versus_spin_match_the_linearised_rigid_rotor(rpm):
    scene = load_scene("asymmetric", SPRINGS)
    omega = rpm * np.pi / 30
    t, a, b, Y, m = free_response(scene, omega)
    # it never touched a retainer: the AMB springs are the only support
    for z in (scene.positions.rb1, scene.positions.rb2):
        reach = np.hypot(Y[:, m.index("x")] + z * a, Y[:, m.index("y")] + z * b)
        assert reach.max() < 0.5 * scene.contact.clearance
    expected = linearised_frequencies(scene, omega)
    found = identified_frequencies(t, a, b)
    np.testing.assert_allclose(found, expected, rtol=1e-4)
    assert (expected > 0).sum() == 2 and (expected < 0).sum() == 2     # 2 forward, 2 backward


def test_spin_splits_the_conical_mode_into_a_rising_forward_and_a_falling_backward_whirl():
    """At 30 000 rpm the conical pair has split by far more than the identification error, in
    the direction the sign of the gyroscopic terms decides: without them (or with their sign
    flipped) the simulated frequencies would be the Omega = 0 ones (or mirrored)."""
    scene = load_scene("asymmetric", SPRINGS)
    still = linearised_frequencies(scene, 0.0)
    spun = linearised_frequencies(scene, 30000.0 * np.pi / 30)
    assert spun.max() > 1.5 * still.max() and -spun.min() < 0.8 * -still.min()
    t, a, b, _, _ = free_response(scene, 30000.0 * np.pi / 30)
    found = identified_frequencies(t, a, b)
    assert found.max() == pytest.approx(spun.max(), rel=1e-4)           # forward conical
    no_gyro = load_scene("asymmetric", {**SPRINGS, "effects.gyroscopic": False})
    t, a, b, _, _ = free_response(no_gyro, 30000.0 * np.pi / 30)
    np.testing.assert_allclose(identified_frequencies(t, a, b), still, rtol=1e-4)


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
