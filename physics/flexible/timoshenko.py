"""Timoshenko shaft finite element of a hollow circular section: mass, stiffness, gyroscopic.

Degrees of freedom per node, matching the rigid rotor of physics/rotor.py:
``(x, y, a, b)`` with ``a = dx/dz`` and ``b = dy/dz`` the slopes of the cross-section (small
tilts; in Timoshenko theory the cross-section rotation, which differs from the slope of the
centre line by the shear angle). With this choice both bending planes have the same planar
element matrices for ``(x1, a1, x2, a2)`` and ``(y1, b1, y2, b2)``, and a spin ``Omega`` about
+z enters as in physics/rotor.py: ``I_d a'' + I_p Omega b' = M_a``, ``I_d b'' - I_p Omega a' =
M_b``, with ``M_a = sum z F_x`` the generalised force of ``a``. The equation of motion is

    M q'' + Omega G q' + K q = f,   G = -G^T.

Matrices (element length L, ``Phi = 12 E I / (kappa G_s A L^2)``), from Friswell, Penny,
Garvey & Lees, *Dynamics of Rotating Machines*, Cambridge UP 2010, §5.4 (same as Nelson,
J. Mech. Des. 102, 1980, 793-803, and as ROSS's cylindrical ShaftElement):

* translational mass ``rho A L / (840 (1+Phi)^2) * [...]`` (m1..m6 below),
* rotary inertia ``rho I / (30 L (1+Phi)^2) * [...]`` (r1..r6 below),
* stiffness ``E I / ((1+Phi) L^3) * [[12, 6L, -12, 6L], [6L, (4+Phi)L^2, -6L, (2-Phi)L^2], ...]``,
* gyroscopic: the rotary-inertia matrix with ``rho I`` replaced by ``rho I_p = 2 rho I``,
  coupling the planes: ``G[x-plane, y-plane] = +R_p``, ``G[y-plane, x-plane] = -R_p``.
"""
from __future__ import annotations

import math

import numpy as np

from ..layout import Slots

#: the node's DOF offsets: x, y, a = dx/dz, b = dy/dz
NODE_DOFS = Slots("node DOF")
X, Y, A, B = NODE_DOFS.add_each("x", "y", "a", "b")
DOF_PER_NODE = NODE_DOFS.freeze().size


def section(outer_diameter: float, inner_diameter: float) -> tuple[float, float]:
    """Area ``A = pi (D^2 - d^2) / 4`` and second moment ``I = pi (D^4 - d^4) / 64``."""
    D, d = outer_diameter, inner_diameter
    return math.pi * (D * D - d * d) / 4.0, math.pi * (D ** 4 - d ** 4) / 64.0


def shear_coefficient(outer_diameter: float, inner_diameter: float, nu: float,
                      method: str = "hutchinson") -> float:
    """Shear coefficient kappa of a hollow circle, ``r = d / D``.

    * ``"hutchinson"``: Hutchinson, J. Appl. Mech. 68 (2001) 87-92, hollow circle
      ``kappa = 6 (1+r^2)^2 (1+nu)^2 / [(1+r^2)^2 (7+12nu+4nu^2) + 4 r^2 (5+6nu+2nu^2)]``
      (solid: ``6 (1+nu)^2 / (7+12nu+4nu^2)``, 0.925 at nu = 0.3).
    * ``"cowper"``: Cowper, J. Appl. Mech. 33 (1966) 335-340, table 1,
      ``kappa = 6 (1+nu) (1+r^2)^2 / [(7+6nu) (1+r^2)^2 + (20+12nu) r^2]`` (solid: 0.886).

    (ROSS 2.3.0's "hutchinson" option has ``(1+nu)`` where Hutchinson has ``(1+nu)^2``, i.e.
    a kappa 1/(1+nu) lower; its "cowper" option is Cowper's formula.)
    """
    r2 = (inner_diameter / outer_diameter) ** 2
    s = (1.0 + r2) ** 2
    if method == "hutchinson":
        return 6.0 * s * (1.0 + nu) ** 2 / (s * (7.0 + 12.0 * nu + 4.0 * nu * nu)
                                            + 4.0 * r2 * (5.0 + 6.0 * nu + 2.0 * nu * nu))
    if method == "cowper":
        return 6.0 * (1.0 + nu) * s / ((7.0 + 6.0 * nu) * s + (20.0 + 12.0 * nu) * r2)
    raise ValueError(f"shear method = {method!r}: allowed 'hutchinson' or 'cowper'")


def shear_parameter(E: float, G_s: float, kappa: float, A: float, I: float, L: float) -> float:
    """``Phi = 12 E I / (kappa G_s A L^2)``: shear over bending flexibility (0: Euler-Bernoulli)."""
    return 12.0 * E * I / (kappa * G_s * A * L * L)


def planar_translational_mass(rho: float, A: float, L: float, phi: float) -> np.ndarray:
    """Consistent translational mass of one plane, DOFs (w1, psi1, w2, psi2)."""
    p, p2 = phi, phi * phi
    m1 = 312 + 588 * p + 280 * p2
    m2 = (44 + 77 * p + 35 * p2) * L
    m3 = 108 + 252 * p + 140 * p2
    m4 = (26 + 63 * p + 35 * p2) * L
    m5 = (8 + 14 * p + 7 * p2) * L * L
    m6 = (6 + 14 * p + 7 * p2) * L * L
    mat = np.array([[m1, m2, m3, -m4],
                    [m2, m5, m4, -m6],
                    [m3, m4, m1, -m2],
                    [-m4, -m6, -m2, m5]])
    return rho * A * L / (840.0 * (1.0 + p) ** 2) * mat


def planar_rotary_mass(rho_I: float, L: float, phi: float) -> np.ndarray:
    """Rotary inertia of one plane (``rho_I`` = rho I for the mass, rho I_p for the gyroscopic)."""
    p, p2 = phi, phi * phi
    r1 = 36.0
    r2 = (3 - 15 * p) * L
    r3 = (4 + 5 * p + 10 * p2) * L * L
    r4 = (-1 - 5 * p + 5 * p2) * L * L
    mat = np.array([[r1, r2, -r1, r2],
                    [r2, r3, -r2, r4],
                    [-r1, -r2, r1, -r2],
                    [r2, r4, -r2, r3]])
    return rho_I / (30.0 * L * (1.0 + p) ** 2) * mat


def planar_stiffness(E: float, I: float, L: float, phi: float) -> np.ndarray:
    """Bending + shear stiffness of one plane, DOFs (w1, psi1, w2, psi2)."""
    L2 = L * L
    mat = np.array([[12, 6 * L, -12, 6 * L],
                    [6 * L, (4 + phi) * L2, -6 * L, (2 - phi) * L2],
                    [-12, -6 * L, 12, -6 * L],
                    [6 * L, (2 - phi) * L2, -6 * L, (4 + phi) * L2]])
    return E * I / ((1.0 + phi) * L ** 3) * mat


# positions of the x-plane (x1, a1, x2, a2) and y-plane (y1, b1, y2, b2) DOFs in the element's
# 8 DOFs (x1, y1, a1, b1, x2, y2, a2, b2)
_XP = np.array([0, 2, 4, 6])
_YP = np.array([1, 3, 5, 7])


def _both_planes(planar: np.ndarray) -> np.ndarray:
    out = np.zeros((8, 8))
    out[np.ix_(_XP, _XP)] = planar
    out[np.ix_(_YP, _YP)] = planar
    return out


def element_matrices(L: float, outer_diameter: float, inner_diameter: float, E: float,
                     G_s: float, rho: float, shear: str | None = "hutchinson",
                     rotary_inertia: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(M, K, G), each 8 x 8 over (x1, y1, a1, b1, x2, y2, a2, b2).

    ``shear`` is the shear-coefficient method, or None for Euler-Bernoulli (Phi = 0).
    ``rotary_inertia=False`` drops rho I from the mass (the gyroscopic matrix is kept).
    """
    A, I = section(outer_diameter, inner_diameter)
    if shear is None:
        phi = 0.0
    else:
        nu = E / (2.0 * G_s) - 1.0
        phi = shear_parameter(E, G_s, shear_coefficient(outer_diameter, inner_diameter, nu, shear),
                              A, I, L)
    Rm = planar_rotary_mass(rho * I, L, phi)
    M = _both_planes(planar_translational_mass(rho, A, L, phi) + (Rm if rotary_inertia else 0.0))
    K = _both_planes(planar_stiffness(E, I, L, phi))
    Rp = 2.0 * Rm  # I_p = 2 I for a circular section
    G = np.zeros((8, 8))
    G[np.ix_(_XP, _YP)] = Rp
    G[np.ix_(_YP, _XP)] = -Rp
    return M, K, G


def disk_matrices(mass: float, I_d: float, I_p: float) -> tuple[np.ndarray, np.ndarray]:
    """Rigid disk at a node: ``M = diag(m, m, I_d, I_d)``, ``G[a, b] = I_p = -G[b, a]``."""
    M = np.diag([mass, mass, I_d, I_d])
    G = np.zeros((4, 4))
    G[A, B] = I_p
    G[B, A] = -I_p
    return M, G
