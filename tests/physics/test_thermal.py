"""Friction heat in the sleeves and mu(theta) (effects.thermal, physics/thermal.py)."""
import math

import numpy as np
import pytest

from physics import SceneError, load_scene, simulate
from physics.metrics import compute_metrics
from physics.model import I_THERM, build_model
from physics.thermal import heat_capacity, time_constant

TIGHT = {"solver.rtol": 1e-8}
HEAT = {"effects.thermal": True}
# every loss but the rotor-sleeve friction switched off (as in test_energy.py)
ONLY_CONTACT_FRICTION = {"support.damping": 0.0, "contact.damping": 0.0, "bearing.damping": 0.0,
                         "effects.bearing_friction": False}


def early_motion_agrees(a, b, t1=0.2):
    """The two runs' orbits agree to 10 nm (3e-5 of the clearance) and contact forces to 1e-4 of
    the peak up to t1 (the extra states change the step-size control at the tolerance level
    only)."""
    w = a.t <= t1
    assert np.array_equal(a.t[w], b.t[w])
    for p in ("RB1", "RB2"):
        assert np.abs(a.orbit(p)[w] - b.orbit(p)[w]).max() < 1e-8
        f = b.contact_force(p)[w]
        assert np.abs(a.contact_force(p)[w] - f).max() < 1e-4 * f.max()


def test_off_adds_no_state_and_the_paper_preset_keeps_it_off():
    scene = load_scene("paper")
    assert not scene.effects.thermal
    model = build_model(scene)
    assert model.I[I_THERM] == -1
    assert not any("temperature" in n or n in ("heat_lost", "friction_work") for n in model.names)
    on = build_model(load_scene("paper", HEAT))
    assert on.n_state == model.n_state + 4
    assert set(on.names) - set(model.names) == {"RB1.temperature", "RB2.temperature",
                                                "heat_lost", "friction_work"}


def test_with_a_zero_mu_slope_the_motion_equals_thermal_off():
    off = simulate(load_scene("paper", TIGHT), t_end=0.2)
    on = simulate(load_scene("paper", {**TIGHT, **HEAT, "thermal.mu_slope": 0.0}), t_end=0.2)
    early_motion_agrees(on, off)
    assert on.temperature_rise("RB1")[-1] > 0.3                 # it did heat: 0.5 K by 0.2 s


@pytest.mark.parametrize("mu0, slope, bound, mu_eff", [(0.5, -0.02, "mu_ratio_min", 0.25),
                                                        (0.2, 0.02, "mu_ratio_max", 0.4)])
def test_a_hot_sleeve_runs_at_the_clamped_friction_coefficient(mu0, slope, bound, mu_eff):
    """Sleeves 100 K warm with |kappa| = 0.02 /K sit on the floor (ceiling) of mu(theta): the drop
    is the thermal-off drop at mu = 0.5 mu_0 (2 mu_0), bound for bound."""
    hot = simulate(load_scene("paper", {**TIGHT, **HEAT, "contact.friction": mu0,
                                        "thermal.mu_slope": slope, "thermal.initial_rise": 100.0,
                                        f"thermal.{bound}": mu_eff / mu0}), t_end=0.2)
    cold = simulate(load_scene("paper", {**TIGHT, "contact.friction": mu_eff}), t_end=0.2)
    assert np.allclose(hot.friction_coefficient("RB1"), mu_eff, rtol=1e-12)
    early_motion_agrees(hot, cold)


def test_without_losses_the_temperature_rise_is_the_friction_heat_over_the_heat_capacity():
    """a = 1, G = 0, friction the only loss: C (theta_1 + theta_2 - 2 theta_0) equals the energy
    the mechanical audit saw dissipated after the fault, and each plane's rise its friction heat
    (metrics friction_heat_J, trapezoidal over the output samples) over C."""
    scene = load_scene("paper", {**ONLY_CONTACT_FRICTION, **HEAT, "thermal.conductance": 0.0,
                                 "thermal.heat_partition": 1.0, "thermal.initial_rise": 20.0})
    r = simulate(scene, t_end=0.5)
    C = heat_capacity(scene)
    assert C == pytest.approx(0.78 * 475.0)
    rise = {p: r.temperature_rise(p) - 20.0 for p in ("RB1", "RB2")}
    lost = r.energy()["dissipated"]
    i = np.searchsorted(r.t, r.t_fault)
    assert C * (rise["RB1"][-1] + rise["RB2"][-1]) == pytest.approx(lost[-1] - lost[i], rel=1e-6)
    m = compute_metrics(r)
    for p in ("RB1", "RB2"):
        heat = m["planes"][p]["friction_heat_J"]
        assert heat > 500.0                                   # the sleeve spin-up: ~850 J
        assert rise[p][-1] == pytest.approx(heat / C, rel=5e-3)
        assert m["planes"][p]["max_temperature_rise_K"] == pytest.approx(20.0 + rise[p].max())
    e = r.energy()
    assert e["heat_lost"][-1] == 0.0


@pytest.mark.parametrize("sleeve_inertia", [True, False])
def test_without_losses_contact_and_bearing_friction_heat_is_all_the_energy_dissipated(
        sleeve_inertia):
    """a = b = 1, G = 0, every damper off: the contact friction and the ball bearings' drag are
    the only losses, and all their heat stays in the sleeves, so C (theta_1 + theta_2 - 2
    theta_0) is the energy the mechanical audit saw dissipated after the fault; the bearing's
    share alone is clearly not negligible. A massless sleeve passes its drag on through the
    contact (F_mu R omega_s), which the heat must count too."""
    no_dampers = {k: v for k, v in ONLY_CONTACT_FRICTION.items() if k != "effects.bearing_friction"}
    scene = load_scene("paper", {**no_dampers, **HEAT, "thermal.conductance": 0.0,
                                 "thermal.heat_partition": 1.0, "thermal.drag_heat_partition": 1.0,
                                 "effects.sleeve_inertia": sleeve_inertia,
                                 "amb.air_gap": 3e-3})   # the whirl stays valid: no stator to reach
    r = simulate(scene, t_end=0.5)
    C = heat_capacity(scene)
    heat = C * (r.temperature_rise("RB1") + r.temperature_rise("RB2"))
    lost = r.energy()["dissipated"]
    i = np.searchsorted(r.t, r.t_fault)
    assert heat[-1] - heat[i] == pytest.approx(lost[-1] - lost[i], rel=1e-6)
    contact_only = sum(compute_metrics(r)["planes"][p]["friction_heat_J"] for p in ("RB1", "RB2"))
    assert heat[-1] - heat[i] > contact_only + 50.0


def test_a_warm_sleeve_without_friction_cools_with_the_stated_time_constant():
    """No friction: theta(t) = theta_0 exp(-t / tau), tau = m_s c / G (here G set for 1 s)."""
    C = heat_capacity(load_scene("paper"))
    scene = load_scene("paper", {**HEAT, "effects.friction": "none", "thermal.conductance": C,
                                 "thermal.initial_rise": 80.0})
    assert time_constant(scene) == pytest.approx(1.0)
    r = simulate(scene, t_end=1.0)
    for p in ("RB1", "RB2"):
        assert np.allclose(r.temperature_rise(p), 80.0 * np.exp(-r.t), rtol=1e-5)
    e = r.energy()
    assert e["heat_lost"][-1] == pytest.approx(2 * C * 80.0 * (1.0 - math.exp(-1.0)), rel=1e-5)
    assert e["friction_work"][-1] == 0.0


@pytest.mark.parametrize("overrides", [
    {"contact.friction": 0.5, "effects.friction": "kinematic", "thermal.mu_slope": 0.02},
    {"contact.friction": 0.3, "effects.sleeve_inertia": False, "effects.friction": "kinematic"},
    {"thermal.conductance": 200.0, "thermal.heat_partition": 0.3, "thermal.initial_rise": 50.0},
    # the heat states after every other optional block of the layout
    {"effects.amb": "actuator", "amb.coil_time_constant": 1e-3, "effects.semi_active_damper": True,
     "effects.retainer_bearing": "linear"}])
def test_heat_audit_closes_and_the_mechanical_audit_still_does(overrides):
    """heat stored + heat lost = friction work (to round-off: the quadratures are states), and
    E_mech + E_dissipated - W_external stays constant with mu following the temperature."""
    r = simulate(load_scene("paper", {**HEAT, **overrides}), t_end=0.4)
    e = r.energy()
    work = e["friction_work"]
    assert work[-1] > 0.0          # massless sleeve: it rolls, only the drag slips (~0.3 J)
    assert np.abs(e["heat_stored"] + e["heat_lost"] - work).max() < 1e-9 * work[-1]
    balance = e["mechanical"] + e["dissipated"] - e["external"]
    assert np.abs(balance - balance[0]).max() < 1e-5 * e["dissipated"][-1]


def test_friction_heat_above_ambient_lowers_mu_by_the_stated_law():
    """Default law (kappa = -1e-3 /K): the measured mu follows mu_0 (1 + kappa theta)."""
    r = simulate(load_scene("paper", {**HEAT, "thermal.initial_rise": 40.0}), t_end=0.3)
    theta = r.temperature_rise("RB2")
    assert np.allclose(r.friction_coefficient("RB2"), 0.25 * (1.0 - 1e-3 * theta), rtol=1e-12)
    assert r.friction_coefficient("RB2")[-1] < 0.25 * (1.0 - 1e-3 * 40.0)    # it warmed further


def test_a_cooling_time_constant_below_a_tenth_of_a_second_is_refused_in_one_line():
    with pytest.raises(SceneError, match=r"thermal.conductance = 5000 W/K.*370 J/K.*0.1 s.*<= 3705"
                       ) as exc:
        load_scene("paper", {**HEAT, "thermal.conductance": 5000.0})
    assert "\n" not in str(exc.value)
    load_scene("paper", {"thermal.conductance": 5000.0})          # irrelevant while off
    assert time_constant(load_scene("paper", {**HEAT, "thermal.conductance": 3705.0})) >= 0.1


@pytest.mark.parametrize("key, value, allowed", [
    ("thermal.specific_heat", 50.0, r"\[100, 2000\] J/\(kg K\)"),
    ("thermal.conductance", -1.0, r"\[0, 10000\] W/K"),
    ("thermal.heat_partition", 1.5, r"\[0, 1\]"),
    ("thermal.drag_heat_partition", -0.5, r"\[0, 1\]"),
    ("thermal.mu_slope", 0.1, r"\[-0.02, 0.02\] 1/K"),
    ("thermal.mu_ratio_min", -0.1, r"\[0, 1\]"),
    ("thermal.mu_ratio_max", 0.5, r"\[1, 10\]"),
    ("thermal.initial_rise", float("nan"), r"\[0, 1000\] K")])
def test_thermal_constants_out_of_range_are_refused_naming_key_and_range(key, value, allowed):
    with pytest.raises(SceneError, match=key.replace(".", r"\.") + ".*" + allowed) as exc:
        load_scene("paper", {**HEAT, key: value})
    assert "\n" not in str(exc.value)


def test_a_rotor_sliding_to_rest_in_seized_retainers_turns_its_spin_energy_into_heat():
    """Seized retainers (seal torque 50 N m, ten times the friction torque), kinematic slip: the
    rotor rests at atan mu up the sleeve wall and slides to a stop, so the friction work is its
    whole spin energy 1/2 I_p Omega_0^2 (the creeping sleeves' seal drag included; measured to
    4e-5). The sleeves warm by ~138 K, the default law lowers mu to 0.26, and the stop comes well
    after the Coulomb estimate at the ambient mu (rotor weight W shared by the planes: torque
    r mu W / sqrt(1 + mu^2))."""
    scene = load_scene("paper", {**HEAT, "bearing.seal_torque": 50.0, "effects.friction": "kinematic",
                                 "contact.friction": 0.3, "solver.output_rate": 200.0,
                                 "solver.t_end": 60.0})
    r = simulate(scene)
    rotor, mu = scene.rotor, 0.3
    omega0 = rotor.speed_rpm * math.pi / 30
    e = r.energy()
    assert abs(r.rotor_speed[-1]) < 1e-3 * omega0                        # at rest
    assert e["friction_work"][-1] == pytest.approx(0.5 * rotor.polar_inertia * omega0 ** 2,
                                                   rel=5e-4)
    assert e["heat_stored"][-1] + e["heat_lost"][-1] == pytest.approx(e["friction_work"][-1],
                                                                      rel=1e-9)
    assert 120.0 < r.temperature_rise("RB1").max() < 160.0
    torque = rotor.journal_radius * mu * rotor.mass * scene.world.gravity / math.sqrt(1 + mu * mu)
    coulomb_stop = scene.amb.off_time + rotor.polar_inertia * 0.99 * omega0 / torque
    stop = r.t[np.flatnonzero(r.rotor_speed < 0.01 * omega0)[0]]
    assert stop > 1.05 * coulomb_stop


def test_drop_cli_reports_plots_and_saves_the_sleeve_heating(tmp_path, capsys):
    import json

    from agents.cli import main
    out = tmp_path / "drop"
    assert main(["drop", "--t-end", "0.3", "--set", "effects.thermal=true", "--set",
                 "thermal.initial_rise=20", "--set", "thermal.mu_slope=-0.01", "--out", str(out),
                 "--quiet"]) == 0
    m = json.loads((out / "metrics.json").read_text())
    rb1 = m["planes"]["RB1"]
    assert 20.3 < rb1["max_temperature_rise_K"] < 22.0            # 20 K start + ~1 K spin-up heat
    # it cools by ~3 mK through G while levitated, then warms
    assert rb1["max_friction_coefficient"] == pytest.approx(0.25 * (1 - 0.01 * 20.0), rel=1e-4)
    assert rb1["min_friction_coefficient"] == pytest.approx(
        0.25 * (1 - 0.01 * rb1["max_temperature_rise_K"]))
    assert "sleeve heating: RB1 +" in capsys.readouterr().out
    assert (out / "thermal.png").stat().st_size > 10_000
    ts = np.load(out / "timeseries.npz")
    assert ts["RB2_temperature_rise"][0] == 20.0
    plain = tmp_path / "plain"
    assert main(["drop", "--t-end", "0.15", "--out", str(plain), "--quiet"]) == 0
    assert not (plain / "thermal.png").exists()
    assert "max_temperature_rise_K" not in json.loads((plain / "metrics.json").read_text())["planes"]["RB1"]


def test_the_spin_down_example_runs_and_orders_the_three_laws(tmp_path):
    """docs/examples/thermal_spin_down.py, shortened to 3 s: after the same time the rotor that
    slid with mu rising is the slowest, the one with mu falling the fastest."""
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path
    root = Path(__file__).resolve().parents[2]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]))
    subprocess.run([sys.executable, str(root / "docs/examples/thermal_spin_down.py"), "--out",
                    str(tmp_path), "--t-end", "3"], check=True, capture_output=True, cwd=root,
                   env=env)
    cases = json.loads((tmp_path / "thermal-spin-down.json").read_text())["cases"]
    off, falls, rises = (cases[name]["final_speed_rpm"] for name in cases)
    assert rises < off < falls
    assert (tmp_path / "thermal-spin-down.png").exists()
    assert (tmp_path / "thermal-spin-down.csv").read_text().count("\n") > 3 * 30
