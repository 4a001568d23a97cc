"""Whirl frequencies of the rigid rotor on its AMB springs versus spin (Campbell diagram, spec §1).

Linearised: the rotor (m, I_d, I_p) on isotropic springs k = ``amb.stiffness`` at the AMB planes
z_1, z_2 (measured from the centre of mass), undamped. With Z = x + iy, psi = a + ib:

    m Z'' + k11 Z + k12 psi = 0,     I_d psi'' - i I_p Omega psi' + k12 Z + k22 psi = 0,
    k11 = sum k, k12 = sum k z, k22 = sum k z^2,

and Z, psi ~ e^{i w t} give (k11 - m w^2)(k22 - I_d w^2 + I_p Omega w) - k12^2 = 0: four real
whirl frequencies, w > 0 forward (with the spin), w < 0 backward. :func:`identified_frequencies`
reads the same frequencies from a simulated free response, so the two can be compared
(tests/physics/test_gyroscopics.py, docs/examples/campbell.py).

A flexible rotor (``rotor.model = "flexible"``) adds its bending modes: :func:`flexible_whirl`
solves ``M q'' + (C + Omega G) q' + (K + K_amb) q = 0`` with isotropic springs ``amb.stiffness``
and dashpots ``amb.damping`` at the AMB stations and the modal damping ratio
``flexible.damping_ratio`` on the elastic modes, either on the reduced floating-frame model the
drop kernel integrates (physics/flexible/floating.py: x, a and the elastic coordinates per
bending plane, built from the same ``FloatingModel`` fields as physics/flexible_rotor.py) or on
the full finite-element model it was reduced from (``full=True``), and classifies each mode as
forward or backward (physics/flexible/modal.py) and by the share of its kinetic energy in
elastic motion (rigid-body mode on the AMB springs or bending mode). With the scene's
``amb.damping = 0`` and ``flexible.damping_ratio = 0`` (:data:`SPRINGS_ONLY`) and a shaft made
stiff (``flexible.modulus_scale = 1000``) its rigid-body modes are :func:`whirl_frequencies`'.
"""
from __future__ import annotations

import numpy as np

# the AMBs as undamped linear springs and nothing else acting (overrides for any scene)
SPRINGS_ONLY = {"effects.amb": "linear", "amb.damping": 0.0, "effects.gravity": False,
                "effects.unbalance": False, "effects.friction": "none"}
#: whirl frequencies this close (relative) are one degenerate pair, e.g. the cylindrical mode of a
#: symmetric rotor, which spin does not split and which the full FE model's eigen-solver, ill
#: conditioned by its stiff high modes, separates by ~1e-6 (physics.flexible.modal.whirl_directions)
CLUSTER_RTOL = 1e-5
#: a mode with more than this share of its kinetic energy in elastic motion is a bending mode
BENDING_SHARE = 0.5


def whirl_frequencies(scene, omega: float) -> np.ndarray:
    """The four signed whirl frequencies [rad/s] at spin ``omega`` [rad/s], ascending."""
    r, k = scene.rotor, scene.amb.stiffness
    z = np.array([scene.positions.amb1, scene.positions.amb2])
    k11, k12, k22 = 2 * k, k * z.sum(), k * (z ** 2).sum()
    quartic = (np.polymul([-r.mass, 0.0, k11], [-r.diametral_inertia, r.polar_inertia * omega, k22])
               - np.array([0.0, 0.0, 0.0, 0.0, k12 ** 2]))
    roots = np.roots(quartic)
    return np.sort(roots.real)


def identified_frequencies(t: np.ndarray, a: np.ndarray, b: np.ndarray, n: int = 4) -> np.ndarray:
    """The ``n`` strongest whirl frequencies [rad/s] in the tilt signal psi = a + ib sampled at
    the uniform times ``t`` (Hann window, 8x zero padding, parabolic interpolation of the log
    spectrum), ascending: > 0 forward, < 0 backward."""
    psi = (a + 1j * b) * np.hanning(len(t))
    nfft = 8 * len(t)
    spec = np.abs(np.fft.fftshift(np.fft.fft(psi, nfft)))
    w = np.fft.fftshift(np.fft.fftfreq(nfft, t[1] - t[0])) * 2 * np.pi
    inner = spec[1:-1]
    peaks = np.flatnonzero((spec[:-2] < inner) & (inner >= spec[2:])) + 1
    peaks = peaks[np.argsort(-spec[peaks])][:n]
    lo, mid, hi = (np.log(spec[peaks + j]) for j in (-1, 0, 1))
    return np.sort(w[peaks] + 0.5 * (w[1] - w[0]) * (lo - hi) / (lo - 2 * mid + hi))


def free_response(scene, omega: float, t_end: float, rate: float = 2000.0,
                  kick: dict | None = None):
    """Free response of the rotor spinning at ``omega`` on the AMBs (powered, no fault) after a
    kick of its velocities (state name -> value; default tilt rates 0.05 and 0.02 rad/s and
    lateral 4 mm/s, which keep a paper-sized rotor well inside the retainer clearance), sampled
    at ``rate`` Hz. Use a scene with :data:`SPRINGS_ONLY` for the linearised comparison.
    Returns (t, Y, model)."""
    from .model import build_model
    from .simulate import Integrator
    model = build_model(scene)
    y = np.zeros(model.n_state)
    y[model.index("Omega")] = omega
    for name, value in (kick or {"va": 0.05, "vb": 0.02, "vx": 0.004}).items():
        y[model.index(name)] = value
    t = np.linspace(0.0, t_end, int(round(t_end * rate)) + 1)
    Y = np.empty((len(t), model.n_state))
    Y[0] = y
    Integrator(model).advance(y, 0.0, t_end, model.controls(True), t, Y, 1)
    return t, Y, model


def flexible_system(scene, full: bool = False) -> dict:
    """The linearised flexible rotor of ``scene`` (``rotor.model = "flexible"``) on its AMBs:
    {"M", "G", "K", "C"} (``M q'' + (C + Omega G) q' + K q = 0``, AMB springs and dashpots in K
    and C, the modal damping in C), the map ``T`` of its coordinates to the FE model's (x, y, a, b
    per node; None for the full model), and the FE model ``fe`` (for the whirl classification).

    Reduced (default): per bending plane (x, a, eta_1 ... eta_n) with the masses m, I_d, 1, the
    elastic stiffnesses omega_j^2, the AMB spring on the station displacement
    ``x + z_s a + S[s] . eta`` and the gyroscopic blocks I_p, g, G_e, as the drop kernel
    (physics/flexible_rotor.py). Full: every FE degree of freedom, the modal damping as
    ``M V diag(2 zeta omega) V^T M`` over all free-free elastic modes V."""
    from .flexible import assembly as asm
    from .flexible.floating import STATIONS, planar_dofs
    from .flexible.modal import generalized_eigh
    from .flexible.shafts import drop_rotor
    if scene.rotor.model != "flexible":
        raise ValueError(f"rotor.model = {scene.rotor.model!r}: allowed 'flexible' here (the rigid "
                         f"rotor's whirl: whirl_frequencies)")
    fm = drop_rotor(scene)
    fe = fm.fe
    k, c, zeta = scene.amb.stiffness, scene.amb.damping, scene.flexible.damping_ratio
    ambs = ("amb1", "amb2")
    if full:
        nodes = [fe.planes[p] for p in ambs]
        K = fe.K + asm.support_matrix(fe, [(n, k, k) for n in nodes])
        C = asm.support_matrix(fe, [(n, c, c) for n in nodes])
        lam, V = generalized_eigh(fe.K, fe.M)
        MV = fe.M @ V[:, 4:]
        C = C + MV @ np.diag(2.0 * zeta * np.sqrt(np.clip(lam[4:], 0.0, None))) @ MV.T
        return {"M": fe.M, "G": fe.G, "K": K, "C": C, "T": None, "fe": fe}
    n = fm.n_modes
    r = 2 + n
    Mr = np.diag(np.concatenate([[fm.mass, fm.I_d], np.ones(n)]))
    Kr = np.diag(np.concatenate([[0.0, 0.0], fm.omega ** 2]))
    Cr = np.diag(np.concatenate([[0.0, 0.0], 2.0 * zeta * fm.omega]))
    z = {"amb1": scene.positions.amb1, "amb2": scene.positions.amb2}
    for p in ambs:
        u = np.concatenate([[1.0, z[p]], fm.shape[STATIONS.index(p)]])
        Kr += k * np.outer(u, u)
        Cr += c * np.outer(u, u)
    Gr = np.zeros((r, r))
    Gr[1, 1] = fm.I_p
    Gr[1, 2:] = Gr[2:, 1] = fm.g
    Gr[2:, 2:] = fm.G
    O = np.zeros((r, r))
    xp, yp = planar_dofs(fe)
    T = np.zeros((fe.ndof, 2 * r))
    T[xp, :r] = fm.basis
    T[yp, r:] = fm.basis
    return {"M": np.block([[Mr, O], [O, Mr]]), "G": np.block([[O, Gr], [-Gr.T, O]]),
            "K": np.block([[Kr, O], [O, Kr]]), "C": np.block([[Cr, O], [O, Cr]]), "T": T, "fe": fe}


def flexible_whirl(scene, speeds, n_modes: int = 4, full: bool = False) -> dict:
    """Campbell diagram of the flexible rotor of ``scene`` on its AMBs (:func:`flexible_system`):
    per speed [rad/s] the first ``n_modes`` forward and backward whirl frequencies [rad/s, > 0]
    with their damping ratios and elastic kinetic-energy shares (> :data:`BENDING_SHARE`: a
    bending mode), NaN where fewer exist. At rest the lower of each degenerate x/y pair counts as
    backward (physics/flexible/modal.py). Returns {"speed", "forward", "backward",
    "forward_damping", "backward_damping", "forward_elastic", "backward_elastic"}, arrays
    (speeds, n_modes)."""
    from .flexible.modal import model_whirl_dofs, whirl_directions, whirl_eigen
    sysm = flexible_system(scene, full)
    fe, T = sysm["fe"], sysm["T"]
    x, y = model_whirl_dofs(fe)
    R = fe.rigid_body_modes()
    MR = fe.M @ R
    mR = R.T @ MR
    speeds = np.atleast_1d(np.asarray(speeds, float))
    out = {key: np.full((len(speeds), n_modes), np.nan) for key in (
        "forward", "backward", "forward_damping", "backward_damping", "forward_elastic",
        "backward_elastic")}
    for i, Om in enumerate(speeds):
        s, V = whirl_eigen(sysm["M"], sysm["G"], sysm["K"], float(Om), sysm["C"])
        if T is not None:
            V = T @ V
        ke = np.einsum("ij,ij->j", V.conj(), fe.M @ V).real
        RV = MR.T @ V
        rigid = np.einsum("ij,ij->j", RV.conj(), np.linalg.solve(mR, RV)).real
        elastic = 1.0 - rigid / ke
        if Om == 0.0:
            fwd = np.zeros(len(s), bool)
            fwd[1::2] = True
        else:
            fwd = whirl_directions(s, V, x, y, CLUSTER_RTOL) > 0
        for name, sel in (("forward", fwd), ("backward", ~fwd)):
            m = min(n_modes, int(sel.sum()))
            out[name][i, :m] = s.imag[sel][:m]
            out[f"{name}_damping"][i, :m] = (-s.real / np.abs(s))[sel][:m]
            out[f"{name}_elastic"][i, :m] = elastic[sel][:m]
    out["speed"] = speeds
    return out


def first_bending(whirl: dict, direction: str = "forward") -> np.ndarray:
    """Per speed the frequency [rad/s] of the lowest ``direction`` whirl mode that is a bending
    mode (elastic kinetic-energy share > :data:`BENDING_SHARE`; NaN if none is among them)."""
    f, e = whirl[direction], whirl[f"{direction}_elastic"]
    out = np.full(len(f), np.nan)
    for i in range(len(f)):
        hit = np.flatnonzero(e[i] > BENDING_SHARE)
        if hit.size:
            out[i] = f[i, hit[0]]
    return out


def flexible_free_frequencies(scene, omega: float, t_end: float = 4.0,
                              rate: float = 4000.0) -> np.ndarray:
    """The whirl frequencies [rad/s, signed: > 0 forward] of the flexible rotor of ``scene``
    read from the drop kernel's free responses at spin ``omega`` (:func:`free_response`): the
    four rigid-body modes from the axis orbit at the AMB1 station (rigid motion plus the
    elastic modes there) after the default kick, and the first bending pair from the first
    elastic coordinate after a kick of its rates. Ascending. Use a scene with
    :data:`SPRINGS_ONLY` and ``flexible.damping_ratio = 0`` (a damped bending mode dies out
    before the window ends) to compare with :func:`flexible_whirl`."""
    from .model import ST_AMB1
    from .results import station_series
    t, Y, m = free_response(scene, omega, t_end, rate)
    axis = station_series(m, Y, ST_AMB1)
    rigid = identified_frequencies(t, axis[:, 0], axis[:, 1], 4)
    t, Y, m = free_response(scene, omega, t_end, rate, kick={"deta_x1": 0.02, "deta_y1": 0.01})
    bending = identified_frequencies(t, Y[:, m.index("eta_x1")], Y[:, m.index("eta_y1")], 2)
    return np.sort(np.concatenate([rigid, bending]))
