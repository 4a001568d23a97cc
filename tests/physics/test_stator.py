"""Rotor-stator contact at the AMB planes (effects.stator_contact, physics/stator.py)."""
import hashlib
import math

import numpy as np
import pytest

from physics import load_scene, simulate
from physics.contact import line_deflection
from physics.metrics import compute_metrics
from physics.model import build_model
from physics.scene import Scene
from physics.stator import damping_coefficient, damping_ratio, restitution_of_damping, stator_force

from helpers import energy_residual

# sha256 of Result.Y (float64, C order) of simulate(load_scene("paper", {"contact.friction": mu,
# "effects.friction": "paper"}), t_end=0.3) (the paper slip law was then the default), computed on the `ensembles` branch at bd3cbbd (its PI step control, beta 0.06),
# before stator contact, the contact laws, the validity metrics and the thermal model existed. The new effects are off in the paper preset: the state history must not move
# by one bit (a different CPU / numba / LLVM build could change the last bits; then re-derive the
# hashes from main's code the same way before trusting a failure).
PAPER_STATE_SHA256 = {
    0.25: "c8f4312d5b60c638eb301af92127795577658325cbee9037938f4cad22d604b7",
    0.45: "1cd2f7c55088f5d6bc72a5bd65d8dbb1502cd42e03f720eceba2f1ffb968928a",
}


@pytest.mark.parametrize("mu", sorted(PAPER_STATE_SHA256))
def test_paper_drop_is_bit_for_bit_unchanged_with_the_new_effects_off(mu):
    r = simulate(load_scene("paper", {"contact.friction": mu, "effects.friction": "paper"}),
                 t_end=0.3)
    assert hashlib.sha256(np.ascontiguousarray(r.Y).tobytes()).hexdigest() == PAPER_STATE_SHA256[mu]
    assert not r.stator_force("AMB1").any()


def test_stator_contact_adds_no_state_and_its_mount_four_per_plane():
    fixed = simulate(load_scene("paper", {"effects.stator_contact": True,
                                          "effects.stator_mount": False}), t_end=0.12)
    off = simulate(load_scene("paper"), t_end=0.12)
    assert fixed.model.names == off.model.names
    mounted = simulate(load_scene("paper", {"effects.stator_contact": True}), t_end=0.12)
    assert mounted.model.names == off.model.names + tuple(
        f"{p}.stator_{n}" for p in ("AMB1", "AMB2") for n in ("x", "y", "vx", "vy"))
    # no stator contact in this drop: the mounted stators stay at rest
    assert not mounted.stator("AMB1").any()


def test_a_mounted_stator_shares_a_whip_with_its_mount():
    """A soft support lets the rotor reach the stators in a whirl. On its mount each stator
    moves, the pair's forces are equal and opposite (the audit closes with the mount's energy),
    and the stator moves by about F / k_m: the contact and the mount share the force."""
    scene = load_scene("paper", {"effects.stator_contact": True, "support.stiffness": 5e6,
                                 "contact.friction": 0.5, "solver.rtol": 1e-7})
    r = simulate(scene, t_end=0.5)
    f = r.stator_force("AMB1")
    assert f.max() > 1000.0
    q = np.hypot(*r.stator("AMB1").T)
    k_m = scene.stator.mount_stiffness
    assert q.max() == pytest.approx(f.max() / k_m, rel=0.5)         # quasi-static share
    res, e = energy_residual(r)
    assert res.max() < 1e-5 * e["dissipated"][-1]


def point_mass_rebound(m, k, c, gap, v0, g=0.0, h=1e-7):
    """Exit speed / impact speed of a mass m hitting the fixed stator radially at v0 (RK4 on
    stator_force, pushed outward by g; no friction), measured when it is back inside the gap."""
    def acc(x, v):
        return stator_force(x, 0.0, v, 0.0, 0.0, gap, k, c, 0.0, 0.045, 1e-3)[0] / m + g

    x, v = gap, v0
    while True:
        k1x, k1v = v, acc(x, v)
        k2x, k2v = v + 0.5 * h * k1v, acc(x + 0.5 * h * k1x, v + 0.5 * h * k1v)
        k3x, k3v = v + 0.5 * h * k2v, acc(x + 0.5 * h * k2x, v + 0.5 * h * k2v)
        k4x, k4v = v + h * k3v, acc(x + h * k3x, v + h * k3v)
        x += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
        v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        if x < gap:
            return -v / v0


@pytest.mark.parametrize("e", [0.2, 0.5, 0.9])
def test_rigid_stator_rebounds_a_point_mass_with_the_restitution_coefficient(e):
    """A mass m hitting the immovable stator radially at v0 (no friction, no gravity) leaves with
    e v0: the damping from damping_coefficient() and the no-pull force law."""
    m, k = 48.65, 2e9
    assert point_mass_rebound(m, k, damping_coefficient(k, m, e), 600e-6, 0.1) == pytest.approx(e, rel=2e-3)
    assert restitution_of_damping(damping_ratio(e)) == pytest.approx(e, rel=1e-9)


def test_a_rotor_dropped_straight_onto_the_stator_rebounds_like_the_point_mass():
    """Full model, limit case: no spin, no unbalance, retainer gap 3 mm (never reached): the rotor
    falls through the 600 µm air gap and hits both stators at once, its lever-rule share m/2 on
    each. Its rebound ratio (at the gap crossings) equals the point mass's under gravity (0.489;
    0.5 without gravity)."""
    ov = {"effects.stator_contact": True, "effects.stator_mount": False,     # a fixed stator
          "contact.clearance": 0.003, "rotor.speed_rpm": 0.0,
          "effects.unbalance": False, "solver.output_rate": 1e6, "solver.rtol": 1e-8}
    r = simulate(load_scene("paper", ov), t_end=0.125)
    gap = r.model.scene.amb.air_gap
    rad, vy = np.hypot(*r.amb_orbit("AMB1").T), r.state("vy")
    i0 = int(np.argmax(rad > gap))
    i1 = i0 + int(np.argmax(rad[i0:] < gap))

    def at_gap(i):
        s = (gap - rad[i - 1]) / (rad[i] - rad[i - 1])
        return vy[i - 1] + s * (vy[i] - vy[i - 1])

    v_in = -at_gap(i0)
    assert v_in == pytest.approx(math.sqrt(2 * 9.80665 * gap), rel=0.01)     # free fall
    m, k = 97.3 / 2, r.model.scene.stator.stiffness
    c = damping_coefficient(k, m, r.model.scene.stator.restitution)
    expect = point_mass_rebound(m, k, c, gap, v_in, g=9.80665, h=1e-8)
    assert at_gap(i1) / v_in == pytest.approx(expect, rel=2e-3)
    assert not r.state("x").any() and not r.state("a").any()           # a straight drop


def test_stator_friction_opposes_the_surface_slip_and_brakes_the_spin():
    """Rotor pressed into the stator along +X, spinning forward: the friction on the rotor points
    along -t = -Y (against its surface velocity Omega R_a t), its torque is -R_a mu F_n, and the
    contact dissipates F_mu times the slip speed."""
    k, gap, mu, R, W = 2e9, 600e-6, 0.3, 0.045, 1000.0
    fx, fy, torque, f_n, elastic, p_damp, p = stator_force(gap + 1e-5, 0.0, 0.0, 0.0, W, gap, k,
                                                           0.0, mu, R, 1e-3)
    assert f_n == pytest.approx(k * 1e-5) and elastic == pytest.approx(f_n)
    assert fx == pytest.approx(-f_n)                    # pushes the rotor back inside
    assert fy == pytest.approx(-mu * f_n)
    assert torque == pytest.approx(-R * mu * f_n)
    assert p == pytest.approx(mu * f_n * W * R)
    assert p_damp == 0.0                                # no dashpot (c = 0)
    # inside the gap: nothing
    assert stator_force(gap - 1e-6, 0.0, 1.0, 0.0, W, gap, k, 1e5, mu, R, 1e-3) == (0.0,) * 7


def test_default_stator_stiffness_is_the_line_contact_secant():
    """stator.stiffness (D): secant F / delta(F) at 10 kN of Johnson's internal line contact of a
    steel rotor (206 GPa, nu 0.3) on a 40 mm stack of 0.96 stacking factor, clearance amb.air_gap."""
    E, nu = 206e9, 0.3
    e_star = 1.0 / ((1 - nu ** 2) / E + (1 - nu ** 2) / (0.96 * E))
    a = math.pi * 0.040 * e_star
    secant = 1e4 / line_deflection(1e4, a, Scene().amb.air_gap)
    assert Scene().stator.stiffness == pytest.approx(secant, rel=0.03)


@pytest.fixture(scope="module")
def whirl_drops():
    """mu = 0.5 (a backward whirl that reaches the stator) without and with a frictionless stator
    contact and with the default dry stator friction."""
    base = {"contact.friction": 0.5}
    return {name: simulate(load_scene("paper", {**base, **ov}), t_end=0.4)
            for name, ov in (("off", {}),
                             ("stop", {"effects.stator_contact": True, "stator.friction": 0.0}),
                             ("dry", {"effects.stator_contact": True}),
                             ("dry_hertz", {"effects.stator_contact": True,
                                            "contact.law": "hertz_line"}))}


def test_the_stator_stops_the_orbit_at_the_air_gap(whirl_drops):
    gap_um = Scene().amb.air_gap * 1e6
    off = compute_metrics(whirl_drops["off"])
    stop = compute_metrics(whirl_drops["stop"])
    for p in ("AMB1", "AMB2"):
        o = whirl_drops["off"].amb_orbit(p)
        assert np.hypot(o[:, 0], o[:, 1]).max() * 1e6 > 1.3 * gap_um         # 831 µm
        # without the stator, validity ends where the orbit reaches the gap: no numbers after
        assert off["amb_planes"][p]["max_displacement_um"] is None
        assert off["amb_planes"][p]["max_displacement_um_before_invalid"] <= gap_um
        assert off["amb_planes"][p]["stator_contact"] and p in off["air_gap_beyond_validity"]
        v = stop["amb_planes"][p]
        assert gap_um < v["max_displacement_um"] < 1.3 * gap_um                 # 609 µm
        assert v["stator_contacts"] >= 1 and v["stator_peak_force_N"] > 1e3
        assert v["stator_contact_time_s"] > 0.0
        assert off["amb_planes"][p]["stator_contacts"] is None
    assert any("AMB stator" in w for w in off["warnings"])
    assert not any("AMB stator" in w for w in stop["warnings"])


def test_dry_stator_friction_drives_the_rotor_into_dry_whip(whirl_drops):
    """With dry friction (mu_st = 0.3) the rotor rolls backward on the stator: the friction torque
    brakes the spin far below what the retainer contact alone takes (a physics result, see
    docs/physics.md: the stator contact is then a dry-whip warning, not a stop)."""
    off, dry = whirl_drops["off"], whirl_drops["dry"]
    assert dry.rotor_speed[-1] < 0.6 * off.rotor_speed[-1]
    m = compute_metrics(dry)
    v = m["amb_planes"]["AMB1"]                  # past the 55.9 µm half-width bound: no numbers
    assert m["stator_beyond_validity"] == ["AMB1", "AMB2"] and v["stator_penetration_um"] is None
    assert 0.1 < m["left_validity_at_s"] <= v["left_validity_at_s"] < 0.4
    assert v["validity_bound_um"] == pytest.approx(55.9, abs=0.1)
    assert v["stator_penetration_um_before_invalid"] <= v["validity_bound_um"]
    assert any("dry whip" in w for w in m["warnings"])
    assert not any("dry whip" in w for w in compute_metrics(whirl_drops["stop"])["warnings"])
    o = dry.amb_orbit("AMB1")
    post = dry.t > 0.2
    ang = np.unwrap(np.arctan2(o[post, 1], o[post, 0]))
    assert (ang[-1] - ang[0]) < -2 * np.pi * 10          # backward whirl, against the spin


@pytest.mark.parametrize("name", ["stop", "dry", "dry_hertz"])
def test_energy_audit_closes_with_stator_contact(whirl_drops, name):
    res, e = energy_residual(whirl_drops[name])
    assert res.max() < 1e-5 * e["dissipated"][-1]


@pytest.mark.parametrize("key, value, words", [
    ("stator.stiffness", -1.0, ["stator.stiffness", "[1e+06, 1e+12] N/m"]),
    ("stator.restitution", 1.5, ["stator.restitution", "[0.05, 1]"]),
    ("stator.friction", -0.1, ["stator.friction", "[0, 1]"]),
    ("contact.law", "hertz", ["contact.law", "paper, hertz_line"]),
    ("effects.stator_contact", "maybe", ["effects.stator_contact", "true or false"]),
])
def test_bad_stator_and_law_values_are_one_line_errors(key, value, words):
    from physics.scene import SceneError
    with pytest.raises(SceneError) as exc:
        load_scene("paper", {key: value})
    msg = str(exc.value)
    assert "\n" not in msg and all(w in msg for w in words), msg


def test_params_lists_the_new_keys_with_unit_range_and_source():
    from physics.scene import parameter_table
    rows = {r["key"]: r for r in parameter_table()}
    assert rows["effects.stator_contact"]["allowed"] == "true|false"
    assert rows["contact.law"]["allowed"] == "paper|hertz_line"
    assert rows["stator.stiffness"]["unit"] == "N/m" and rows["stator.stiffness"]["tag"] == "D"
    assert rows["stator.friction"]["tag"] == "A"


def test_each_amb_plane_damps_the_impact_of_its_own_mass_share():
    """On the asymmetric rotor the AMB planes carry different shares of the mass (lever rule:
    64 % and 36 %); each plane's stator dashpot is the one that rebounds its own share with
    stator.restitution, c_k = 2 zeta(e) sqrt(k m_k) (so c_1 / c_2 = sqrt(m_1 / m_2)), and a point
    mass of that share rebounds from it with e."""
    from physics.amb import weight_shares
    s = load_scene("asymmetric", {"effects.stator_contact": True})
    m = build_model(s)
    i = m.param_index("stator.damping")
    k, e = s.stator.stiffness, s.stator.restitution
    shares = [abs(w) for w in weight_shares(s.rotor.mass, s.positions.amb1, s.positions.amb2)]
    assert shares[0] != pytest.approx(shares[1], rel=0.1)
    for plane, mk in enumerate(shares):
        c = m.P[i + plane]
        assert c == pytest.approx(2.0 * damping_ratio(e) * math.sqrt(k * mk), rel=1e-12)
        assert point_mass_rebound(mk, k, c, 600e-6, 0.1) == pytest.approx(e, rel=2e-3)
    assert m.P[i] / m.P[i + 1] == pytest.approx(math.sqrt(shares[0] / shares[1]), rel=1e-12)


def test_the_stator_mount_takes_the_reaction_of_the_contact_force():
    """Newton's third law at the stator, from the recorded motion alone: the rotor, not spinning,
    falls straight onto both mounted stators (no friction); over the first impact each stator's
    momentum changes by the impulse of the contact's reaction F_n n (n the unit vector from the
    stator centre to the rotor axis: the contact pushes the stator outward, after the rotor) and of its
    mount's spring and dashpot, m_m Δq' = ∫ (F_n n - k_m q - c_m q') dt, from the first contact
    sample on (the dashpot's jump at the touch falls between samples). A short run (0.4 ms of
    contact), so an error in the reaction shows as a wrong impulse, not as a blow-up."""
    ov = {"effects.stator_contact": True, "effects.stator_mount": True, "stator.friction": 0.0,
          "contact.clearance": 0.003, "rotor.speed_rpm": 0.0, "effects.unbalance": False,
          "solver.output_rate": 2e6, "solver.rtol": 1e-9}
    scene = load_scene("paper", ov)
    gap, g = scene.amb.air_gap, 9.80665
    t_touch = scene.amb.off_time + math.sqrt(2.0 * gap / g)          # free fall through the gap
    r = simulate(scene, t_end=t_touch + 4e-4)
    st = scene.stator
    k, m = st.mount_stiffness, st.mount_mass
    c = 2.0 * st.mount_damping_ratio * math.sqrt(k * m)
    for plane in ("AMB1", "AMB2"):
        f_n = r.stator_force(plane)
        assert f_n.max() > 1e3                                        # a real impact
        q = r.stator(plane)
        qv = np.column_stack([r.state(f"{plane}.stator_vx"), r.state(f"{plane}.stator_vy")])
        d = r.amb_orbit(plane) - q                                    # rotor axis from the stator
        n = d / np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-300)[:, None]
        force = f_n[:, None] * n - k * q - c * qv                     # on the stator
        impulse = np.concatenate(([[0.0, 0.0]], np.cumsum(
            0.5 * (force[1:] + force[:-1]) * np.diff(r.t)[:, None], axis=0)))
        i = np.flatnonzero(f_n > 0.0)[0]                              # the first contact sample
        change = m * (qv - qv[i]) - (impulse - impulse[i])
        peak = m * np.abs(qv[i:, 1]).max()
        np.testing.assert_allclose(change[i:], 0.0, atol=1e-4 * peak)
        assert q[i:, 1].min() < -1e-7 and peak > 0.0                 # pushed down, away
