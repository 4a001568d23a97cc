"""Whirl frequencies of the rigid rotor on its AMB springs versus spin (Campbell diagram, spec §1).

Linearised: the rotor (m, I_d, I_p) on isotropic springs k = ``amb.stiffness`` at the AMB planes
z_1, z_2 (measured from the centre of mass), undamped. With Z = x + iy, psi = a + ib:

    m Z'' + k11 Z + k12 psi = 0,     I_d psi'' - i I_p Omega psi' + k12 Z + k22 psi = 0,
    k11 = sum k, k12 = sum k z, k22 = sum k z^2,

and Z, psi ~ e^{i w t} give (k11 - m w^2)(k22 - I_d w^2 + I_p Omega w) - k12^2 = 0: four real
whirl frequencies, w > 0 forward (with the spin), w < 0 backward. :func:`identified_frequencies`
reads the same frequencies from a simulated free response, so the two can be compared
(tests/physics/test_gyroscopics.py, docs/examples/campbell.py).
"""
from __future__ import annotations

import numpy as np

# the AMBs as undamped linear springs and nothing else acting (overrides for any scene)
SPRINGS_ONLY = {"effects.amb": "linear", "amb.damping": 0.0, "effects.gravity": False,
                "effects.unbalance": False, "effects.friction": "none"}


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
