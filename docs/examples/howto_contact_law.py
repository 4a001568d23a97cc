"""A contact law of one's own: the worked example of docs/howto/contact-law.md
(tests/physics/test_howto_examples.py runs it).

The law: a linear spring-dashpot that never pulls, F = max(K δ + C δ̇, 0), with K =
``contact.stiffness`` [N/m] and C = ``contact.damping``. Like every contact law it is one module
with a name, its force and potential kernels, its validity bound and its metrics hook; here it
is registered in a temporary registry (a copy of ``physics.laws.CONTACT_LAWS`` with it added), so
nothing of the package changes, and one impact is run on it: the rotor's mass share at a
retainer plane falling through the clearance onto an immovable sleeve.
"""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from physics import laws, load_scene
from physics.amb import weight_shares
from physics.jit import njit, njit_inline
from physics.laws.hertz_line import HALF_WIDTH_LIMIT, half_width_load, line_stiffness
from physics.model import LAYOUT

# --8<-- [start:law]
NAME = "linear"
DOC = "a linear spring-dashpot that never pulls: F = max(K delta + C delta', 0)"


@njit_inline
def force(delta, ddelta, P):
    """(F_r, elastic part) at penetration delta > 0 and its rate."""
    elastic = P[P_KC] * delta
    f = elastic + P[P_CMAX] * ddelta
    return (f if f > 0.0 else 0.0), elastic


@njit_inline
def potential(delta, P):
    """Elastic energy ½ K δ² stored at penetration delta."""
    return 0.5 * P[P_KC] * delta * delta if delta > 0.0 else 0.0


def validity_bound(scene) -> tuple[float, float, str]:
    """(penetration, load, criterion): the load at which a steel line contact of the same
    geometry reaches the half-width bound, through K δ (like the paper law's)."""
    load = half_width_load(scene.rotor.journal_radius, scene.contact.clearance,
                           line_stiffness(scene))
    return (load / scene.contact.stiffness, load,
            f"load at which a steel line contact reaches Hertz half-width b ="
            f" {HALF_WIDTH_LIMIT:g} x rotor.journal_radius, through K delta")


def tangent_stiffness(scene, load: float) -> float:
    """dF/dδ = K at any load (the metrics' contact period)."""
    return scene.contact.stiffness
# --8<-- [end:law]


# --8<-- [start:registry]
def registry() -> dict:
    """A temporary registry: the registered contact laws and this one (the package's registry
    is left as it is); this module's kernels read the layout's constants."""
    LAYOUT.bind(globals())
    this = SimpleNamespace(NAME=NAME, DOC=DOC, force=force, potential=potential,
                           validity_bound=validity_bound, tangent_stiffness=tangent_stiffness)
    return {**laws.CONTACT_LAWS, NAME: this}
# --8<-- [end:registry]


@njit
def _impact(P, m, v0, h):
    """A mass m meeting the law at δ = 0 with speed v0: RK4 until it leaves; (the rebound
    speed, the largest penetration, the elastic energy at it over ½ m v0²)."""
    d, v, d_max, e_max = 0.0, v0, 0.0, 0.0
    while True:
        a1 = -force(d, v, P)[0] / m
        a2 = -force(d + 0.5 * h * v, v + 0.5 * h * a1, P)[0] / m
        a3 = -force(d + 0.5 * h * v + 0.25 * h * h * a1, v + 0.5 * h * a2, P)[0] / m
        a4 = -force(d + h * v + 0.5 * h * h * a2, v + h * a3, P)[0] / m
        d, v = d + h * v + h * h / 6.0 * (a1 + a2 + a3), v + h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4)
        if d > d_max:
            d_max, e_max = d, potential(d, P)
        if d <= 0.0 and v < 0.0:
            return -v, d_max, e_max / (0.5 * m * v0 * v0)


# --8<-- [start:impact]
def impact(overrides: dict | None = None, plane: int = 0):
    """One impact on the law: the rotor's mass share at a retainer plane arriving at the
    free-fall speed through the clearance. Returns (restitution, largest penetration [m],
    the law's validity bound from the registry, the elastic energy at the largest penetration
    over the impact energy)."""
    law = registry()[NAME]
    scene = load_scene("paper", {"contact.stiffness": 2e8, "contact.damping": 2000.0,
                                 **(overrides or {})})
    P = np.zeros(LAYOUT.params.size)
    P[LAYOUT.params["contact.stiffness"]] = scene.contact.stiffness
    P[LAYOUT.params["contact.damping"]] = scene.contact.damping
    m = abs(weight_shares(scene.rotor.mass, scene.positions.rb1, scene.positions.rb2)[plane])
    v0 = math.sqrt(2.0 * scene.world.gravity * scene.contact.clearance)
    k, c = scene.contact.stiffness, scene.contact.damping
    h = 2.0 * math.pi * math.sqrt(m / k) / 2000.0
    v1, d_max, energy_ratio = _impact(P, m, v0, h)
    return v1 / v0, d_max, law.validity_bound(scene), energy_ratio, m
# --8<-- [end:impact]


if __name__ == "__main__":
    e, d_max, bound, ratio, m = impact()
    print(f"restitution {e:.4f}, largest penetration {d_max * 1e6:.2f} µm"
          f" (validity bound {bound[0] * 1e6:.1f} µm)")
