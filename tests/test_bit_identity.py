"""Reorganising the model's code (its layout, the effect modules) changes no bit of a trajectory:
the hashes of tests/data/bit_identity.json were recorded before the reorganisation (see
tests/bit_identity.py for the runs and for re-deriving them on another machine)."""
import json
from pathlib import Path

import pytest

from bit_identity import DROPS, EPISODES, drop_hashes, episode_hashes

WANT = json.loads((Path(__file__).parent / "data" / "bit_identity.json").read_text())


@pytest.mark.parametrize("name", sorted(DROPS))
def test_a_short_drop_is_bit_for_bit_unchanged(name):
    assert drop_hashes(name) == WANT["drops"][name]


@pytest.mark.parametrize("name", sorted(EPISODES))
def test_a_short_episode_is_bit_for_bit_unchanged(name):
    assert episode_hashes(name) == WANT["episodes"][name]
