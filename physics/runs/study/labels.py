"""How a parameter study names what it shows: the per-plane KPIs of a sweep cell and the grid
values, shared by the tables and CSV of :mod:`physics.runs.study.parametric` and the figures of
:mod:`physics.runs.study.report`."""
from __future__ import annotations

PLANE_KPIS = {"whirl_revolutions": "whirl revolutions", "peak_contact_force_N": "peak contact force [N]",
              "max_displacement_um": "max displacement [µm]",
              "peak_bearing_load_N": "peak retainer-bearing load [N]",
              "friction_heat_J": "contact friction heat [J]",
              "max_contact_pressure_MPa": "max ball-race contact pressure [MPa]"}


def value_label(value) -> str:
    """A grid value as the table and the plot show it (``2790``, ``1e+05``, ``kinematic``)."""
    return f"{value:g}" if isinstance(value, float) else str(value)
