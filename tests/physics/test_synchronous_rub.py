"""The harmonic balance of the steady synchronous forward rub (physics/synchronous_rub.py): its
pieces against the model's own laws (the AMB describing function reduces to the PID's dynamic
stiffness for a small orbit; the sleeve and housing amplitudes satisfy their equations), every
root satisfies the rotor's balance, and the simulated steady rub of the bi-stable preset (without
gravity, which the balance leaves out) has the predicted amplitude, contact force and phase."""
import math

import numpy as np
import pytest

from physics import load_scene, simulate
from physics.amb import actuator_constants, pid_dynamic_stiffness
from physics.ball_bearing import ball_forces, film_thickness
from physics.model import P_CB, P_FILM, P_HALF_PLAY, P_KS, P_KTOT, P_MH, P_MS, P_NB
from physics.scene import SceneError
from physics.persistence import end_state
from physics.synchronous_rub import (RubPlant, contact_stiffened_speed, free_orbit, rub_solutions,
                                     simulated_rub)

RUB = {"effects.gravity": False}
#: the stated tolerances of the check (docs/physics.md)
AMPLITUDE_TOL, FORCE_TOL, PHASE_TOL_DEG = 0.02, 0.02, 5.0


@pytest.fixture(scope="module")
def scene():
    return load_scene("amb-persistent", RUB)


@pytest.fixture(scope="module")
def plant(scene):
    return RubPlant(scene)


def test_a_small_orbit_sees_the_pids_dynamic_stiffness(plant, scene):
    """The describing function of the magnet force under the PID tends to k_i C(jΩ) − k_s."""
    omega = scene.rotor.speed_rpm * math.pi / 30
    ac = actuator_constants(scene.amb, 0.0, 0.0)
    K_lin = pid_dynamic_stiffness(scene.amb, ac.current_gain, ac.negative_stiffness, omega)
    K, _ = plant.amb_stiffness(1e-7, omega)
    assert abs(K / K_lin - 1) < 1e-4
    K_big, peak = plant.amb_stiffness(250e-6, omega)         # the gap law stiffens, no clipping
    assert peak < scene.amb.current_limit and abs(K_big / K_lin - 1) > 0.01


def test_the_linear_amb_level_is_its_spring_and_damper():
    scene = load_scene("amb-persistent", {**RUB, "effects.amb": "linear"})
    K, _ = RubPlant(scene).amb_stiffness(1e-4, 400.0)
    assert K == pytest.approx(scene.amb.stiffness + 400j * scene.amb.damping)


def test_sleeve_and_housing_amplitudes_satisfy_their_equations(plant):
    """(R3)-(R5): −m_s Ω² S = f_s − B(u), −m_h Ω² H = B(u) − (K_s + iΩC_s) H, u = S − H, with
    B from the ball set's Hertz forces averaged over the cage angle (computed here anew)."""
    P, w, ws, f_s = plant.P, 420.0, 430.0, 4000.0 + 15j
    S, H, load = plant.support(f_s, w, ws)
    u = S - H
    h = film_thickness(ws, P[P_FILM])[0]
    cages = np.arange(32) / 32 * 2 * math.pi / P[P_NB]
    q = np.mean([complex(*ball_forces(abs(u), 0.0, c, int(P[P_NB]), P[P_HALF_PLAY], h,
                                       P[P_KTOT])[:2]) for c in cages]) * u / abs(u)
    B = q + 1j * w * P[P_CB] * u
    zs = P[P_KS] + 1j * w * plant.scene.support.damping
    assert abs(-P[P_MS] * w ** 2 * S - (f_s - B)) < 2e-3 * abs(f_s)
    assert abs(-P[P_MH] * w ** 2 * H - (B - zs * H)) < 2e-3 * abs(f_s)
    assert load == pytest.approx(abs(q), rel=2e-3)


def test_every_root_balances_the_rotor(plant, scene):
    """Two rubs at the preset's speed: the resonant one the shock reaches (large force, the orbit
    leading the unbalance by less than 90°) and a smaller one between it and the contact-free
    orbit; each satisfies (R1) to round-off."""
    sols = rub_solutions(scene, plant=plant)
    assert len(sols) == 2
    for s in sols:
        assert s.residual < 1e-9
        gap = plant.c + s.penetration                       # X = S + (c + δ) n
        assert gap - s.sleeve_amplitude <= s.amplitude <= gap + s.sleeve_amplitude
        assert s.amplitude < scene.amb.air_gap
    small, big = sorted(sols, key=lambda s: s.contact_force)
    assert big.contact_force > 3 * small.contact_force
    assert abs(big.phase_deg) < 90 < abs(small.phase_deg)


def test_no_unbalance_no_rub(scene):
    assert rub_solutions(scene.with_overrides({"unbalance.mass": 0.0})) == []


def test_the_simulated_steady_rub_matches_the_balance(scene):
    """The preset's shock throws the rotor into its rub; over the last 50 ms of 0.4 s its orbit
    radius and contact force at RB1 are the balance's (at the run's own spin speed) within 2 %,
    its phase within 5°."""
    result = simulate(scene)
    assert end_state(result).label == "forward_rub"
    sim = simulated_rub(result, 0.05)
    hb = max(rub_solutions(scene, speed_rpm=sim["speed"] * 30 / math.pi),
             key=lambda s: s.contact_force)
    assert sim["amplitude"] == pytest.approx(hb.amplitude, rel=AMPLITUDE_TOL)
    assert sim["contact_force"] == pytest.approx(hb.contact_force, rel=FORCE_TOL)
    assert abs((sim["phase_deg"] - hb.phase_deg + 180) % 360 - 180) < PHASE_TOL_DEG


def test_scenes_outside_the_derivation_are_refused_by_name():
    with pytest.raises(SceneError, match="positions.rb1"):
        RubPlant(load_scene("asymmetric"))
    with pytest.raises(SceneError, match="effects.friction"):
        RubPlant(load_scene("amb-persistent", {"effects.friction": "paper"}))
    with pytest.raises(SceneError, match="effects.amb"):
        RubPlant(load_scene("amb-persistent", {"effects.amb": "none"}))
    with pytest.raises(SceneError, match="speed_rpm"):
        rub_solutions(load_scene("amb-persistent"), speed_rpm=-5.0)
    with pytest.raises(ValueError, match="window"):
        simulated_rub(simulate(load_scene("amb-persistent", {"solver.t_end": 0.01})), 1.0)


def test_the_contact_free_orbit_is_the_simulated_one_without_a_shock(scene, plant):
    """Without the shock the preset stays contact-free; its orbit radius at RB1 is the balance's
    without the contact (no gravity), within 1 %."""
    result = simulate(scene.with_overrides({"effects.base_excitation": False}))
    assert end_state(result).label == "contact_free"
    a = free_orbit(scene, plant=plant)
    assert simulated_rub(result, 0.05)["amplitude"] == pytest.approx(a, rel=0.01)
    assert free_orbit(scene.with_overrides({"unbalance.mass": 0.5})) is None   # it cannot fit


def test_a_stiffer_support_raises_the_contact_stiffened_speed(scene, plant):
    soft = load_scene("amb-persistent", {**RUB, "support.stiffness": 5e7})
    stiff = contact_stiffened_speed(scene, 4000.0, plant)
    assert contact_stiffened_speed(soft, 4000.0) < stiff
    assert stiff > scene.rotor.speed_rpm         # the preset runs below it: the rub pushes in
    with pytest.raises(ValueError, match="load"):
        contact_stiffened_speed(scene, 0.0, plant)
