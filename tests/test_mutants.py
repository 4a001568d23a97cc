"""The physics tests fail by an assertion when a friction, damping or coupling sign is flipped
(tests/mutants.py).

Each mutant compiles its own copy of the kernels (~30 s), so one runs with the suite (the flip the
energy audit alone missed: the contact friction's sign in both its force and its power) and the
rest with ``pytest -m slow tests/test_mutants.py`` or ``python3 tests/mutants.py``.
"""
import pytest

from mutants import MUTANTS, run

BY_NAME = {m.name: m for m in MUTANTS}
SLOW = [pytest.param(m, marks=pytest.mark.slow, id=m.name) for m in MUTANTS
        if m.name != "contact_friction"]


@pytest.mark.parametrize("mutant", [pytest.param(BY_NAME["contact_friction"], id="contact_friction")]
                         + SLOW)
def test_a_flipped_sign_fails_the_energy_tests(mutant):
    death = run(mutant)
    assert death.killed, (f"no test fails by an assertion with {mutant.name} flipped "
                          f"({death.how}: {death.why}; errors {death.errors})")
