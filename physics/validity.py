"""Validity bounds of the contact laws: the penetration past which a law leaves its own
assumptions (docs/physics.md "Validity bounds"). One piece serves the metrics, the studies and
the environments.

* retainer, ``contact.law = "hertz_line"``: Johnson's approach when the Hertz half-width reaches
  0.3 r (:func:`physics.contact.half_width_approach`);
* retainer, ``contact.law = "paper"`` (K δ^e): K lumps the journal-sleeve contact, so its δ is not
  a steel approach; the bound is the load at which a steel line contact of the same geometry
  (``contact.length``, ``rotor.journal_radius``, ``contact.clearance``, E* of the bearing steel)
  reaches the same half-width (:func:`physics.contact.half_width_load`), converted to δ through
  K δ^e (:func:`physics.contact.power_law_approach`);
* stator (``effects.stator_contact``): :func:`physics.stator.penetration_bound`;
* AMB air gap (``where = "air_gap"``, without ``effects.stator_contact``): the rotor reaching
  ``amb.air_gap`` at an AMB plane meets a stator the model does not have, so the motion from then
  on is not physical; the bound is the gap itself (a radius, not a penetration).

A run is valid up to the first of these bounds it passes, whichever it is
(:func:`physics.metrics.left_validity`).
"""
from __future__ import annotations

from dataclasses import dataclass

from .contact import HALF_WIDTH_LIMIT
from .laws import contact_law
from .laws.hertz_line import line_stiffness  # noqa: F401  (re-exported)
from .stator import penetration_bound

WHERE = ("retainer", "stator", "air_gap")


@dataclass(frozen=True)
class Bound:
    """A validity bound: the penetration [m] (the AMB-plane radius for the air gap), the law's
    elastic force there [N] (None for the air gap: no law), the criterion."""
    penetration: float
    load: float | None
    criterion: str

    def to_dict(self) -> dict:
        return dict(validity_bound_um=self.penetration * 1e6, validity_bound_load_N=self.load,
                    validity_criterion=self.criterion)


def validity_bound(scene, where: str = "retainer") -> Bound:
    """The penetration bound of the rotor-sleeve law (``where = "retainer"``), of the stator
    contact (``"stator"``) or the AMB air gap of a scene without it (``"air_gap"``) in ``scene``
    (module docstring)."""
    if where not in WHERE:
        raise ValueError(f"where must be one of {WHERE}; got {where!r}")
    if where == "air_gap":
        return Bound(scene.amb.air_gap, None, "the rotor reaches amb.air_gap: the stator is not "
                     "modelled (effects.stator_contact = false)")
    lim = f"Hertz half-width b = {HALF_WIDTH_LIMIT:g} x"
    if where == "stator":
        st, g0 = scene.stator, scene.amb.air_gap
        d = penetration_bound(st.rotor_radius, g0)
        return Bound(d, st.stiffness * d, f"{lim} stator.rotor_radius (line-contact approach)")
    return Bound(*contact_law(scene.contact.law).validity_bound(scene))    # the law's own
