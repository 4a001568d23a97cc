"""Validated description of a flexible rotor (shaft sections, rigid disks, force planes) and
its global finite-element matrices M, K, G (DOFs per node as in timoshenko.py).

Axial positions z are in the rigid rotor's frame (physics/scene.py: AMB planes at +-0.28 m,
retainer planes at +-0.38 m); the shaft starts at ``z_start``. The mesh has a node at every
section end, disk and force plane, and elements no longer than ``max_element_length``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import timoshenko as tim

_ZTOL = 1e-9  # m: two stations closer than this are the same node


def _require(ok: bool, message: str) -> None:
    if not ok:
        raise ValueError(message)


def _finite_in(name: str, value: float, lo: float, hi: float, lo_open: bool = True) -> None:
    ok = isinstance(value, (int, float)) and math.isfinite(value) and value <= hi and (
        value > lo if lo_open else value >= lo)
    bracket = "(" if lo_open else "["
    _require(ok, f"{name} = {value!r}: allowed {bracket}{lo:g}, {hi:g}]")


@dataclass(frozen=True)
class Material:
    """Isotropic elastic material: Young's modulus E, shear modulus G_s, density rho (SI)."""
    name: str = "steel"
    E: float = 211e9
    G_s: float = 81.2e9
    rho: float = 7810.0

    def __post_init__(self):
        _finite_in(f"material {self.name!r}: E", self.E, 0.0, 1e16)
        _finite_in(f"material {self.name!r}: G_s", self.G_s, 0.0, 1e16)
        _finite_in(f"material {self.name!r}: rho", self.rho, 0.0, 1e5)
        _finite_in(f"material {self.name!r}: Poisson ratio E/(2 G_s) - 1", self.nu, -1.0, 0.5)

    @property
    def nu(self) -> float:
        """Poisson's ratio ``E / (2 G_s) - 1``."""
        return self.E / (2.0 * self.G_s) - 1.0

    @classmethod
    def from_poisson(cls, name: str, E: float, nu: float, rho: float) -> "Material":
        """Material from E and Poisson's ratio: ``G_s = E / (2 (1 + nu))``."""
        _finite_in(f"material {name!r}: nu", nu, -1.0, 0.5)
        return cls(name, E, E / (2.0 * (1.0 + nu)), rho)


STEEL = Material()


@dataclass(frozen=True)
class ShaftSection:
    """A uniform hollow cylinder: length, outer and inner diameter (m), material."""
    length: float
    outer_diameter: float
    inner_diameter: float = 0.0
    material: Material = STEEL

    def validate(self, i: int) -> None:
        _finite_in(f"sections[{i}].length", self.length, 0.0, 100.0)
        _finite_in(f"sections[{i}].outer_diameter", self.outer_diameter, 0.0, 10.0)
        _finite_in(f"sections[{i}].inner_diameter", self.inner_diameter, 0.0,
                   self.outer_diameter, lo_open=False)
        _require(self.inner_diameter < self.outer_diameter,
                 f"sections[{i}].inner_diameter = {self.inner_diameter!r}: allowed "
                 f"[0, outer_diameter = {self.outer_diameter!r}) (a hollow section needs wall)")
        _require(isinstance(self.material, Material),
                 f"sections[{i}].material = {self.material!r}: allowed a Material")

    @property
    def mass(self) -> float:
        A, _ = tim.section(self.outer_diameter, self.inner_diameter)
        return self.material.rho * A * self.length


@dataclass(frozen=True)
class Disk:
    """A rigid disk at axial station z: mass m, diametral and polar inertia about its centre."""
    z: float
    mass: float
    I_d: float
    I_p: float

    def validate(self, i: int) -> None:
        _finite_in(f"disks[{i}].z", self.z, -100.0, 100.0)
        _finite_in(f"disks[{i}].mass", self.mass, 0.0, 1e6, lo_open=False)
        _finite_in(f"disks[{i}].I_d", self.I_d, 0.0, 1e6, lo_open=False)
        _finite_in(f"disks[{i}].I_p", self.I_p, 0.0, 1e6, lo_open=False)


@dataclass(frozen=True)
class FlexibleRotor:
    """Shaft sections from ``z_start`` on, disks, and the planes where forces act.

    ``amb_planes`` and ``retainer_planes`` are two axial stations each; ``unbalance_planes``
    any number. ``shear`` is the shear-coefficient method (``"hutchinson"``, ``"cowper"``) or
    None for Euler-Bernoulli elements.
    """
    sections: tuple[ShaftSection, ...]
    disks: tuple[Disk, ...] = ()
    z_start: float = 0.0
    amb_planes: tuple[float, ...] = ()
    retainer_planes: tuple[float, ...] = ()
    unbalance_planes: tuple[float, ...] = ()
    max_element_length: float | None = None
    shear: str | None = "hutchinson"
    name: str = "rotor"

    def __post_init__(self):
        for key in ("sections", "disks", "amb_planes", "retainer_planes", "unbalance_planes"):
            object.__setattr__(self, key, tuple(getattr(self, key)))
        _require(len(self.sections) >= 1, "sections: allowed at least one ShaftSection, got none")
        for i, s in enumerate(self.sections):
            _require(isinstance(s, ShaftSection), f"sections[{i}] = {s!r}: allowed a ShaftSection")
            s.validate(i)
        _finite_in("z_start", self.z_start, -100.0, 100.0)
        z0, z1 = self.z_start, self.z_end
        for i, d in enumerate(self.disks):
            _require(isinstance(d, Disk), f"disks[{i}] = {d!r}: allowed a Disk")
            d.validate(i)
            _require(z0 - _ZTOL <= d.z <= z1 + _ZTOL,
                     f"disks[{i}].z = {d.z!r}: allowed [{z0:g}, {z1:g}] (on the shaft)")
        for key in ("amb_planes", "retainer_planes"):
            planes = getattr(self, key)
            _require(len(planes) in (0, 2), f"{key} = {planes!r}: allowed two stations (or none)")
        for key in ("amb_planes", "retainer_planes", "unbalance_planes"):
            for i, z in enumerate(getattr(self, key)):
                _finite_in(f"{key}[{i}]", z, -100.0, 100.0)
                _require(z0 - _ZTOL <= z <= z1 + _ZTOL,
                         f"{key}[{i}] = {z!r}: allowed [{z0:g}, {z1:g}] (on the shaft)")
        if self.max_element_length is not None:
            _finite_in("max_element_length", self.max_element_length, 0.0, 100.0)
        _require(self.shear in (None, "hutchinson", "cowper"),
                 f"shear = {self.shear!r}: allowed 'hutchinson', 'cowper' or None")

    @property
    def z_end(self) -> float:
        return self.z_start + sum(s.length for s in self.sections)

    @property
    def length(self) -> float:
        return self.z_end - self.z_start


@dataclass(frozen=True)
class FEModel:
    """Global matrices of ``M q'' + Omega G q' + K q = f`` over q = (x, y, a, b) per node."""
    rotor: FlexibleRotor
    z: np.ndarray                       # node stations (m)
    M: np.ndarray
    K: np.ndarray
    G: np.ndarray
    planes: dict = field(default_factory=dict)  # plane name -> node ("amb1", "rb2", "unb1")

    @property
    def n_nodes(self) -> int:
        return len(self.z)

    @property
    def ndof(self) -> int:
        return tim.DOF_PER_NODE * len(self.z)

    def dof(self, node: int, which: str) -> int:
        """Global index of DOF ``which`` in ``"xyab"`` at ``node``."""
        return tim.DOF_PER_NODE * node + "xyab".index(which)

    def node_at(self, z: float) -> int:
        """Index of the node at station z (ValueError naming the nearest if none is there)."""
        i = int(np.argmin(np.abs(self.z - z)))
        _require(abs(self.z[i] - z) <= 1e-6,
                 f"z = {z!r}: no node there; nearest node {i} at {self.z[i]:g}")
        return i

    def rigid_body_modes(self) -> np.ndarray:
        """The 4 rigid-body shapes (columns): x translation, tilt a about z = 0, y, tilt b."""
        R = np.zeros((self.ndof, 4))
        n = np.arange(self.n_nodes) * tim.DOF_PER_NODE
        R[n + tim.X, 0] = 1.0
        R[n + tim.X, 1] = self.z
        R[n + tim.A, 1] = 1.0
        R[n + tim.Y, 2] = 1.0
        R[n + tim.Y, 3] = self.z
        R[n + tim.B, 3] = 1.0
        return R


def mesh(rotor: FlexibleRotor) -> tuple[np.ndarray, list[int]]:
    """Node stations and, per element, the index of its section."""
    ends = np.cumsum([rotor.z_start] + [s.length for s in rotor.sections])
    extra = [d.z for d in rotor.disks] + list(rotor.amb_planes) + list(rotor.retainer_planes) \
        + list(rotor.unbalance_planes)
    z_nodes, owner = [ends[0]], []
    for k, s in enumerate(rotor.sections):
        a, b = ends[k], ends[k + 1]
        cuts = [b]
        for z in sorted((z for z in extra if a + _ZTOL < z < b - _ZTOL), reverse=True):
            if cuts[0] - z > _ZTOL:              # stations closer than _ZTOL share a node
                cuts.insert(0, z)
        prev = a
        for c in cuts:
            n = 1 if rotor.max_element_length is None else max(
                1, math.ceil((c - prev) / rotor.max_element_length - 1e-9))
            for j in range(1, n + 1):
                z_nodes.append(prev + (c - prev) * j / n)
                owner.append(k)
            prev = c
    return np.array(z_nodes), owner


def assemble(rotor: FlexibleRotor) -> FEModel:
    """Global M, K, G of the shaft elements and disks, and the node of each named plane."""
    z, owner = mesh(rotor)
    nd = tim.DOF_PER_NODE * len(z)
    M, K, G = np.zeros((nd, nd)), np.zeros((nd, nd)), np.zeros((nd, nd))
    for e, k in enumerate(owner):
        s = rotor.sections[k]
        Me, Ke, Ge = tim.element_matrices(z[e + 1] - z[e], s.outer_diameter, s.inner_diameter,
                                          s.material.E, s.material.G_s, s.material.rho,
                                          rotor.shear)
        sl = slice(tim.DOF_PER_NODE * e, tim.DOF_PER_NODE * (e + 2))
        M[sl, sl] += Me
        K[sl, sl] += Ke
        G[sl, sl] += Ge

    def node(zp: float) -> int:  # mesh() put a node at every disk and plane
        return int(np.argmin(np.abs(z - zp)))

    for d in rotor.disks:
        Md, Gd = tim.disk_matrices(d.mass, d.I_d, d.I_p)
        sl = slice(tim.DOF_PER_NODE * node(d.z), tim.DOF_PER_NODE * (node(d.z) + 1))
        M[sl, sl] += Md
        G[sl, sl] += Gd
    planes = {f"{prefix}{j + 1}": node(zp)
              for prefix, stations in (("amb", rotor.amb_planes), ("rb", rotor.retainer_planes),
                                       ("unb", rotor.unbalance_planes))
              for j, zp in enumerate(stations)}
    return FEModel(rotor, z, M, K, G, planes)


def support_matrix(model: FEModel, supports) -> np.ndarray:
    """Stiffness (or damping) matrix of linear point supports ``[(node, kxx, kyy), ...]`` on the
    x and y DOFs (e.g. an AMB's linearised stiffness, or ROSS's bearings)."""
    S = np.zeros((model.ndof, model.ndof))
    for node, kxx, kyy in supports:
        _require(0 <= node < model.n_nodes,
                 f"support node = {node!r}: allowed [0, {model.n_nodes - 1}]")
        S[model.dof(node, "x"), model.dof(node, "x")] += kxx
        S[model.dof(node, "y"), model.dof(node, "y")] += kyy
    return S


def rigid_properties(rotor: FlexibleRotor) -> dict:
    """Mass, centre of mass, I_d (about the centre of mass) and I_p of shaft + disks, in closed
    form: a hollow cylinder has ``I_p = m (D^2 + d^2) / 8`` and, about its own centre,
    ``I_d = m ((D^2 + d^2) / 16 + L^2 / 12)``."""
    parts = []  # (m, z_c, I_d about own centre, I_p)
    z = rotor.z_start
    for s in rotor.sections:
        m = s.mass
        D2 = s.outer_diameter ** 2 + s.inner_diameter ** 2
        parts.append((m, z + s.length / 2, m * (D2 / 16 + s.length ** 2 / 12), m * D2 / 8))
        z += s.length
    parts += [(d.mass, d.z, d.I_d, d.I_p) for d in rotor.disks]
    m = sum(p[0] for p in parts)
    zc = sum(p[0] * p[1] for p in parts) / m
    I_d = sum(p[2] + p[0] * (p[1] - zc) ** 2 for p in parts)
    return {"mass": m, "z_cg": zc, "I_d": I_d, "I_p": sum(p[3] for p in parts)}
