"""Modal reduction: static correction, retained frequencies, rigid limit, Campbell diagram."""
import math
from dataclasses import replace

import numpy as np
import pytest

from physics.flexible import assembly as asm
from physics.flexible import modal

K_AMB = 1e7  # N/m, linear supports at the AMB planes
RUN = 10_000 * 2 * math.pi / 60


def stepped(E_scale=1.0):
    """A stepped hollow shaft with two disks in the rigid rotor's frame (AMBs at +-0.28 m,
    retainer planes at +-0.38 m, unbalance at 0)."""
    mat = replace(asm.STEEL, E=asm.STEEL.E * E_scale, G_s=asm.STEEL.G_s * E_scale)
    return asm.FlexibleRotor(
        (asm.ShaftSection(0.2, 0.06, 0.0, mat), asm.ShaftSection(0.8, 0.12, 0.03, mat),
         asm.ShaftSection(0.2, 0.06, 0.0, mat)),
        (asm.Disk(-0.1, 20.0, 0.15, 0.28), asm.Disk(0.15, 10.0, 0.06, 0.1)), z_start=-0.6,
        amb_planes=(-0.28, 0.28), retainer_planes=(-0.38, 0.38), unbalance_planes=(0.0,),
        max_element_length=0.05)


def amb_supports(model, k=K_AMB):
    return asm.support_matrix(model, [(model.planes[p], k, k) for p in ("amb1", "amb2")])


@pytest.fixture(scope="module")
def model():
    return asm.assemble(stepped())


@pytest.mark.parametrize("omega_cut", [0.0, 6000.0, 20000.0])
@pytest.mark.parametrize("plane, dof", [("rb1", "x"), ("rb2", "y"), ("unb1", "x")])
def test_static_deflection_equals_full_model(model, omega_cut, plane, dof):
    """On the AMB springs, a point load at a force plane: the reduced model's deflection
    (everywhere, mapped back by T) equals the full FE solution to 1e-8, whatever the number of
    bending modes kept: the static correction modes span it."""
    red = modal.reduce(model, omega_cut=omega_cut)
    S = amb_supports(model)
    f = np.zeros(model.ndof)
    f[model.dof(model.planes[plane], dof)] = 1000.0
    q = np.linalg.solve(model.K + S, f)
    T = red.T
    q_r = T @ np.linalg.solve(red.K + T.T @ S @ T, T.T @ f)
    assert np.linalg.norm(q_r - q) / np.linalg.norm(q) < 1e-8


def test_retained_frequencies_equal_full_model(model):
    """Free-free, not spinning: the bending modes below the cut-off are exact in the reduced
    model (Rayleigh-Ritz with the exact modes in the basis); its rigid modes are at 0."""
    w_full = modal.free_free_frequencies(model)
    cut = 9000.0
    red = modal.reduce(model, omega_cut=cut)
    kept = w_full[4:][w_full[4:] < cut]
    assert red.n_bending == len(kept) == 6
    assert red.omega[4:4 + len(kept)] == pytest.approx(kept, rel=1e-9)
    assert np.all(red.omega[:4] < 1e-6 * kept[0])
    assert red.size == 4 + 6 + 10  # rigid + bending + x, y at 5 planes
    assert np.allclose(red.M, np.eye(red.size), atol=1e-10)


def test_reduction_converges_on_supports_at_speed(model):
    """On the AMB springs at 10 000 rpm, the first 3 forward and backward whirl frequencies of
    the reduced model approach the full model's as the cut-off rises."""
    S = amb_supports(model)
    x, y = modal.model_whirl_dofs(model)
    full = modal.campbell(model.M, model.G, model.K + S, [RUN], 3, x, y)
    errs = []
    for cut in (0.0, 6000.0, 20000.0):
        red = modal.reduce(model, omega_cut=cut)
        r = modal.campbell(red.M, red.G, red.K + red.T.T @ S @ red.T, [RUN], 3, x, y, T=red.T)
        errs.append(max(np.max(np.abs(r[k] / full[k] - 1)) for k in ("forward", "backward")))
    assert errs[0] > errs[1] > errs[2]
    assert errs[1] < 1e-3 and errs[2] < 1e-4


def test_rigid_limit_mass_properties_and_frequencies():
    """E x 1000: the reduced model carries exactly the shaft + disks' m, I_d, I_p (about the
    centre of mass), and its lowest whirl frequencies on the AMB springs at 10 000 rpm are the
    rigid rotor's: translation sqrt(sum k / m) and the conical pair from
    I_d w^2 -+ I_p Omega w - sum k (z_i - z_cg)^2 = 0 (coupled rigid 4-DOF model)."""
    rotor = stepped(E_scale=1000.0)
    model = asm.assemble(rotor)
    red = modal.reduce(model, n_bending=2)
    p = asm.rigid_properties(rotor)
    eta = red.T.T @ model.M @ model.rigid_body_modes()   # rigid motions in reduced coordinates
    mR, gR = eta.T @ red.M @ eta, eta.T @ red.G @ eta
    m = mR[0, 0]
    zc = mR[0, 1] / m
    assert m == pytest.approx(p["mass"], rel=1e-10)
    assert mR[1, 1] - m * zc ** 2 == pytest.approx(p["I_d"], rel=1e-10)
    assert gR[1, 3] == pytest.approx(p["I_p"], rel=1e-10)
    # rigid rotor on the springs, coordinates (x, y, a, b) of the centre of mass
    zs = np.array([-0.28, 0.28]) - p["z_cg"]
    k = K_AMB
    Kr = np.zeros((4, 4))
    for c, t in ((0, 2), (1, 3)):
        Kr[c, c] = 2 * k
        Kr[c, t] = Kr[t, c] = k * zs.sum()
        Kr[t, t] = k * (zs ** 2).sum()
    Mr = np.diag([p["mass"], p["mass"], p["I_d"], p["I_d"]])
    Gr = np.zeros((4, 4))
    Gr[2, 3], Gr[3, 2] = p["I_p"], -p["I_p"]
    rig = modal.campbell(Mr, Gr, Kr, [RUN], 2, np.array([0, 2]), np.array([1, 3]))
    S = amb_supports(model)
    x, y = modal.model_whirl_dofs(model)
    flex = modal.campbell(red.M, red.G, red.K + red.T.T @ S @ red.T, [RUN], 2, x, y, T=red.T)
    for key in ("forward", "backward"):
        assert flex[key][0] == pytest.approx(rig[key][0], rel=1e-4)


def test_campbell_forward_rises_backward_falls(model):
    S = amb_supports(model)
    red = modal.reduce(model, omega_cut=12000.0)
    x, y = modal.model_whirl_dofs(model)
    c = modal.campbell(red.M, red.G, red.K + red.T.T @ S @ red.T, np.linspace(0, 2 * RUN, 5), 4,
                       x, y, T=red.T)
    assert np.all(np.diff(c["forward"], axis=0) > 0)
    assert np.all(np.diff(c["backward"], axis=0) < 0)
    assert c["forward"][0] == pytest.approx(c["backward"][0], rel=1e-9)  # standing at rest


def test_reduce_refuses_bad_requests(model):
    with pytest.raises(ValueError, match=r"n_bending = 1000: allowed \[0, 104\]"):
        modal.reduce(model, n_bending=1000)
    with pytest.raises(ValueError, match="exactly one of omega_cut"):
        modal.reduce(model)
    with pytest.raises(ValueError, match=r"omega_cut = -1.0: allowed"):
        modal.reduce(model, omega_cut=-1.0)
    with pytest.raises(ValueError, match="linearly dependent"):
        modal.reduce(model, n_bending=100)
