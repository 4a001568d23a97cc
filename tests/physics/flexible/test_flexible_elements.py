"""Timoshenko shaft elements and assembly against closed-form beam results."""
import math

import numpy as np
import pytest

from physics.flexible import assembly as asm
from physics.flexible import modal
from physics.flexible import timoshenko as tim

STEEL = asm.Material.from_poisson("steel", 2.0e11, 0.3, 7800.0)
# free-free Euler-Bernoulli beam: cos(bL) cosh(bL) = 1 (e.g. Blevins, Formulas for Natural
# Frequency and Mode Shape, 1979, table 8-1)
BETA_L = (4.730040745, 7.853204624, 10.99560784, 14.13716549)


def uniform(L, D, d=0.0, n=40, shear="hutchinson"):
    return asm.FlexibleRotor((asm.ShaftSection(L, D, d, STEEL),), max_element_length=L / n,
                             shear=shear)


def bending(model, n):
    """First n bending frequencies (rad/s) of a free-free model (one per x/y pair)."""
    return modal.free_free_frequencies(model)[4::2][:n]


@pytest.mark.parametrize("d_over_D", [0.0, 0.6])
def test_slender_free_free_shaft_matches_euler_bernoulli(d_over_D):
    """L/D = 100: the Timoshenko element (shear + rotary inertia) within 0.5 % of
    omega_n = (beta_n L)^2 sqrt(E I / (rho A L^4)) for the first 4 bending modes."""
    L, D = 2.0, 0.02
    model = asm.assemble(uniform(L, D, d_over_D * D))
    A, I = tim.section(D, d_over_D * D)
    w_eb = np.array(BETA_L) ** 2 * math.sqrt(STEEL.E * I / (STEEL.rho * A * L ** 4))
    err = bending(model, 4) / w_eb - 1
    assert np.all(np.abs(err) < 0.005), err
    # the shear and rotary inertia only lower the frequencies
    assert np.all(err < 0)


def test_euler_bernoulli_element_converges_from_above():
    """Without shear and rotary inertia the consistent-mass element is a Rayleigh-Ritz model:
    frequencies above the analytic ones and within 1e-4 with 40 elements."""
    L, D = 2.0, 0.02
    A, I = tim.section(D, 0.0)
    w_eb = np.array(BETA_L) ** 2 * math.sqrt(STEEL.E * I / (STEEL.rho * A * L ** 4))
    nd = 4 * 41
    M, K = np.zeros((nd, nd)), np.zeros((nd, nd))
    for e in range(40):
        Me, Ke, _ = tim.element_matrices(L / 40, D, 0.0, STEEL.E, STEEL.G_s, STEEL.rho,
                                         shear=None, rotary_inertia=False)
        M[4 * e:4 * e + 8, 4 * e:4 * e + 8] += Me
        K[4 * e:4 * e + 8, 4 * e:4 * e + 8] += Ke
    lam, _ = modal.generalized_eigh(K, M)
    err = np.sqrt(np.clip(lam, 0, None))[4::2][:4] / w_eb - 1
    assert np.all(err > 0) and np.all(err < 1e-4), err


def timoshenko_simply_supported(n, L, D, d, mat, kappa):
    """Exact n-th frequency of a simply supported Timoshenko beam (Timoshenko, Phil. Mag. 41,
    1921, 744; Han, Benaroya & Wei, J. Sound Vib. 225, 1999, 935-988, hinged-hinged case): with
    k = n pi / L, the lower root of
    (rho^2 I / (kappa G)) w^4 - (rho A + rho I k^2 (1 + E / (kappa G))) w^2 + E I k^4 = 0."""
    A, I = tim.section(D, d)
    k = n * math.pi / L
    a = mat.rho ** 2 * I / (kappa * mat.G_s)
    b = mat.rho * A + mat.rho * I * k ** 2 * (1 + mat.E / (kappa * mat.G_s))
    c = mat.E * I * k ** 4
    return math.sqrt((b - math.sqrt(b * b - 4 * a * c)) / (2 * a))


@pytest.mark.parametrize("shear", ["hutchinson", "cowper"])
def test_thick_simply_supported_shaft_matches_timoshenko_closed_form(shear):
    """L/D = 4, hollow: shear and rotary inertia lower the 3rd mode by ~40 % from Euler-
    Bernoulli; the FE model (40 elements, ends pinned in x and y) is within 0.5 % of the exact
    Timoshenko frequencies for the first 3 modes."""
    L, D, d = 0.8, 0.2, 0.1
    model = asm.assemble(uniform(L, D, d, shear=shear))
    pinned = [model.dof(i, w) for i in (0, model.n_nodes - 1) for w in "xy"]
    free = np.setdiff1d(np.arange(model.ndof), pinned)
    lam, _ = modal.generalized_eigh(model.K[np.ix_(free, free)], model.M[np.ix_(free, free)])
    w_fe = np.sqrt(lam)[0::2][:3]
    kappa = tim.shear_coefficient(D, d, STEEL.nu, shear)
    w_ex = np.array([timoshenko_simply_supported(n, L, D, d, STEEL, kappa) for n in (1, 2, 3)])
    assert np.all(np.abs(w_fe / w_ex - 1) < 0.005), w_fe / w_ex - 1
    A, I = tim.section(D, d)
    w_eb = (3 * math.pi / L) ** 2 * math.sqrt(STEEL.E * I / (STEEL.rho * A))
    assert w_ex[2] / w_eb < 0.8


def test_shear_coefficients_published_values():
    """Solid circle at nu = 0.3: Hutchinson 6(1+nu)^2/(7+12nu+4nu^2) = 0.9252, Cowper
    6(1+nu)/(7+6nu) = 0.8864; thin-walled tube (d -> D): Cowper 2(1+nu)/(4+3nu) = 0.5306."""
    assert tim.shear_coefficient(1.0, 0.0, 0.3) == pytest.approx(0.92518, abs=1e-5)
    assert tim.shear_coefficient(1.0, 0.0, 0.3, "cowper") == pytest.approx(0.88636, abs=1e-5)
    assert tim.shear_coefficient(1.0, 0.9999, 0.3, "cowper") == pytest.approx(2.6 / 4.9, abs=1e-4)


def test_element_matrices_symmetry_and_rigid_body():
    M, K, G = tim.element_matrices(0.3, 0.1, 0.04, STEEL.E, STEEL.G_s, STEEL.rho)
    assert np.allclose(M, M.T) and np.allclose(K, K.T) and np.allclose(G, -G.T)
    assert np.all(np.linalg.eigvalsh(M) > 0)
    # rigid translation and rotation: no strain energy
    for r in ([1, 0, 0, 0, 1, 0, 0, 0], [0, 0, 1, 0, 0.3, 0, 1, 0]):
        assert np.allclose(K @ np.array(r, float), 0, atol=1e-6 * np.abs(K).max())


def test_rigid_body_mass_properties_exact():
    """R^T M R and R^T G R of shaft + disks give m, z_cg, I_d, I_p of rigid_properties."""
    rotor = asm.FlexibleRotor(
        (asm.ShaftSection(0.3, 0.1, 0.04, STEEL), asm.ShaftSection(0.5, 0.14, 0.0, STEEL)),
        (asm.Disk(0.1, 12.0, 0.08, 0.15), asm.Disk(0.4, 5.0, 0.02, 0.03)), z_start=-0.3,
        max_element_length=0.05)
    model = asm.assemble(rotor)
    R = model.rigid_body_modes()
    mR = R.T @ model.M @ R
    p = asm.rigid_properties(rotor)
    m = mR[0, 0]
    zc = mR[0, 1] / m
    assert m == pytest.approx(p["mass"], rel=1e-12)
    assert zc == pytest.approx(p["z_cg"], rel=1e-12)
    assert mR[1, 1] - m * zc ** 2 == pytest.approx(p["I_d"], rel=1e-12)
    assert (R.T @ model.G @ R)[1, 3] == pytest.approx(p["I_p"], rel=1e-12)


def test_gyroscopic_sign_matches_rigid_rotor():
    """A free spinning disk on a massless point: I_d a'' + I_p Omega b' = 0 nutates forward at
    I_p Omega / I_d (physics/rotor.py)."""
    Md, Gd = tim.disk_matrices(1.0, 0.5, 0.8)
    idx = [2, 3]
    s, V = modal.whirl_eigen(Md[np.ix_(idx, idx)], Gd[np.ix_(idx, idx)],
                             np.zeros((2, 2)), 100.0)
    assert s.imag[-1] == pytest.approx(0.8 * 100 / 0.5)
    assert modal.whirl_direction(V[:, -1], np.array([0]), np.array([1])) > 0.99
