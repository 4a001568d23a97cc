"""The flexible rotor in the drop (rotor.model = "flexible"): energy audit with strain energy,
the stiff limit against the rigid drop, files, metrics and bad input."""
from __future__ import annotations

import re

import numpy as np
import pytest

from physics.dissipation import dissipation_check
from physics.flexible import examples
from physics.flexible.assembly import rigid_properties
from physics.flexible.shafts import drop_rotor
from physics.flexible_rotor import MAX_MODES, strain_energy
from physics.metrics import compute_metrics
from physics.model import build_model
from physics.scene import SceneError, load_scene
from physics.simulate import simulate

#: the audit's residual, relative to the energy the drop dissipates (about 1e-8 of its
#: mechanical energy); at the default tolerance the asymmetric whirl's is 1.005e-6, so the audit
#: tests run at solver.rtol = 1e-6 (the residual is the integration error: it shrinks with rtol)
AUDIT_TOL = 1e-6


def audit_residual(result) -> float:
    """max |E_mech + E_dissipated - W_external - E_mech(0)| over the energy dissipated."""
    e = result.energy()
    residual = e["mechanical"] + e["dissipated"] - e["external"] - e["mechanical"][0]
    return float(np.abs(residual).max() / e["dissipated"][-1])


#: a step budget some 20 x what these drops take: a model that blows up fails fast (a test
#: failure, not a fixture error: tests/mutants.py counts only failures)
BUDGET = {"solver.max_steps": 400_000, "solver.rtol": 1e-6}


#: the stations moved 80 mm towards RB2 (as in the asymmetric preset, within this 0.9 m shaft):
#: the rotor tilts as it drops, so the elastic modes that couple to the tilt take part
ASYMMETRIC = {"positions.rb1": -0.30, "positions.rb2": 0.44, "positions.amb1": -0.20,
              "positions.amb2": 0.36, "unbalance.z": 0.08}


@pytest.mark.parametrize("overrides", [{}, ASYMMETRIC], ids=["symmetric", "asymmetric"])
def test_energy_audit_closes_with_strain_energy(overrides):
    """The slender machine-like rotor whirling (mu = 0.5): the shaft bends most here."""
    r = simulate(load_scene("machine-flexible", {"contact.friction": 0.5, **BUDGET, **overrides}),
                 t_end=0.35)
    strain = strain_energy(r.model, r.Y)
    assert strain.max() > 1.0                     # J: the shaft does bend in the whirl
    assert audit_residual(r) <= AUDIT_TOL
    # leaving the elastic energy out of the audit opens it by far more than the tolerance
    e = r.energy()
    without = e["mechanical"] - strain + e["dissipated"] - e["external"] - e["mechanical"][0]
    assert np.abs(without).max() / e["dissipated"][-1] > 100 * AUDIT_TOL
    check = dissipation_check(r)
    assert check["ok"] and "rotor.structural_damping" in check["terms"]


def test_stiff_rotor_drop_closes_its_audit_too():
    r = simulate(load_scene("paper-flexible", BUDGET), t_end=0.3)
    assert audit_residual(r) <= AUDIT_TOL
    assert dissipation_check(r)["ok"]


def test_rigid_body_properties_and_modes_of_the_presets():
    for preset, first_hz in (("paper-flexible", 740.5), ("machine-flexible", 399.2)):
        scene = load_scene(preset)
        fm = drop_rotor(scene)
        assert fm.mass == pytest.approx(scene.rotor.mass, rel=1e-12)
        assert fm.I_d == pytest.approx(scene.rotor.diametral_inertia, rel=1e-9)
        assert fm.I_p == pytest.approx(scene.rotor.polar_inertia, rel=1e-9)
        assert fm.omega[0] / (2 * np.pi) == pytest.approx(first_hz, abs=0.1)
        assert fm.n_bending == 2 and fm.n_correction == 0      # the default: bending only
        static = drop_rotor(load_scene(preset, {"flexible.static_modes": True}))
        assert static.n_correction == 5                        # rb1, rb2, amb1, amb2, unbalance
        # the stations' elastic shapes are mirror images (a symmetric rotor)
        assert np.allclose(np.abs(fm.shape[0]), np.abs(fm.shape[1]), atol=1e-9)


def stiff_and_rigid(mu: float, t_end: float):
    """The rigid and the stiff-limit drop; the whirls reach the presets' AMB air gap, which would
    end validity (no stator in the model): a wide gap keeps them valid, the retainer physics the
    same."""
    wide = {"amb.air_gap": 3e-3}
    rigid = compute_metrics(simulate(load_scene("paper", {"contact.friction": mu, **wide}),
                                     t_end=t_end))
    stiff = compute_metrics(simulate(load_scene("paper-flexible", {     # the static modes
        "contact.friction": mu, "flexible.modulus_scale": 1000.0,      # stay at E x 1000
        "flexible.static_modes": True, **wide}), t_end=t_end))
    return rigid, stiff


def test_a_1000x_stiffer_shaft_reproduces_the_rigid_drop():
    rigid, stiff = stiff_and_rigid(0.25, 0.4)
    assert stiff["rotor"]["model"] == "flexible" and rigid["rotor"]["model"] == "rigid"
    assert stiff["first_contact_after_fault_s"] == pytest.approx(
        rigid["first_contact_after_fault_s"], rel=0.01)
    assert stiff["final_rotor_speed_rpm"] == pytest.approx(rigid["final_rotor_speed_rpm"], rel=0.01)
    for p in ("RB1", "RB2"):
        for key in ("peak_contact_force_N", "max_displacement_um", "peak_bearing_load_N"):
            assert stiff["planes"][p][key] == pytest.approx(rigid["planes"][p][key], rel=0.01), key
    assert stiff["backward_whirl"] == rigid["backward_whirl"] is False


@pytest.mark.parametrize("mus, t_end", [
    ((0.15, 0.5), 0.4),
    # the paper's study range 0.1-0.5 (spec section 2) in steps of 0.05, over the paper's 1 s drop
    pytest.param(tuple(np.round(np.arange(0.1, 0.501, 0.05), 2)), 1.0, marks=pytest.mark.slow)])
def test_the_stiff_limit_makes_the_same_whirl_decision_across_friction(mus, t_end):
    decisions = []
    for mu in mus:
        rigid, stiff = stiff_and_rigid(float(mu), t_end)
        assert stiff["backward_whirl"] == rigid["backward_whirl"], mu
        decisions.append(rigid["backward_whirl"])
    assert decisions[0] is False and decisions[-1] is True      # the sweep crosses the onset


def test_metrics_and_summary_name_the_retained_modes():
    from physics.cli import summary_table
    m = compute_metrics(simulate(load_scene("paper-flexible"), t_end=0.12))
    r = m["rotor"]
    assert r["elastic_modes"] == len(r["frequencies_hz"]) == r["bending_modes"] == 2
    assert r["frequencies_hz"][0] == pytest.approx(740.5, abs=0.1)
    assert "2 elastic modes per bending plane" in summary_table(m)


def test_the_mode_cutoff_and_static_modes_set_the_state():
    base = load_scene("paper-flexible")
    n = build_model(base).elastic_modes
    assert build_model(base.with_overrides({"flexible.static_modes": True})).elastic_modes == n + 5
    more = build_model(base.with_overrides({"flexible.mode_cutoff_hz": 6000.0}))
    assert more.elastic_modes > n
    assert build_model(base).n_state == build_model(load_scene("paper")).n_state + 4 * n


# ------------------------------------------------------------------------------ rotor files --
def write_rotor_file(path, rotor, mass_scale=1.0):
    lines = ['name = "file-rotor"', f"z_start = {rotor.z_start!r}", f'shear = "{rotor.shear}"']
    for s in rotor.sections:
        lines += ["[[sections]]", f"length = {s.length!r}", f"outer_diameter = {s.outer_diameter!r}",
                  f"inner_diameter = {s.inner_diameter!r}"]
    for d in rotor.disks:
        lines += ["[[disks]]", f"z = {d.z!r}", f"mass = {d.mass * mass_scale!r}",
                  f"I_d = {d.I_d!r}", f"I_p = {d.I_p!r}"]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def test_a_rotordrop_rotor_file_gives_the_built_in_rotor(tmp_path):
    f = write_rotor_file(tmp_path / "paper.toml", examples.paper_flexible())
    a = drop_rotor(load_scene("paper-flexible"))
    b = drop_rotor(load_scene("paper-flexible", {"flexible.shaft": f}))
    assert np.allclose(a.omega, b.omega, rtol=1e-12)


def test_a_ross_rotor_drops(tmp_path):
    from pathlib import Path
    from physics.flexible.ross_io import read_ross
    path = str(Path(__file__).resolve().parents[2] / "data" / "ross_sample_rotor.toml")
    with pytest.warns(UserWarning):
        props = rigid_properties(read_ross(path).rotor)
    with pytest.raises(SceneError, match=r"rotor\.mass = 97\.3: allowed"):
        load_scene("paper", {"rotor.model": "flexible", "flexible.shaft": path})
    scene = load_scene("paper", {
        "rotor.model": "flexible", "flexible.shaft": path, "rotor.mass": props["mass"],
        "rotor.diametral_inertia": props["I_d"], "rotor.polar_inertia": props["I_p"],
        "positions.rb1": -0.7, "positions.rb2": 0.7, "positions.amb1": -0.6,
        "positions.amb2": 0.6})
    r = simulate(scene, t_end=0.2)
    assert np.isfinite(r.Y).all() and audit_residual(r) <= AUDIT_TOL
    m = compute_metrics(r)                   # a light rotor: it may reach the AMB air gap
    assert (m["planes"]["RB1"]["peak_contact_force_N"]
            or m["planes"]["RB1"]["peak_contact_force_N_before_invalid"]) > 0.0


def test_the_mass_properties_the_error_prints_are_accepted_when_pasted_back():
    """The refusal prints the shaft's m, I_d, I_p to full precision: copying them into the scene
    (as `--set rotor.mass=...` would, from text) loads it, whatever the check's tolerance."""
    from pathlib import Path
    path = str(Path(__file__).resolve().parents[2] / "data" / "ross_sample_rotor.toml")
    where = {"rotor.model": "flexible", "flexible.shaft": path, "positions.rb1": -0.7,
             "positions.rb2": 0.7, "positions.amb1": -0.6, "positions.amb2": 0.6}
    with pytest.warns(UserWarning), pytest.raises(SceneError) as err:
        load_scene("paper", where)
    printed = dict(re.findall(r"(rotor\.\w+) = ([-+0-9.e]+)(?=[,;) ])", str(err.value).split(": ", 1)[1]))
    assert set(printed) == {"rotor.mass", "rotor.diametral_inertia", "rotor.polar_inertia"}
    with pytest.warns(UserWarning):
        scene = load_scene("paper", {**where, **{k: float(v) for k, v in printed.items()}})
    assert scene.rotor.mass == float(printed["rotor.mass"]) != 97.3     # the file's, not the paper's


@pytest.mark.parametrize("edit, words", [
    (lambda s: s.replace("inner_diameter = 0.0", "inner_diameter = 0.2", 1),
     ["flexible.shaft", "sections[0].inner_diameter = 0.2", "allowed [0, 0.07]"]),
    (lambda s: s.replace("length = 0.25", "length = 0.0", 1),
     ["flexible.shaft", "sections[0].length = 0.0", "allowed (0, 100]"]),
    (lambda s: s + '[[gear]]\nz = 0.0\n', ["unknown key(s) gear"]),
    (lambda s: s.replace("length = 0.25", 'length = "long"', 1),
     ["flexible.shaft", "sections[0].length", "a number"]),
])
def test_a_bad_rotor_file_stops_with_one_line_naming_it(tmp_path, edit, words):
    f = write_rotor_file(tmp_path / "r.toml", examples.paper_flexible())
    (tmp_path / "r.toml").write_text(edit((tmp_path / "r.toml").read_text()))
    with pytest.raises(SceneError) as err:
        load_scene("paper-flexible", {"flexible.shaft": f})
    message = str(err.value)
    assert "\n" not in message and all(w in message for w in words), message


@pytest.mark.parametrize("overrides, words", [
    ({"positions.rb2": 0.5}, ["positions.rb2 = 0.5", "allowed [-0.45, 0.45]", "on the shaft"]),
    ({"unbalance.z": -0.6}, ["unbalance.z = -0.6", "on the shaft"]),
    ({"flexible.mode_cutoff_hz": 3e4, "flexible.static_modes": True},
     ["flexible.mode_cutoff_hz", f"at most {MAX_MODES}"]),
    ({"flexible.mode_cutoff_hz": 1e6, "flexible.element_length": 0.3, "flexible.static_modes": True},
     ["flexible.mode_cutoff_hz", "elastic DOFs", "refine the mesh"]),
    ({"flexible.shaft": "granite"}, ["flexible.shaft = 'granite'", "'paper', 'machine'"]),
    ({"flexible.shaft": "missing.toml"}, ["flexible.shaft = 'missing.toml'", "cannot read"]),
    ({"rotor.mass": 90.0}, ["rotor.mass = 90: allowed 97.3"]),
    ({"effects.seal": True}, ["effects.seal", "rigid"]),
])
def test_bad_flexible_input_stops_before_anything_runs(overrides, words):
    with pytest.raises(SceneError) as err:
        load_scene("paper-flexible", overrides)
    message = str(err.value)
    assert "\n" not in message and all(w in message for w in words), message


def test_a_ross_file_with_an_unsupported_element_is_refused(tmp_path):
    f = tmp_path / "gear.toml"
    f.write_text('ross_version = "2.3.0"\n[ShaftElement_0]\nn = 0\nL = 0.5\nidl = 0.0\n'
                 'odl = 0.05\n[ShaftElement_0.material]\nE = 2.1e11\nG_s = 8.1e10\nrho = 7810\n'
                 '[GearElement_1]\nn = 1\nm = 3.0\n')
    with pytest.raises(SceneError, match=r"GearElement_1.*not supported"):
        load_scene("paper", {"rotor.model": "flexible", "flexible.shaft": str(f)})


def test_a_scene_file_finds_its_rotor_file_beside_it(tmp_path, monkeypatch):
    write_rotor_file(tmp_path / "shaft.toml", examples.machine_flexible())
    (tmp_path / "scene.toml").write_text('base = "machine-flexible"\n[flexible]\nshaft = "shaft.toml"\n')
    monkeypatch.chdir("/")
    scene = load_scene(str(tmp_path / "scene.toml"))
    assert scene.flexible.shaft == str(tmp_path / "shaft.toml")
    assert np.allclose(drop_rotor(scene).omega, drop_rotor(load_scene("machine-flexible")).omega)
