"""The flexible rotor as the drop model sees it: a rigid body plus elastic modes (floating frame).

The rotor's lateral motion in one bending plane is ``q_x = x r_1 + a r_2 + E eta_x`` (the same in
the y plane with y, b, eta_y), where

* ``r_1`` is the rigid translation and ``r_2`` the rigid tilt about the centre of mass, so that
  x, y, a, b are exactly the rigid rotor's coordinates (physics/rotor.py) and the rigid model is
  the flexible one with no elastic modes;
* ``E`` holds the elastic modes: the free-free bending modes below a cut-off frequency and the
  static correction (inertia-relief attachment) modes of x at the force stations (retainer
  planes, AMB planes, unbalance plane; MacNeal 1971, Craig 1981), M-orthogonal to the rigid
  modes, then M-orthonormalised and diagonalised (Rayleigh-Ritz), so ``E^T M E = I`` and
  ``E^T K E = diag(omega^2)``.

M-orthogonality to ``r_1``, ``r_2`` decouples the rigid and elastic inertia, makes gravity (a
uniform body force) do no work on the elastic modes, and leaves only the gyroscopic matrix to
couple them: with ``B = [r_1, r_2, E]`` and ``G_p`` the x-plane-to-y-plane block of the FE
gyroscopic matrix (``G[x-plane, y-plane] = +G_p``, ``G[y-plane, x-plane] = -G_p``, symmetric),
``B^T G_p B`` gives the polar inertia ``I_p`` (tilt-tilt), the coupling vector ``g`` (tilt to
the elastic modes) and the elastic block ``G_e``. The equations the kernel integrates
(physics/flexible_rotor.py):

    I_d a'' + Omega (I_p b' + g . eta_y') = M_a          I_d b'' - Omega (I_p a' + g . eta_x') = M_b
    eta_x'' + 2 zeta omega eta_x' + omega^2 eta_x + Omega (g b' + G_e eta_y') = S^T f_x
    eta_y'' + 2 zeta omega eta_y' + omega^2 eta_y - Omega (g a' + G_e eta_x') = S^T f_y

with ``S[s, j]`` the x translation of elastic mode j at force station s and ``f`` the station
forces. Structural damping is the modal ratio ``zeta`` (assumed).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import timoshenko as tim
from .assembly import FEModel, assemble
from .modal import generalized_eigh

#: the force stations, in the order of the drop model's axial-station block (physics/rotor.py)
STATIONS = ("rb1", "rb2", "amb1", "amb2", "unb1")
#: the most elastic modes per bending plane the drop kernel's packed arrays hold
MAX_MODES = 24


@dataclass(frozen=True)
class FloatingModel:
    """A flexible rotor reduced for the drop model (module docstring); z in the centre-of-mass
    frame of the FE model's rotor (its ``z_cg`` is 0 by construction of the caller)."""
    fe: FEModel
    mass: float
    I_d: float
    I_p: float
    z_cg: float
    omega: np.ndarray            # (n,) rad/s, elastic modes ascending
    shape: np.ndarray            # (stations, n) x translation of each elastic mode at each station
    g: np.ndarray                # (n,) gyroscopic coupling of the rigid tilt to the elastic modes
    G: np.ndarray                # (n, n) elastic gyroscopic block (symmetric)
    basis: np.ndarray            # (2 nodes, 2 + n) planar basis [r_1, r_2, E] over (x, a) per node
    n_bending: int
    n_correction: int

    @property
    def n_modes(self) -> int:
        return len(self.omega)


def planar_dofs(fe: FEModel) -> tuple[np.ndarray, np.ndarray]:
    """The x-plane DOFs (x, a per node) and the y-plane DOFs (y, b per node), node by node."""
    n = np.arange(fe.n_nodes) * tim.DOF_PER_NODE
    xp = np.ravel(np.column_stack([n + tim.X, n + tim.A]))
    yp = np.ravel(np.column_stack([n + tim.Y, n + tim.B]))
    return xp, yp


def reduce_floating(fe: FEModel, omega_cut: float, static_modes: bool = True,
                    max_modes: int | None = None) -> FloatingModel:
    """Reduce ``fe`` (whose stations are named rb1, rb2, amb1, amb2, unb1) to the floating-frame
    model: rigid modes about the centre of mass, free-free bending modes below ``omega_cut``
    (rad/s), and (``static_modes``) one inertia-relief attachment mode per distinct force node.
    ValueError when more modes are asked for than the shaft has DOFs, or than ``max_modes``."""
    xp, yp = planar_dofs(fe)
    M, K = fe.M[np.ix_(xp, xp)], fe.K[np.ix_(xp, xp)]
    Gp = fe.G[np.ix_(xp, yp)]
    z = fe.z
    r1 = np.zeros(len(xp))
    r1[0::2] = 1.0
    mass = float(r1 @ M @ r1)
    z_cg = float((r1 @ M @ _tilt(z, 0.0)) / mass)
    r2 = _tilt(z, z_cg)
    R = np.column_stack([r1, r2])
    wb, Vb = free_free_bending(fe)
    Phi = Vb[:, wb < omega_cut]
    cols = [Phi]
    nodes = sorted({fe.planes[s] for s in STATIONS if s in fe.planes})
    if static_modes:
        MR = M @ R
        mR = R.T @ MR
        F = np.zeros((len(xp), len(nodes)))
        F[[2 * n for n in nodes], range(len(nodes))] = 1.0
        F -= MR @ np.linalg.solve(mR, R.T @ F)                  # self-equilibrated loads
        Psi = np.linalg.solve(K + MR @ np.linalg.solve(mR, MR.T), F)
        Psi -= R @ np.linalg.solve(mR, MR.T @ Psi)
        Psi -= Phi @ (Phi.T @ (M @ Psi))
        cols.append(Psi)
    E0 = np.hstack(cols)
    n = E0.shape[1]
    if n > len(xp) - 2:
        raise ValueError(f"{n} elastic modes asked for, but the shaft has only {len(xp) - 2} "
                         f"elastic DOFs per plane: lower the mode cut-off or refine the mesh")
    if max_modes is not None and n > max_modes:
        raise ValueError(f"{n} elastic modes ({Phi.shape[1]} bending below the cut-off + "
                         f"{n - Phi.shape[1]} static correction): allowed at most {max_modes}; "
                         f"lower the mode cut-off")
    E = _diagonalised(E0, M, K) if n else E0
    B = np.column_stack([R, E])
    Gr = B.T @ Gp @ B
    omega = np.sqrt(np.clip(np.einsum("ij,ij->j", E, K @ E), 0.0, None))
    shape = np.array([E[2 * fe.planes[s]] if s in fe.planes else np.zeros(n) for s in STATIONS])
    return FloatingModel(fe, mass, float(r2 @ M @ r2), float(Gr[1, 1]), z_cg, omega, shape,
                         Gr[1, 2:].copy(), (Gr[2:, 2:] + Gr[2:, 2:].T) / 2, B,
                         int(Phi.shape[1]), n - int(Phi.shape[1]))


def free_free_bending(fe: FEModel) -> tuple[np.ndarray, np.ndarray]:
    """The free-free bending modes of one bending plane: frequencies (rad/s, ascending) and
    shapes over (x, a) per node, M-normalised (the two rigid-body modes left out)."""
    xp, _ = planar_dofs(fe)
    lam, V = generalized_eigh(fe.K[np.ix_(xp, xp)], fe.M[np.ix_(xp, xp)])
    return np.sqrt(np.clip(lam[2:], 0.0, None)), V[:, 2:]


def _tilt(z: np.ndarray, z0: float) -> np.ndarray:
    """The rigid tilt about station z0 over (x, a) per node: x = z - z0, a = 1."""
    r = np.empty(2 * len(z))
    r[0::2] = z - z0
    r[1::2] = 1.0
    return r


def _diagonalised(E0: np.ndarray, M: np.ndarray, K: np.ndarray) -> np.ndarray:
    """The basis of span(E0) with ``E^T M E = I`` and ``E^T K E`` diagonal, ascending."""
    E0 = E0 / np.sqrt(np.einsum("ij,ij->j", E0, M @ E0))
    Mr = E0.T @ M @ E0
    s, U = np.linalg.eigh((Mr + Mr.T) / 2)
    if s.min() <= 1e-12 * s.max():
        raise ValueError("the static correction modes are linearly dependent on the retained "
                         "bending modes (two force planes at one node, or more modes than DOFs)")
    W = U / np.sqrt(s)
    Kr = W.T @ (E0.T @ K @ E0) @ W
    _, Z = np.linalg.eigh((Kr + Kr.T) / 2)
    return E0 @ (W @ Z)


def floating_model(rotor, omega_cut: float, static_modes: bool = True,
                   max_modes: int | None = None) -> FloatingModel:
    """Assemble and reduce a :class:`~physics.flexible.assembly.FlexibleRotor`."""
    return reduce_floating(assemble(rotor), omega_cut, static_modes, max_modes)
