"""The how-tos' worked examples run (docs/examples/howto_effect.py, howto_contact_law.py; the
pages include their code from these files): each registers its effect or law in a temporary
registry, leaves the package's registries as they were, and checks its physics."""
import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from physics import laws
from physics.model import EFFECTS, LAYOUT
from physics.stator import restitution_of_damping

EXAMPLES = Path(__file__).resolve().parents[2] / "docs" / "examples"


def _load(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module          # numba's disk cache finds a kernel's module by name
    spec.loader.exec_module(module)
    return module


def test_the_effect_example_adds_its_load_in_a_temporary_registry():
    """A side load F at the centre of mass of the free-falling rotor (AMBs off, no unbalance):
    x = F t^2 / (2 m) until the first contact; the package's registry is unchanged and every
    registered slot keeps its index in the temporary one."""
    ex = _load("howto_effect")
    before = (EFFECTS, LAYOUT.constants())
    layout = ex.registry()
    assert (EFFECTS, LAYOUT.constants()) == before
    assert {k: v for k, v in layout.constants().items() if k in before[1] and k != "N_P"} == \
        {k: v for k, v in before[1].items() if k != "N_P"}
    F = 300.0
    t, Y, model = ex.drop(F, 0.0, 0.0, overrides={"effects.unbalance": False})
    x = Y[:, model.state_index("x")]
    assert x == pytest.approx(F * t ** 2 / (2.0 * model.param("rotor.mass")), rel=1e-9)
    _, Y0, _ = ex.drop(0.0, 0.0, 0.0, overrides={"effects.unbalance": False})
    assert np.array_equal(Y0[:, model.state_index("x")], np.zeros(len(t)))


def test_the_contact_law_example_rebounds_as_its_damping_ratio_says():
    """One impact on the linear spring-dashpot law: the restitution of a no-pull Kelvin-Voigt
    contact, exp(-zeta (pi - 2 asin zeta) / sqrt(1 - zeta^2)); without damping the impact is
    elastic and the largest penetration stores the impact energy; the registry lookup gives
    its validity bound; the package's registry is unchanged."""
    ex = _load("howto_contact_law")
    names = tuple(laws.CONTACT_LAWS)
    e, d_max, bound, _, m = ex.impact()
    zeta = 2000.0 / (2.0 * math.sqrt(2e8 * m))
    assert e == pytest.approx(restitution_of_damping(zeta), rel=1e-3)
    assert 0.0 < d_max < bound[0]
    e0, _, _, ratio0, _ = ex.impact({"contact.damping": 0.0})
    assert e0 == pytest.approx(1.0, rel=1e-6) and ratio0 == pytest.approx(1.0, rel=1e-6)
    assert tuple(laws.CONTACT_LAWS) == names and "linear" not in laws.CONTACT_LAWS
    assert "linear" in ex.registry()
