"""Per-element dissipation: the power each damper, drag and friction takes out of the motion.

Every dissipative element of the model must have a power >= 0 at every instant: a dashpot
c v^2, a contact's normal damping (F_r - F_el) d(delta)/dt, a friction force times the sliding
velocity of its contact points, a drag torque times the speed it brakes. The energy audit
(``Result.energy``: E_mech + E_dissipated - W_external = const) cannot see a sign error in one of
these on its own, since it integrates the same power the kernel applies; together the two are a
check: the audit ties each applied force to its power, and this module ties each power's sign to
its physics. The kernel writes the powers into its diagnostics (``A_P*`` of physics/model.py);
they are read here at the output samples.

The paper's slip law (``effects.friction = "paper"``, eq. 19 as printed) drives the friction by
Omega - omega_s instead of by the contact's sliding velocity r Omega + e_t - R omega_s; with
r != R its contact friction power turns negative and it creates energy. Every other law and
element of the model dissipates.
"""
from __future__ import annotations

import numpy as np

from .model import (A_FX_PDAMP, A_PBDAMP, A_PCDAMP, A_PDRAG, A_PFRIC, A_PSUPPORT, A_ST_PDAMP,
                    A_ST_PFRIC, A_ST_PMOUNT, N_AUX_PLANE, PLANES)
from .results import AMB_PLANES, Result

#: per retainer plane: element -> diagnostics column (offset within the plane's block)
PLANE_TERMS = {"contact_friction": A_PFRIC, "contact_damping": A_PCDAMP,
               "bearing_damping": A_PBDAMP, "bearing_drag": A_PDRAG,
               "support_damping": A_PSUPPORT}
#: per AMB plane (rotor-stator contact): element -> first column (AMB1; AMB2 is the next one)
STATOR_TERMS = {"stator_damping": A_ST_PDAMP, "stator_friction": A_ST_PFRIC,
                "stator_mount_damping": A_ST_PMOUNT}
#: a power below -ROUNDOFF x (the largest |power| of any element in the run) is negative beyond
#: round-off. Each power is a product of a force and a velocity whose signs the law ties
#: together, so a correct element gives >= 0 exactly or within a few ulps of its terms; the
#: scale is the run's, not the element's: a sleeve that rolls without slip has a friction power
#: that is all round-off (+-1e-13 W under a 20 N friction force)
ROUNDOFF = 1e-9


def dissipation_powers(result: Result) -> dict[str, np.ndarray]:
    """``{"RB1.contact_friction": P(t), ..., "AMB2.stator_friction": P(t)}`` [W] at the output
    samples: the power each dissipative element takes out of the mechanical energy."""
    out = {}
    for k, p in enumerate(PLANES):
        for name, j in PLANE_TERMS.items():
            out[f"{p}.{name}"] = result.aux[:, k * N_AUX_PLANE + j]
    for k, p in enumerate(AMB_PLANES):
        for name, j in STATOR_TERMS.items():
            out[f"{p}.{name}"] = result.aux[:, j + k]
    if result.model.elastic_modes:               # a flexible rotor's structural damping
        out["rotor.structural_damping"] = result.aux[:, A_FX_PDAMP]
    return out


def created_energy(t: np.ndarray, power: np.ndarray) -> float:
    """Energy [J] an element created over the samples ``t``: the trapezoidal integral of its
    negative power (0.0 for an element that dissipates)."""
    neg = np.minimum(power, 0.0)
    return 0.0 - float(np.sum(0.5 * (neg[1:] + neg[:-1]) * np.diff(t))) if len(t) > 1 else 0.0


def dissipation_check(result: Result) -> dict:
    """Each element's lowest power and the energy it created, and whether every element
    dissipates (``ok``): ``{"ok", "negative": [names], "created_energy_J": total,
    "terms": {name: {"min_power_W", "created_energy_J"}}}``."""
    terms, negative = {}, []
    powers = dissipation_powers(result)
    scale = max((float(np.abs(p).max()) for p in powers.values() if len(p)), default=0.0)
    for name, power in powers.items():
        lo = float(power.min()) if len(power) else 0.0
        terms[name] = dict(min_power_W=lo, created_energy_J=created_energy(result.t, power))
        if lo < -ROUNDOFF * scale:
            negative.append(name)
    return dict(ok=not negative, negative=negative,
                created_energy_J=sum(terms[n]["created_energy_J"] for n in negative), terms=terms)
