"""Read a rotor saved by ROSS (``ross.Rotor.save``, TOML; ROSS 2.3.0's format) into a
FlexibleRotor.

Taken: ``ShaftElement_*`` tables (cylindrical: idl = idr, odl = odr; the material sub-table
E, G_s, rho; shear_effects / shear_method_calc), ``DiskElement_*`` (n, m, Id, Ip) and
``PointMass_*`` (a disk without inertia). Bearing-like elements (``BearingElement``, seals,
ball/roller/magnetic bearings, ...) are skipped with a warning: rotordrop models its supports
itself (the AMB control law and the retainer contact); their stiffness and damping are returned
in ``RossImport.supports`` so that ROSS's modal results can be reproduced. Anything else (a
tapered element, axial force or torque prestress, Rayleigh damping alpha/beta, elements off the
main shaft line, an unknown element type) stops with one line naming it.

ROSS's "hutchinson" shear option differs from Hutchinson's formula (see timoshenko.py); such
elements are read with the published formula, with a warning that their shear flexibility
differs from ROSS's.
"""
from __future__ import annotations

import tomllib
import warnings
from dataclasses import dataclass
from pathlib import Path

from .assembly import Disk, FlexibleRotor, Material, ShaftSection

SUPPORT_TYPES = ("BearingElement", "SealElement", "BallBearingElement", "RollerBearingElement",
                 "MagneticBearingElement", "BearingFluidFlow", "BearingElement6DoF",
                 "CylindricalBearing", "PlainJournal", "TiltingPad", "THDCylindrical",
                 "SqueezeFilmDamper", "LabyrinthSeal", "HoleDampSeal", "HoneycombSeal")


@dataclass(frozen=True)
class Support:
    """A skipped ROSS bearing/seal: node, axial station and its first-frequency coefficients."""
    tag: str
    kind: str
    node: int
    z: float
    kxx: float
    kyy: float
    kxy: float
    kyx: float
    cxx: float
    cyy: float


@dataclass(frozen=True)
class RossImport:
    rotor: FlexibleRotor
    supports: tuple[Support, ...]
    ross_version: str
    node_z: tuple[float, ...]   # ROSS node stations in the rotordrop frame


def _first(v) -> float:
    return float(v[0] if isinstance(v, list) else v)


def read_ross(path: str | Path, z_start: float = 0.0, **rotor_kwargs) -> RossImport:
    """Read a ROSS rotor TOML. ``z_start`` places ROSS's node 0; ``rotor_kwargs`` (amb_planes,
    retainer_planes, unbalance_planes, max_element_length, name) go to FlexibleRotor."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise ValueError(f"{path}: not a readable ROSS TOML file ({exc})") from None
    version = str(data.get("ross_version", "unknown"))
    shafts, disks, skipped = [], [], []
    for key, table in data.items():
        if key in ("ross_version", "parameters"):
            continue
        kind = key.split("_", 1)[0]
        if not isinstance(table, dict):
            raise ValueError(f"{path}: {key!r} is not a ROSS element table")
        if kind == "ShaftElement":
            shafts.append((key, table))
        elif kind in ("DiskElement", "PointMass"):
            disks.append((key, kind, table))
        elif kind in SUPPORT_TYPES or "Bearing" in kind or "Seal" in kind:
            skipped.append((key, kind, table))
        else:
            raise ValueError(f"{path}: element {key!r} of type {kind}: not supported (rotordrop "
                             f"reads ShaftElement, DiskElement, PointMass; bearings and seals are "
                             f"skipped)")
    if not shafts:
        raise ValueError(f"{path}: no ShaftElement tables (ROSS version {version})")
    shafts.sort(key=lambda kt: int(kt[1].get("n", 0)))
    sections, shear = [], set()
    for i, (key, t) in enumerate(shafts):
        if int(t.get("n", i)) != i:
            raise ValueError(f"{path}: {key!r} has n = {t.get('n')}: rotordrop takes one shaft "
                             f"line of elements numbered 0, 1, 2, ... (not parallel elements)")
        if t["idl"] != t.get("idr", t["idl"]) or t["odl"] != t.get("odr", t["odl"]):
            raise ValueError(f"{path}: {key!r} is tapered (idl/idr {t['idl']}/{t.get('idr')}, "
                             f"odl/odr {t['odl']}/{t.get('odr')}): only cylindrical elements "
                             f"are supported; split it into cylindrical ones")
        for k in ("axial_force", "torque", "alpha", "beta"):
            if float(t.get(k, 0.0)) != 0.0:
                raise ValueError(f"{path}: {key!r} has {k} = {t[k]}: not supported "
                                 f"(rotordrop's shaft has no prestress nor Rayleigh damping)")
        if not t.get("rotary_inertia", True) or not t.get("gyroscopic", True):
            raise ValueError(f"{path}: {key!r} switches off rotary_inertia or gyroscopic: "
                             f"rotordrop's elements always include both")
        shear.add(t.get("shear_method_calc", "hutchinson") if t.get("shear_effects", True)
                  else None)
        m = t.get("material")
        if not isinstance(m, dict):
            raise ValueError(f"{path}: {key!r} has no material table (E, G_s, rho)")
        mat = Material(str(m.get("name", "material")), float(m["E"]), float(m["G_s"]),
                       float(m["rho"]))
        sections.append(ShaftSection(float(t["L"]), float(t["odl"]), float(t["idl"]), mat))
    if len(shear) != 1:
        raise ValueError(f"{path}: shaft elements mix shear options {sorted(map(str, shear))}: "
                         f"rotordrop uses one for the whole shaft")
    node_z = [z_start]
    for s in sections:
        node_z.append(node_z[-1] + s.length)

    def station(key, t):
        n = int(t["n"])
        if not 0 <= n < len(node_z):
            raise ValueError(f"{path}: {key!r} at node n = {n}: allowed [0, {len(node_z) - 1}]")
        return n, node_z[n]

    disk_list = []
    for key, kind, t in disks:
        _, z = station(key, t)
        if kind == "PointMass":
            disk_list.append(Disk(z, float(t["m"]), 0.0, 0.0))
        else:
            disk_list.append(Disk(z, float(t["m"]), float(t["Id"]), float(t["Ip"])))
    supports = []
    for key, kind, t in skipped:
        n, z = station(key, t)
        supports.append(Support(str(t.get("tag", key)), kind, n, z,
                                *(_first(t.get(c, 0.0)) for c in
                                  ("kxx", "kyy", "kxy", "kyx", "cxx", "cyy"))))
    if supports:
        warnings.warn(f"{path}: skipped {len(supports)} bearing/seal element(s) "
                      f"({', '.join(s.tag for s in supports)}): rotordrop models its supports "
                      f"itself; their coefficients are in RossImport.supports", stacklevel=2)
    method = shear.pop()
    if method == "hutchinson":
        warnings.warn(f"{path}: shear_method_calc = 'hutchinson': ROSS 2.3.0's kappa is "
                      f"Hutchinson's divided by (1 + nu); read with Hutchinson's published "
                      f"formula, so the frequencies differ slightly from ROSS's", stacklevel=2)
    rotor = FlexibleRotor(tuple(sections), tuple(disk_list), z_start=z_start,
                          shear=method, **rotor_kwargs)
    return RossImport(rotor, tuple(supports), version, tuple(node_z))
