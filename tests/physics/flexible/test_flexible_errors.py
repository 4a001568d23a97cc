"""Bad flexible-rotor descriptions stop with one line naming the key and its allowed range."""
import pytest

from physics.flexible import assembly as asm
from physics.flexible import timoshenko as tim

SHAFT = (asm.ShaftSection(0.5, 0.1), asm.ShaftSection(0.3, 0.08, 0.02))


def build(**kw):
    args = dict(sections=SHAFT, z_start=-0.4)
    args.update(kw)
    return asm.FlexibleRotor(**args)


@pytest.mark.parametrize("kw, message", [
    (dict(sections=()), r"sections: allowed at least one ShaftSection"),
    (dict(sections=(asm.ShaftSection(0.0, 0.1),)),
     r"sections\[0\].length = 0.0: allowed \(0, 100\]"),
    (dict(sections=(asm.ShaftSection(0.5, 0.1), asm.ShaftSection(-0.1, 0.1))),
     r"sections\[1\].length = -0.1: allowed \(0, 100\]"),
    (dict(sections=(asm.ShaftSection(0.5, 0.1, 0.1),)),
     r"sections\[0\].inner_diameter = 0.1: allowed \[0, outer_diameter = 0.1\)"),
    (dict(sections=(asm.ShaftSection(0.5, 0.1, 0.12),)),
     r"sections\[0\].inner_diameter = 0.12: allowed \[0, 0.1\]"),
    (dict(sections=(asm.ShaftSection(0.5, float("nan")),)),
     r"sections\[0\].outer_diameter = nan: allowed \(0, 10\]"),
    (dict(sections=("shaft",)), r"sections\[0\] = 'shaft': allowed a ShaftSection"),
    (dict(disks=(asm.Disk(0.5, 10.0, 0.1, 0.2),)),
     r"disks\[0\].z = 0.5: allowed \[-0.4, 0.4\] \(on the shaft\)"),
    (dict(disks=(asm.Disk(0.0, -1.0, 0.1, 0.2),)),
     r"disks\[0\].mass = -1.0: allowed \[0, 1e\+06\]"),
    (dict(amb_planes=(-0.28,)), r"amb_planes = \(-0.28,\): allowed two stations \(or none\)"),
    (dict(retainer_planes=(-0.38, 0.45)),
     r"retainer_planes\[1\] = 0.45: allowed \[-0.4, 0.4\] \(on the shaft\)"),
    (dict(unbalance_planes=(-2.0,)), r"unbalance_planes\[0\] = -2.0: allowed \[-0.4, 0.4\]"),
    (dict(max_element_length=0.0), r"max_element_length = 0.0: allowed \(0, 100\]"),
    (dict(shear="reissner"), r"shear = 'reissner': allowed 'hutchinson', 'cowper' or None"),
])
def test_bad_rotor_description(kw, message):
    with pytest.raises(ValueError, match=message) as info:
        build(**kw)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("kw, message", [
    (dict(E=-1.0), r"material 'm': E = -1.0: allowed \(0, 1e\+16\]"),
    (dict(rho=0.0), r"material 'm': rho = 0.0: allowed \(0, 100000\]"),
    (dict(G_s=5e10), r"material 'm': Poisson ratio E/\(2 G_s\) - 1 = 1.0: allowed \(-1, 0.5\]"),
])
def test_bad_material(kw, message):
    args = dict(name="m", E=2e11, G_s=7.7e10, rho=7800.0)
    args.update(kw)
    with pytest.raises(ValueError, match=message):
        asm.Material(**args)


def test_bad_poisson_ratio():
    with pytest.raises(ValueError, match=r"material 'x': nu = 0.6: allowed \(-1, 0.5\]"):
        asm.Material.from_poisson("x", 2e11, 0.6, 7800.0)


def test_unknown_shear_method():
    with pytest.raises(ValueError, match="shear method = 'x': allowed 'hutchinson' or 'cowper'"):
        tim.shear_coefficient(0.1, 0.0, 0.3, "x")


def test_node_lookup_and_supports():
    model = asm.assemble(build(amb_planes=(-0.28, 0.28), max_element_length=0.1))
    with pytest.raises(ValueError, match=r"z = 0.123: no node there; nearest node \d+ at"):
        model.node_at(0.123)
    with pytest.raises(ValueError, match=r"support node = 99: allowed \[0, \d+\]"):
        asm.support_matrix(model, [(99, 1e6, 1e6)])
    # the planes are nodes, elements no longer than 0.1 m
    assert model.z[model.planes["amb1"]] == pytest.approx(-0.28)
    assert max(model.z[1:] - model.z[:-1]) <= 0.1 + 1e-12
