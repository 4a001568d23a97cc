"""The packed arrays' layout is built from the effects' declarations (physics/layout.py): every
slot has one owner, no gaps; the names the effects declare resolve to the constants the kernels
read; names above physics resolve, and an unknown name is a clear error naming it."""
import numpy as np
import pytest

from physics import model as M
from physics.layout import Layout, Slots
from physics.scene import load_scene


def test_every_table_is_contiguous_without_overlaps():
    for table in M.LAYOUT.tables():
        table.check()
        covered = np.zeros(table.size, dtype=int)
        for _, first, width in table.spans():
            covered[first:first + width] += 1
        assert (covered == 1).all(), table.what
    assert (M.N_P, M.N_I, M.N_U, M.N_AUX) == (M.LAYOUT.params.size, M.LAYOUT.index.size,
                                              M.LAYOUT.controls.size, M.LAYOUT.aux.size)
    assert M.N_PLANE_IDX == M.LAYOUT.plane.size and M.N_AUX_PLANE == M.LAYOUT.plane_aux.size
    assert M.LAYOUT.index.width("planes") == 2 * M.N_PLANE_IDX
    assert M.LAYOUT.aux["planes"] == 0                  # the planes' diagnostics come first


def test_the_effects_declarations_build_the_same_layout_again():
    again = Layout.build(M.EFFECTS)
    for a, b in zip(again.tables(), M.LAYOUT.tables()):
        assert a.spans() == b.spans()


def test_each_effect_declares_its_scene_keys_and_they_exist():
    scene = load_scene("paper")
    for effect in M.EFFECTS:
        for key in effect.SCENE_KEYS:
            group, field = key.split(".")
            assert hasattr(scene, group), (effect, key)
            assert field == "*" or hasattr(getattr(scene, group), field), (effect, key)


@pytest.mark.parametrize("overrides", [
    {}, {"effects.amb": "actuator", "effects.thermal": True, "effects.stator_contact": True,
         "effects.semi_active_damper": True, "sensor.delay": 1e-4},
    {"effects.retainer_bearing": "rigid", "effects.housing": False,
     "effects.sleeve_inertia": False, "effects.unbalance": False}])
def test_every_declared_name_resolves_and_the_state_indices_point_at_their_states(overrides):
    model = M.build_model(load_scene("paper", overrides))
    for name in M.LAYOUT.params:
        assert model.param_index(name) == M.LAYOUT.params[name]
        assert isinstance(model.param(name), float)
    for name in M.LAYOUT.controls:
        assert 0 <= model.control_index(name) < M.N_U
    for name in M.LAYOUT.index:
        if name.startswith("flag."):
            model.flag(name[5:])
    for name in M.rotor.STATE_NAMES:                # rotor states: index slot -> name
        assert model.names[model.I[M.LAYOUT.index["state." + name]]] == name
    for k, plane in enumerate(M.PLANES):
        for j in M.LAYOUT.plane:
            i = model.I[M.I_PLANES + k * M.N_PLANE_IDX + M.LAYOUT.plane[j]]
            assert (i < 0) == (f"{plane}.{j}" not in model.names)
            if i >= 0:
                assert model.names[i] == f"{plane}.{j}"
    assert len(set(model.names)) == model.n_state


def test_the_kernels_constants_are_the_declared_slots():
    assert M.P_M == M.LAYOUT.params["rotor.mass"]
    assert M.P_Z_RB2 == M.P_Z_RB1 + 1 and M.P_Z_AMB2 == M.P_Z_AMB1 + 1
    assert M.P_AMB_IFF2 == M.P_AMB_IFF1 + 1 and M.U_CS2 == M.U_CS1 + 1
    assert M.P_TH_B - M.P_TH_C == len(M.thermal.PARAM_NAMES) - 1
    assert M.LAYOUT.controls.width("amb.current_command") == 4 == len(M.AMB_AXES)
    assert M.A_ST_PMOUNT + 2 == M.A_STF        # the rhs zeroes the stator's slots up to A_STF
    assert M.A_FX_PDAMP + 1 == M.N_AUX         # ... and the flexible rotor's, A_STF on
    assert M.P_Z_AMB1 == M.P_Z_RB1 + M.ST_AMB1 and M.P_Z_UB == M.P_Z_RB1 + M.ST_UB
    for s, name in enumerate(M.flexible_rotor.STATIONS):    # the station block's order
        assert M.LAYOUT.params[{"unb1": "unbalance.z"}.get(name, name + ".z")] == M.P_Z_RB1 + s


def test_name_lookups_above_physics():
    model = M.build_model(load_scene("paper", {"effects.amb": "actuator"}))
    y = np.zeros(model.n_state)
    y[model.state_index("x")], y[model.state_index("a")] = 1e-5, 1e-4
    z1, z2 = model.amb_z()
    assert model.sensor_positions(y) == pytest.approx([1e-5 + z1 * 1e-4, 0.0,
                                                       1e-5 + z2 * 1e-4, 0.0])
    assert model.retainer_z() == (model.scene.positions.rb1, model.scene.positions.rb2)
    assert model.has_ambs and model.has_ball_bearing
    assert list(model.rotor_axis_indices()) == [model.state_index(n) for n in "xyab"]
    assert model.sizes == {"P": M.N_P, "I": M.N_I, "U": M.N_U, "aux": M.N_AUX}


@pytest.mark.parametrize("lookup, name", [
    (lambda m: m.state_index("rotor.nonsense"), "rotor.nonsense"),
    (lambda m: m.state_index("RB1.temperature"), "RB1.temperature"),      # thermal is off
    (lambda m: m.param("amb9.z"), "amb9.z"),
    (lambda m: m.param_index("rotor.mas"), "rotor.mas"),
    (lambda m: m.control_index("amb.powr"), "amb.powr"),
    (lambda m: m.flag("warp_drive"), "flag.warp_drive")])
def test_an_unknown_name_is_an_error_naming_it(lookup, name):
    model = M.build_model(load_scene("paper"))
    with pytest.raises(KeyError, match=f"unknown .*'{name}'"):
        lookup(model)


def test_slots_refuse_duplicates_late_names_and_bad_widths():
    s = Slots("thing")
    assert s.add("a") == 0 and s.add("b", 3) == 1 and s.add_each("c", "d") == (4, 5)
    assert s.block("e", "f") == 6 and s.size == 8
    with pytest.raises(ValueError, match="'a' is declared twice"):
        s.add("a")
    with pytest.raises(ValueError, match="width"):
        s.add("g", 0)
    s.freeze()
    with pytest.raises(RuntimeError, match="'h' comes too late"):
        s.add("h")
    with pytest.raises(KeyError, match="unknown thing 'zz'; the things are: a, b, c"):
        s["zz"]
