"""Scenes: presets, TOML, dotted overrides and validation errors that name key and range."""
import json
import math
from pathlib import Path

import pytest

from physics import SceneError, load_scene, parameter_table, preset_names
from physics.scene import scene_from_toml

SPEC_VALUES = Path(__file__).resolve().parents[1] / "data" / "spec_values.json"

PUBLIC_KEYS = ["contact.friction", "contact.stiffness", "support.stiffness", "support.damping",
               "unbalance.mass", "rotor.speed_rpm", "amb.off_time", "solver.rtol",
               "effects.gravity", "effects.unbalance", "effects.gyroscopic", "effects.amb",
               "effects.retainer_bearing", "effects.ehl_film", "effects.bearing_friction",
               "effects.housing", "effects.sleeve_inertia", "effects.friction"]


def test_public_keys_exist_with_units_and_ranges():
    rows = {r["key"]: r for r in parameter_table()}
    for key in PUBLIC_KEYS:
        assert key in rows, key
        assert rows[key]["unit"] and rows[key]["allowed"]
    assert rows["effects.retainer_bearing"]["allowed"] == "rigid|linear|sopanen_mikkola"
    assert rows["effects.friction"]["allowed"] == "none|paper|kinematic"


def test_presets_paper_and_spec_hold_the_paper_base_case():
    assert {"paper", "spec"} <= set(preset_names())
    for name in ("paper", "spec"):
        s = load_scene(name)
        assert s.name == name
        assert (s.contact.friction, s.support.stiffness, s.support.damping) == (0.25, 5e7, 5000.0)
        assert (s.rotor.mass, s.rotor.speed_rpm, s.contact.clearance) == (97.3, 10000.0, 300e-6)


def _typed(values: dict) -> dict:
    return {k: (type(v).__name__, v) for k, v in values.items()}


def test_spec_preset_is_frozen_at_the_spec_values():
    """Every [P]/[A] value of spec §2-4 as written there, and solver.rtol = 1e-5 as chosen by the
    accuracy study (docs/accuracy.md), against a literal snapshot: a changed default changes the
    ``spec`` preset and fails here. Change tests/data/spec_values.json by hand, with the spec."""
    frozen = json.loads(SPEC_VALUES.read_text())
    assert _typed(load_scene("spec").flat()) == _typed(frozen)       # values and types, exactly


def test_dotted_overrides_and_string_values_are_typed():
    s = load_scene("paper", {"contact.friction": "0.4", "effects.housing": "false",
                             "bearing.balls": "12", "effects.friction": "kinematic"})
    assert s.contact.friction == 0.4 and s.effects.housing is False
    assert s.bearing.balls == 12 and s.effects.friction == "kinematic"
    assert load_scene("paper").contact.friction == 0.25            # immutable original


@pytest.mark.parametrize("key, value, words", [
    ("rotor.mass", -1.0, ["rotor.mass", "[0.001, 100000] kg"]),
    ("contact.friction", 1.5, ["contact.friction", "[0, 1]"]),
    ("contact.friction", float("nan"), ["contact.friction", "finite"]),
    ("support.stiffness", math.inf, ["support.stiffness", "finite"]),
    ("effects.friction", "coulomb", ["effects.friction", "none, paper, kinematic"]),
    ("effects.housing", "maybe", ["effects.housing", "true or false"]),
    ("bearing.balls", 7.5, ["bearing.balls"]),
    ("contact.fricton", 0.3, ["contact.fricton", "friction"]),
    ("nosuch.key", 1, ["nosuch.key", "contact"]),
    ("friction", 1, ["friction", "GROUP.NAME"]),
])
def test_bad_values_raise_errors_naming_key_and_allowed_range(key, value, words):
    with pytest.raises(SceneError) as exc:
        load_scene("paper", {key: value})
    for w in words:
        assert w in str(exc.value)


def test_cross_parameter_rules():
    with pytest.raises(SceneError, match="positions.amb1"):
        load_scene("paper", {"positions.amb1": 0.5})
    with pytest.raises(SceneError, match="ball_diameter"):
        load_scene("paper", {"bearing.ball_diameter": 0.2})


def test_toml_round_trip_and_base_preset(tmp_path):
    s = load_scene("paper", {"contact.friction": 0.33, "effects.retainer_bearing": "linear"})
    path = tmp_path / "mine.toml"
    path.write_text(s.to_toml())
    back = load_scene(str(path))
    assert back.flat() == s.flat()
    derived = scene_from_toml('base = "paper"\n[contact]\nfriction = 0.45\n')
    assert derived.contact.friction == 0.45 and derived.support.stiffness == 5e7


def test_malformed_or_wrong_toml_is_a_clear_error(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[contact\nfriction = 0.3\n")
    with pytest.raises(SceneError, match="malformed TOML"):
        load_scene(str(bad))
    with pytest.raises(SceneError, match="contact.friction"):
        scene_from_toml("[contact]\nfriction = 2.0\n")
    with pytest.raises(SceneError, match="must be a table"):
        scene_from_toml("contact = 3\n")
    with pytest.raises(SceneError, match="neither a preset"):
        load_scene("no_such_scene")
