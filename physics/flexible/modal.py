"""Modal reduction of a free-free rotor and its natural frequencies / Campbell diagram.

Basis ``T = [R, Phi_b, Psi]`` (Craig, *Structural Dynamics*, 1981, ch. 15; MacNeal, Computers
& Structures 1, 1971, 581-601 for the inertia-relief attachment modes):

* ``R``: the 4 rigid-body modes (x, tilt a, y, tilt b);
* ``Phi_b``: free-free bending modes with ``omega < omega_cut`` from ``K phi = omega^2 M phi``;
* ``Psi``: static correction (inertia-relief attachment) modes, one per force DOF j (x and y
  at each AMB, retainer and unbalance plane): ``K psi_j = P e_j``, with the inertia-relief
  projector ``P = I - M R (R^T M R)^-1 R^T`` making the load self-equilibrated, ``psi_j``
  M-orthogonal to ``R``.

``T`` is M-orthonormalised and re-diagonalised (``T^T M T = I``, ``T^T K T = diag(omega^2)``),
so the reduced coordinates are modal. Since every static response to loads at the force DOFs
lies in span(R, Psi), the reduced model reproduces the full model's static deflection there
exactly (up to round-off), and the retained modes' frequencies exactly (Rayleigh-Ritz with the
exact modes in the subspace).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .assembly import FEModel


def generalized_eigh(K: np.ndarray, M: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenpairs of ``K v = lambda M v`` (M symmetric positive definite), ascending,
    ``V^T M V = I``; by the Cholesky factor ``M = L L^T``."""
    L = np.linalg.cholesky(M)
    Li = np.linalg.inv(L)
    lam, W = np.linalg.eigh(Li @ K @ Li.T)
    return lam, Li.T @ W


def free_free_frequencies(model: FEModel) -> np.ndarray:
    """Natural frequencies (rad/s) of the free-free, non-spinning full model, ascending
    (each bending frequency twice: x and y planes; the 4 rigid-body modes first, ~0)."""
    lam, _ = generalized_eigh(model.K, model.M)
    return np.sqrt(np.clip(lam, 0.0, None))


def force_dofs(model: FEModel, planes: tuple[str, ...] | None = None,
               extra_nodes: tuple[int, ...] = ()) -> list[int]:
    """x and y DOFs of the named planes (default: every AMB, retainer and unbalance plane) and
    of ``extra_nodes`` (e.g. other support nodes)."""
    names = model.planes if planes is None else planes
    for p in names:
        if p not in model.planes:
            raise ValueError(f"planes: {p!r} is not a plane of the model; allowed "
                             f"{sorted(model.planes)}")
    for n in extra_nodes:
        if not 0 <= n < model.n_nodes:
            raise ValueError(f"extra_nodes: {n!r}: allowed [0, {model.n_nodes - 1}]")
    nodes = sorted({model.planes[p] for p in names} | set(extra_nodes))
    return [model.dof(i, w) for i in nodes for w in "xy"]


@dataclass(frozen=True)
class ReducedModel:
    """``q = T eta``; ``M_r = T^T M T = I``, ``K_r = diag(omega^2)``, ``G_r = T^T G T``."""
    T: np.ndarray
    M: np.ndarray
    K: np.ndarray
    G: np.ndarray
    omega: np.ndarray          # rad/s, of the reduced basis (4 rigid ~0, bending, correction)
    n_rigid: int
    n_bending: int
    n_correction: int

    @property
    def size(self) -> int:
        return self.T.shape[1]


def reduce(model: FEModel, omega_cut: float | None = None, n_bending: int | None = None,
           planes: tuple[str, ...] | None = None, extra_nodes: tuple[int, ...] = ()
           ) -> ReducedModel:
    """Reduced model: rigid modes, free-free bending modes below ``omega_cut`` (rad/s) or the
    first ``n_bending`` of them (counting x and y planes separately), and the static correction
    modes of the x, y DOFs of ``planes`` (default all named planes) and ``extra_nodes``."""
    nd = model.ndof
    M, K = model.M, model.K
    R = model.rigid_body_modes()
    if (omega_cut is None) == (n_bending is None):
        raise ValueError("reduce: give exactly one of omega_cut (rad/s) or n_bending")
    if n_bending is not None and not (0 <= n_bending <= nd - 4):
        raise ValueError(f"n_bending = {n_bending!r}: allowed [0, {nd - 4}] "
                         f"(the model has {nd} DOFs, 4 of them rigid-body)")
    if omega_cut is not None and not (omega_cut >= 0.0 and np.isfinite(omega_cut)):
        raise ValueError(f"omega_cut = {omega_cut!r}: allowed [0, inf) rad/s")
    # elastic modes: eigenvectors M-orthogonal to R (drop the 4 lowest, the rigid ones)
    lam, V = generalized_eigh(K, M)
    Vb = V[:, 4:]
    wb = np.sqrt(np.clip(lam[4:], 0.0, None))
    keep = np.arange(len(wb)) < n_bending if n_bending is not None else wb < omega_cut
    Phi = Vb[:, keep]
    # inertia-relief attachment modes
    dofs = force_dofs(model, planes, extra_nodes)
    MR = M @ R
    mR = R.T @ MR
    E = np.zeros((nd, len(dofs)))
    E[dofs, range(len(dofs))] = 1.0
    F = E - MR @ np.linalg.solve(mR, R.T @ E)               # P e_j, self-equilibrated
    Ks = K + MR @ np.linalg.solve(mR, MR.T)                  # K + M R (R^T M R)^-1 R^T M: regular
    Psi = np.linalg.solve(Ks, F)
    Psi -= R @ np.linalg.solve(mR, MR.T @ Psi)               # M-orthogonal to R
    Psi -= Phi @ (Phi.T @ (M @ Psi))                         # and to the retained modes
    T0 = np.hstack([R, Phi, Psi])
    T0 = T0 / np.sqrt(np.einsum("ij,ij->j", T0, M @ T0))    # unit M-norm columns
    # M-orthonormalise and diagonalise the reduced problem (Rayleigh-Ritz)
    Mr, Kr = T0.T @ M @ T0, T0.T @ K @ T0
    Mr, Kr = (Mr + Mr.T) / 2, (Kr + Kr.T) / 2
    s, U = np.linalg.eigh(Mr)
    if s.min() <= 1e-12 * s.max():
        raise ValueError("reduce: the static correction modes are linearly dependent on the "
                         "retained modes (planes at the same node or more modes than DOFs); "
                         "lower omega_cut/n_bending or remove duplicate planes")
    W = U / np.sqrt(s)
    lam_r, Z = np.linalg.eigh(W.T @ Kr @ W)
    T = T0 @ (W @ Z)
    Mt, Kt, Gt = T.T @ M @ T, T.T @ K @ T, T.T @ model.G @ T
    return ReducedModel(T, (Mt + Mt.T) / 2, (Kt + Kt.T) / 2, (Gt - Gt.T) / 2,
                        np.sqrt(np.clip(lam_r, 0.0, None)), 4, int(Phi.shape[1]), len(dofs))


def whirl_eigen(M: np.ndarray, G: np.ndarray, K: np.ndarray, Omega: float,
                C: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues s and mode shapes (displacement part) of ``M q'' + (C + Omega G) q' + K q = 0``
    from the first-order form, only those with Im s > 0, ascending in Im s."""
    n = M.shape[0]
    D = Omega * G + (C if C is not None else 0.0)
    Mi = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Mi @ K, -Mi @ D]])
    s, V = np.linalg.eig(A)
    pos = s.imag > 1e-6 * max(1.0, np.abs(s).max())  # rigid-body s ~ 0 (Jordan blocks) out
    s, V = s[pos], V[:n, pos]
    order = np.argsort(s.imag)
    return s[order], V[:, order]


def whirl_direction(shape: np.ndarray, x_dofs: np.ndarray, y_dofs: np.ndarray) -> float:
    """Forward-whirl fraction minus backward fraction, in [-1, 1] (+1 purely forward).

    With ``x = Re(X e^{i w t})``, ``y = Re(Y e^{i w t})`` (w > 0), ``x + i y`` has a forward
    (with the spin, x towards y) circle of radius ``|X + iY|/2`` and a backward one ``|X - iY|/2``.
    """
    X, Y = shape[x_dofs], shape[y_dofs]
    f = np.sum(np.abs(X + 1j * Y) ** 2)
    b = np.sum(np.abs(X - 1j * Y) ** 2)
    return float((f - b) / (f + b))


def whirl_directions(s: np.ndarray, V: np.ndarray, x_dofs: np.ndarray, y_dofs: np.ndarray,
                     rtol: float = 1e-7) -> np.ndarray:
    """whirl_direction of each mode, with repeated eigenvalues resolved: a cluster of modes
    with equal frequency (e.g. the cylindrical mode of a symmetric rotor, which spin does not
    split) spans a forward and a backward circular mode, but the eigen-solver returns arbitrary
    mixtures. Within a cluster the directions are the eigenvalues of ``F - B`` relative to
    ``F + B`` (``F = P^H P``, ``P = X + iY`` over the cluster's shapes; ``B`` with ``X - iY``),
    the extreme whirl of the combinations of its shapes."""
    d = np.array([whirl_direction(V[:, j], x_dofs, y_dofs) for j in range(len(s))])
    i = 0
    while i < len(s):
        j = i + 1
        while j < len(s) and abs(s[j] - s[i]) <= rtol * abs(s[i]):
            j += 1
        if j - i > 1:
            Vc = V[:, i:j]
            P = Vc[x_dofs] + 1j * Vc[y_dofs]
            Q = Vc[x_dofs] - 1j * Vc[y_dofs]
            F, B = P.conj().T @ P, Q.conj().T @ Q
            L = np.linalg.cholesky(F + B)
            Li = np.linalg.inv(L)
            d[i:j] = np.sort(np.linalg.eigvalsh(Li @ (F - B) @ Li.conj().T))
        i = j
    return d


def campbell(M: np.ndarray, G: np.ndarray, K: np.ndarray, speeds: np.ndarray, n_modes: int,
             x_dofs: np.ndarray, y_dofs: np.ndarray, C: np.ndarray | None = None,
             T: np.ndarray | None = None) -> dict:
    """Campbell diagram: for each speed (rad/s) the first ``n_modes`` forward and backward
    whirl frequencies (rad/s, Im s; NaN where fewer exist). Rigid-body (s ~ 0) modes are
    excluded by ``Im s > 0``. For a reduced model pass its basis ``T``: the shapes are mapped
    to the full DOFs (``x_dofs``, ``y_dofs``) before their whirl is classified.
    Returns {"speed", "forward", "backward"}, arrays (speeds, n_modes).
    """
    fw = np.full((len(speeds), n_modes), np.nan)
    bw = np.full((len(speeds), n_modes), np.nan)
    for i, Om in enumerate(speeds):
        s, V = whirl_eigen(M, G, K, float(Om), C)
        if Om == 0.0:
            # not spinning: the x/y pairs are standing modes, any combination of a pair is a
            # mode; the lower of each pair counts as backward, the upper as forward (the
            # branches they continue into as the speed rises)
            b, f = s.imag[0::2], s.imag[1::2]
        else:
            if T is not None:
                V = T @ V
            d = whirl_directions(s, V, x_dofs, y_dofs)
            f, b = s.imag[d > 0], s.imag[d <= 0]
        fw[i, :min(n_modes, len(f))] = f[:n_modes]
        bw[i, :min(n_modes, len(b))] = b[:n_modes]
    return {"speed": np.asarray(speeds, float), "forward": fw, "backward": bw}


def model_whirl_dofs(model: FEModel) -> tuple[np.ndarray, np.ndarray]:
    """The x and y DOFs of every node (whirl_direction / campbell of the full model)."""
    n = np.arange(model.n_nodes) * 4
    return n + 0, n + 1
