"""Example flexible rotors with the paper rotor's rigid-body properties (physics/scene.py:
m = 97.3 kg, I_p = 0.39 kg m^2, I_d = 2.82 kg m^2 about the centre of mass at z = 0; AMB
planes +-0.28 m, retainer planes +-0.38 m, unbalance at z = 0).

Each is a symmetric steel shaft 0.9 m long (journals, a thicker core) plus one rigid central disk
(the impeller / motor parts) sized so that shaft + disk have exactly the paper's m, I_d, I_p.

* ``paper_flexible()``: 70 mm journals, 160 mm x 0.4 m core. First bending mode: free-free
  740.5 Hz; on 1e6 N/m AMBs (spec preset) at 10 000 rpm forward 744.1 Hz, backward 737.3 Hz,
  4.46 x the running speed: a stiff rotor, as the paper's rigid model assumes.
* ``machine_flexible()``: 50 mm journals, 140 mm x 0.3 m core. First bending mode: free-free
  399.2 Hz; on the same AMBs at 10 000 rpm forward 402.2 Hz = 2.41 x running speed (between
  1.5 and 3 x, as in many high-speed AMB machines), backward 399.6 Hz.

(Figures from tests/physics/flexible/test_flexible_examples.py, which recomputes them.)
"""
from __future__ import annotations

from .assembly import STEEL, Disk, FlexibleRotor, Material, ShaftSection, rigid_properties

PAPER_MASS, PAPER_I_P, PAPER_I_D = 97.3, 0.39, 2.82
LENGTH = 0.9


def matched_rotor(journal_diameter: float, core_diameter: float, core_length: float,
                  name: str, max_element_length: float = 0.025,
                  material: Material = STEEL) -> FlexibleRotor:
    """Symmetric journal-core-journal shaft from z = -0.45 m plus the central disk that brings
    shaft + disk to the paper's m, I_d, I_p (ValueError if the shaft alone exceeds them)."""
    journal = (LENGTH - core_length) / 2
    sections = (ShaftSection(journal, journal_diameter, 0.0, material),
                ShaftSection(core_length, core_diameter, 0.0, material),
                ShaftSection(journal, journal_diameter, 0.0, material))
    shaft = rigid_properties(FlexibleRotor(sections, z_start=-LENGTH / 2))
    disk = Disk(0.0, PAPER_MASS - shaft["mass"], PAPER_I_D - shaft["I_d"],
                PAPER_I_P - shaft["I_p"])
    return FlexibleRotor(sections, (disk,), z_start=-LENGTH / 2, amb_planes=(-0.28, 0.28),
                         retainer_planes=(-0.38, 0.38), unbalance_planes=(0.0,),
                         max_element_length=max_element_length, name=name)


def paper_flexible(material: Material = STEEL) -> FlexibleRotor:
    """The paper rotor as a stiff shaft + disk (first bending ~740 Hz)."""
    return matched_rotor(0.07, 0.16, 0.4, "paper-flexible", material=material)


def machine_flexible(material: Material = STEEL) -> FlexibleRotor:
    """Same rigid-body properties, first forward bending at 2.4 x 10 000 rpm."""
    return matched_rotor(0.05, 0.14, 0.3, "machine-flexible", material=material)
