"""The shaft a scene names (``flexible.shaft``) and the reduced rotor a drop integrates.

``flexible.shaft`` is a built-in rotor (``"paper"``, ``"machine"``: physics/flexible/examples.py)
or the path of a TOML rotor file: either one saved by ROSS (``ross.Rotor.save``, read by
:func:`physics.flexible.ross_io.read_ross`) or a rotordrop rotor file::

    name = "compressor"          # optional
    z_start = 0.0                # m, station of the shaft's left end (any frame; optional)
    shear = "hutchinson"         # or "cowper", or "none" (Euler-Bernoulli); optional

    [materials.steel]            # optional; "steel" (211 GPa, 81.2 GPa, 7810 kg/m^3) is built in
    E = 211e9                    # Pa
    nu = 0.3                     # or G_s = 81.2e9 (Pa)
    rho = 7810.0                 # kg/m^3

    [[sections]]                 # from the left end on, one after the other
    length = 0.25                # m
    outer_diameter = 0.07        # m
    inner_diameter = 0.0         # m (optional)
    material = "steel"           # optional

    [[disks]]                    # rigid disks (optional)
    z = 0.45                     # m, in the file's frame
    mass = 19.5                  # kg
    I_d = 0.21                   # kg m^2, about the disk's centre
    I_p = 0.18                   # kg m^2

The drop model puts the rotor's centre of mass at z = 0 (the frame of ``positions.*`` and
``unbalance.z``): the shaft is shifted by its centre of mass, and the force stations are the
scene's. A file that is not one of the two forms, an element rotordrop cannot take or a station
off the shaft stops with one line naming it.
"""
from __future__ import annotations

import dataclasses
import functools
import math
import tomllib
from pathlib import Path

from . import examples
import numpy as np

from .assembly import STEEL, Disk, FlexibleRotor, Material, ShaftSection, assemble, rigid_properties
from .floating import MAX_MODES, FloatingModel, floating_model, free_free_bending

#: built-in shafts by name
BUILT_IN = {"paper": examples.paper_flexible, "machine": examples.machine_flexible}


class ShaftError(ValueError):
    """A shaft description that cannot be used (the message names the key or element)."""


def load_shaft(source: str) -> FlexibleRotor:
    """The rotor ``flexible.shaft`` names, in its own frame, without force stations."""
    if source in BUILT_IN:
        return BUILT_IN[source]()
    path = Path(source)
    if path.suffix != ".toml":
        raise ShaftError(f"flexible.shaft = {source!r}: allowed {', '.join(map(repr, BUILT_IN))} "
                         f"or the path of a .toml rotor file (rotordrop's or ROSS's Rotor.save)")
    try:
        data = tomllib.loads(path.read_text())
    except OSError as exc:
        raise ShaftError(f"flexible.shaft = {source!r}: cannot read it ({exc.strerror})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ShaftError(f"flexible.shaft = {source!r}: not valid TOML ({exc})") from None
    try:
        if "sections" in data:
            return _rotordrop_file(data, path)
        from .ross_io import read_ross
        return read_ross(path).rotor     # warns in one line of the bearings it leaves out
    except (ValueError, KeyError, TypeError) as exc:          # ShaftError is a ValueError
        raise ShaftError(f"flexible.shaft = {source!r}: {exc}") from None


def _rotordrop_file(data: dict, path: Path) -> FlexibleRotor:
    known = {"name", "z_start", "shear", "materials", "sections", "disks"}
    extra = sorted(set(data) - known)
    if extra:
        raise ShaftError(f"unknown key(s) {', '.join(extra)}; allowed "
                         f"{', '.join(sorted(known))}")
    materials = {"steel": STEEL}
    for name, m in data.get("materials", {}).items():
        if "G_s" in m:
            materials[name] = Material(name, float(m["E"]), float(m["G_s"]), float(m["rho"]))
        else:
            materials[name] = Material.from_poisson(name, float(m["E"]), float(m["nu"]),
                                                    float(m["rho"]))
    sections = []
    for i, s in enumerate(data["sections"]):
        mat = s.get("material", "steel")
        if mat not in materials:
            raise ShaftError(f"sections[{i}].material = {mat!r}: allowed "
                             f"{', '.join(map(repr, materials))}")
        sections.append(ShaftSection(*(_number(s, f"sections[{i}]", key, default) for key, default
                                       in (("length", None), ("outer_diameter", None),
                                           ("inner_diameter", 0.0))), materials[mat]))
    disks = tuple(Disk(*(_number(d, f"disks[{i}]", key, default) for key, default in
                         (("z", None), ("mass", None), ("I_d", 0.0), ("I_p", 0.0))))
                  for i, d in enumerate(data.get("disks", [])))
    shear = data.get("shear", "hutchinson")
    return FlexibleRotor(tuple(sections), disks, z_start=float(data.get("z_start", 0.0)),
                         shear=None if shear == "none" else shear,
                         name=str(data.get("name", path.stem)))


def _number(table: dict, where: str, key: str, default: float | None) -> float:
    """``table[key]`` as a float; a missing required key or a non-number names the key."""
    if key not in table and default is None:
        raise ShaftError(f"{where}.{key}: missing (a number is required)")
    value = table.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ShaftError(f"{where}.{key} = {value!r}: allowed a number")
    return float(value)


def _scaled(material: Material, factor: float) -> Material:
    return dataclasses.replace(material, E=material.E * factor, G_s=material.G_s * factor)


def centred(shaft: FlexibleRotor, modulus_scale: float, element_length: float) -> FlexibleRotor:
    """The shaft shifted so that its centre of mass is at z = 0, moduli scaled, no stations."""
    z_cg = rigid_properties(shaft)["z_cg"]
    sections = tuple(dataclasses.replace(s, material=_scaled(s.material, modulus_scale))
                     for s in shaft.sections)
    disks = tuple(dataclasses.replace(d, z=d.z - z_cg) for d in shaft.disks)
    return FlexibleRotor(sections, disks, z_start=shaft.z_start - z_cg,
                         max_element_length=element_length, shear=shaft.shear, name=shaft.name)


def _station_rotor(shaft: str, modulus_scale: float, element_length: float, stations: tuple,
                   unbalance_z: float) -> FlexibleRotor:
    """The centred shaft with the scene's force stations (each checked to lie on it)."""
    base = centred(load_shaft(shaft), modulus_scale, element_length)
    rb1, rb2, amb1, amb2 = stations
    for key, z in (("positions.rb1", rb1), ("positions.rb2", rb2), ("positions.amb1", amb1),
                   ("positions.amb2", amb2), ("unbalance.z", unbalance_z)):
        if not base.z_start - 1e-9 <= z <= base.z_end + 1e-9:
            raise ShaftError(f"{key} = {z:g}: allowed [{base.z_start:.4g}, {base.z_end:.4g}] m "
                             f"(on the shaft {shaft!r}, centre-of-mass frame)")
    return dataclasses.replace(base, retainer_planes=(rb1, rb2), amb_planes=(amb1, amb2),
                               unbalance_planes=(unbalance_z,))


def _key(scene) -> tuple:
    f, p = scene.flexible, scene.positions
    return (f.shaft, f.modulus_scale, f.element_length, (p.rb1, p.rb2, p.amb1, p.amb2),
            scene.unbalance.z)


@functools.lru_cache(maxsize=64)
def _reduced(key: tuple, cutoff_hz: float, static_modes: bool) -> FloatingModel:
    try:
        return floating_model(_station_rotor(*key), 2.0 * math.pi * cutoff_hz, static_modes,
                              MAX_MODES)
    except ShaftError:
        raise
    except ValueError as exc:
        raise ShaftError(f"flexible.mode_cutoff_hz = {cutoff_hz:g}: {exc}") from None


def bending_frequencies(scene) -> np.ndarray:
    """The free-free bending frequencies [Hz] of the scene's shaft, ascending, on the mesh the
    drop's reduction uses (every one, retained or not)."""
    return free_free_bending(assemble(_station_rotor(*_key(scene))))[0] / (2.0 * math.pi)


def drop_rotor(scene) -> FloatingModel:
    """The reduced flexible rotor of a scene with ``rotor.model = "flexible"`` (cached)."""
    f = scene.flexible
    return _reduced(_key(scene), f.mode_cutoff_hz, f.static_modes)


def mass_properties(scene) -> dict:
    """m, I_d (about the centre of mass), I_p of the scene's flexible shaft + disks."""
    f = scene.flexible
    props = rigid_properties(load_shaft(f.shaft))
    return {"rotor.mass": props["mass"], "rotor.diametral_inertia": props["I_d"],
            "rotor.polar_inertia": props["I_p"]}
