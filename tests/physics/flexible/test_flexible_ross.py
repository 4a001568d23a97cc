"""rotordrop's flexible rotor against ROSS 2.3.0 on the same rotor
(tests/data/ross_sample_rotor.toml, saved by ROSS's Rotor.save).

Reference numbers: tests/data/ross_reference.json, regenerated in a separate venv by

    /tmp/rossenv/bin/python benchmarks/ross_reference.py

(see that script's docstring). If ``import ross`` works here, ROSS is also run live.
"""
import importlib.util
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from physics.flexible import assembly as asm
from physics.flexible import modal
from physics.flexible import ross_io

DATA = Path(__file__).resolve().parents[2] / "data"
TOML = DATA / "ross_sample_rotor.toml"
REF = json.loads((DATA / "ross_reference.json").read_text())


ROTORS = tuple(REF["rotors"])


def imported(name="ross_sample_rotor"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ross_io.read_ross(DATA / f"{name}.toml")


def rotordrop_frequencies(imp, speeds, n=4, omega_cut=None):
    """Forward/backward whirl frequencies of the imported rotor on ROSS's (skipped) bearings,
    full FE model, or reduced with bending modes below ``omega_cut``."""
    model = asm.assemble(imp.rotor)
    S = asm.support_matrix(model, [(model.node_at(s.z), s.kxx, s.kyy) for s in imp.supports])
    x, y = modal.model_whirl_dofs(model)
    if omega_cut is None:
        return modal.campbell(model.M, model.G, model.K + S, speeds, n, x, y)
    # static correction modes at the bearing nodes, where the support forces act
    red = modal.reduce(model, omega_cut=omega_cut,
                       extra_nodes=tuple(model.node_at(s.z) for s in imp.supports))
    T = red.T
    return modal.campbell(red.M, red.G, red.K + T.T @ S @ T, speeds, n, x, y, T=T)


def test_import_reads_shaft_disks_and_reports_bearings():
    with pytest.warns(UserWarning, match=r"skipped 2 bearing/seal element\(s\) \(Bearing 0, "
                                         r"Bearing 1\): rotordrop models its supports itself"):
        imp = ross_io.read_ross(TOML)
    r = imp.rotor
    assert imp.ross_version == "2.3.0"
    assert len(r.sections) == 6 and r.length == pytest.approx(1.5)
    assert r.shear == "cowper"
    assert [d.z for d in r.disks] == pytest.approx([0.5, 1.0])
    assert r.disks[0].mass == pytest.approx(32.58972765304033)
    assert [(s.node, s.kxx, s.kyy) for s in imp.supports] == [(0, 1e6, 1e6), (6, 1e6, 1e6)]
    assert r.sections[0].material.E == 211e9 and r.sections[0].material.G_s == 81.2e9


@pytest.mark.parametrize("name", ROTORS)
@pytest.mark.parametrize("i", range(len(REF["speeds"])))
def test_frequencies_match_ross_reference(name, i):
    """First 4 forward and 4 backward whirl frequencies at 0 and 10 000 rpm within 0.5 % of
    ROSS 2.3.0 (measured: ~1e-13, the same element formulation), for the slender sample rotor
    and for a thick hollow one where the shear coefficient matters (with Hutchinson's instead of
    Cowper's kappa its 4th mode moves by more than 0.5 %)."""
    speed, ref = REF["speeds"][i], REF["rotors"][name][i]
    ours = rotordrop_frequencies(imported(name), [speed])
    for key in ("forward", "backward"):
        err = ours[key][0] / np.array(ref[key]) - 1
        assert np.all(np.abs(err) < 0.005), (key, err)
        assert np.all(np.abs(err) < 1e-8), (key, err)


def test_thick_rotor_is_sensitive_to_the_shear_coefficient():
    """The thick hollow rotor's check has teeth: the other shear coefficient (Hutchinson's)
    moves its frequencies by more than the 0.5 % tolerance."""
    from dataclasses import replace
    imp = imported("ross_thick_hollow_rotor")
    other = replace(imp, rotor=replace(imp.rotor, shear="hutchinson"))
    ref = REF["rotors"]["ross_thick_hollow_rotor"][0]["forward"]
    err = rotordrop_frequencies(other, [0.0])["forward"][0] / np.array(ref) - 1
    assert np.max(np.abs(err)) > 0.005, err


@pytest.mark.parametrize("name", ROTORS)
def test_reduced_model_matches_ross_reference(name):
    """The modal reduction (free-free bending modes below 3 x the highest compared frequency
    + static correction modes at the bearing nodes) stays within 0.5 % of ROSS at running
    speed."""
    speed, ref = REF["speeds"][1], REF["rotors"][name][1]
    omega_cut = 3.0 * max(ref["forward"] + ref["backward"])
    ours = rotordrop_frequencies(imported(name), [speed], omega_cut=omega_cut)
    for key in ("forward", "backward"):
        err = ours[key][0] / np.array(ref[key]) - 1
        assert np.all(np.abs(err) < 0.005), (key, err)


def test_ross_live():
    """ROSS itself (only where it is installed): the committed numbers are what it computes."""
    pytest.importorskip("ross")
    path = Path(__file__).resolve().parents[3] / "benchmarks" / "ross_reference.py"
    spec = importlib.util.spec_from_file_location("ross_reference", path)
    ref_mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ref_mod)
    for name, build in ref_mod.ROTORS.items():
        rotor = build()
        for speed, ref in zip(REF["speeds"], REF["rotors"][name]):
            live = ref_mod.whirl_frequencies(rotor, speed)
            for key in ("forward", "backward"):
                assert live[key] == pytest.approx(ref[key], rel=1e-9)


BASE = TOML.read_text()


def variant(tmp_path, text):
    p = tmp_path / "rotor.toml"
    p.write_text(text)
    return p


@pytest.mark.parametrize("edit, message", [
    (lambda t: t.replace("idr = 0.0\nodr = 0.05\nn = 3", "idr = 0.0\nodr = 0.06\nn = 3", 1),
     r"'ShaftElement_Shaft Element 3' is tapered .*only cylindrical elements"),
    (lambda t: t.replace("n = 1\naxial_force = 0", "n = 1\naxial_force = 1000.0", 1),
     r"'ShaftElement_Shaft Element 1' has axial_force = 1000.0: not supported"),
    (lambda t: t + '\n["GearElement_Gear 0"]\nn = 2\nm = 1.0\n',
     r"element 'GearElement_Gear 0' of type GearElement: not supported"),
    (lambda t: t.replace('["DiskElement_Disk 1"]\nn = 4', '["DiskElement_Disk 1"]\nn = 9'),
     r"'DiskElement_Disk 1' at node n = 9: allowed \[0, 6\]"),
    (lambda t: t.replace('shear_method_calc = "cowper"\ntag = "Shaft Element 5"',
                         'shear_method_calc = "hutchinson"\ntag = "Shaft Element 5"'),
     r"shaft elements mix shear options"),
    (lambda t: t.replace("n = 5\naxial_force", "n = 4\naxial_force"),
     r"has n = 4: rotordrop takes one shaft line"),
    (lambda t: "ross_version = \"2.3.0\"\n", r"no ShaftElement tables"),
    (lambda t: t.replace("[parameters]", "[parameters"), r"not a readable ROSS TOML file"),
])
def test_import_refuses_what_it_cannot_take(tmp_path, edit, message):
    text = edit(BASE)
    assert text != BASE
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError, match=message) as info:
            ross_io.read_ross(variant(tmp_path, text))
    assert "\n" not in str(info.value)


def test_point_mass_is_a_disk_without_inertia(tmp_path):
    text = BASE + '\n["PointMass_pm"]\nn = 3\nm = 2.5\ntag = "pm"\n'
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        imp = ross_io.read_ross(variant(tmp_path, text), z_start=-0.75,
                                retainer_planes=(-0.7, 0.7))
    assert imp.rotor.disks[-1] == asm.Disk(0.0, 2.5, 0.0, 0.0)
    assert imp.node_z[0] == -0.75 and imp.rotor.retainer_planes == (-0.7, 0.7)


@pytest.mark.filterwarnings("ignore:.*skipped 2 bearing")
def test_ross_hutchinson_option_is_read_with_the_published_formula_and_warns(tmp_path):
    text = BASE.replace('shear_method_calc = "cowper"', 'shear_method_calc = "hutchinson"')
    with pytest.warns(UserWarning, match=r"shear_method_calc = 'hutchinson': ROSS 2.3.0's kappa "
                                         r"is Hutchinson's divided by \(1 \+ nu\)"):
        imp = ross_io.read_ross(variant(tmp_path, text))
    assert imp.rotor.shear == "hutchinson"
