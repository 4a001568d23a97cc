"""Scenes: which effects to simulate and every parameter, validated and typed.

A :class:`Scene` is an immutable tree of parameter groups (``scene.contact.friction``...).
Every leaf has a dotted key (``contact.friction``), a unit, a default, an allowed range and a
tag saying where the value comes from (spec §2):

* ``P`` given by the paper, ``A`` assumed (the paper does not give it), ``D`` derived.

Scenes come from named presets (``paper``, ``spec``), TOML files, and dotted overrides
(``--set contact.friction=0.4``). All inputs are validated here so that no bad value ever
reaches a numba kernel: errors name the key and the allowed range.
"""
from __future__ import annotations

import dataclasses
import json
import math
import tomllib
from dataclasses import dataclass, field, fields
from importlib import resources
from pathlib import Path
from typing import Any, Iterator, Mapping

from .laws import CONTACT_LAWS, SLIP_LAWS


class SceneError(ValueError):
    """A scene or parameter value is invalid; the message names the key and what is allowed."""


def param(default, unit: str, lo=None, hi=None, doc: str = "", tag: str = "P", choices=None):
    """A scene parameter: default, SI unit, closed range [lo, hi] (or choices), provenance tag."""
    return field(default=default, metadata=dict(unit=unit, lo=lo, hi=hi, doc=doc, tag=tag,
                                                choices=choices))


# ---------------------------------------------------------------------------------------------
# Parameter groups (spec §2). Symbols follow the spec; SI units inside.
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Rotor:
    mass: float = param(97.3, "kg", 1e-3, 1e5, "rotor mass m")
    polar_inertia: float = param(0.39, "kg m^2", 1e-6, 1e4, "polar moment of inertia I_p")
    diametral_inertia: float = param(2.82, "kg m^2", 1e-6, 1e5, "diametral moment of inertia I_d")
    speed_rpm: float = param(10000.0, "rpm", 0.0, 60000.0, "initial spin speed")
    journal_radius: float = param(0.030, "m", 1e-3, 1.0, "journal radius r at the retainer planes", "D")
    model: str = param("rigid", "-", doc="rigid body (the paper's model), or flexible: the rigid"
                       " body plus the elastic modes of the shaft flexible.shaft (flexible.*);"
                       " a flexible rotor's mass, I_d and I_p must equal its shaft's",
                       tag="A", choices=("rigid", "flexible"))


@dataclass(frozen=True)
class Positions:
    """Axial positions z measured from the rotor's centre of mass."""
    rb1: float = param(-0.38, "m", -5.0, 5.0, "retainer bearing 1 plane", "A")
    rb2: float = param(0.38, "m", -5.0, 5.0, "retainer bearing 2 plane", "A")
    amb1: float = param(-0.28, "m", -5.0, 5.0, "AMB 1 plane (sensor 1 collocated)", "A")
    amb2: float = param(0.28, "m", -5.0, 5.0, "AMB 2 plane (sensor 2 collocated)", "A")


@dataclass(frozen=True)
class Unbalance:
    mass: float = param(1e-3, "kg", 0.0, 1.0, "unbalance mass m_u")
    radius: float = param(0.0975, "m", 0.0, 1.0, "unbalance radius e")
    angle_deg: float = param(90.0, "deg", -360.0, 360.0, "angle from +X at t = 0")
    z: float = param(0.0, "m", -5.0, 5.0, "axial position of the unbalance plane")


@dataclass(frozen=True)
class World:
    gravity: float = param(9.80665, "m/s^2", 0.0, 100.0, "gravitational acceleration g (acts in -Y)")


@dataclass(frozen=True)
class Amb:
    off_time: float = param(0.1, "s", 0.0, 100.0, "time at which both AMB forces vanish (fault)")
    stiffness: float = param(1e6, "N/m", 0.0, 1e9, "linear AMB stiffness k_amb per AMB and axis", "A")
    damping: float = param(2e3, "N s/m", 0.0, 1e7, "linear AMB damping c_amb per AMB and axis", "A")
    # actuator level (effects.amb = "actuator", spec §5)
    air_gap: float = param(0.6e-3, "m", 1e-5, 0.1,
                           "nominal magnetic air gap g_0 (the stator: environments end when the rotor"
                           " reaches it at an AMB plane)", "P")
    turns: int = param(250, "-", 1, 100_000, "coil turns N per electromagnet", "A")
    pole_area: float = param(1e-3, "m^2", 1e-7, 1.0, "pole face area A_g", "A")
    pole_angle_deg: float = param(22.5, "deg", 0.0, 60.0, "pole angle alpha to the force axis", "A")
    bias_current: float = param(3.0, "A", 0.0, 1e3, "bias current i_0", "A")
    current_limit: float = param(3.0, "A", 0.0, 1e3, "control current limit |i| <= i_max (<= i_0)", "A")
    saturation_flux: float = param(1.6, "T", 0.1, 5.0,
                                   "iron saturation flux density B_sat: caps each magnet's force"
                                   " at B_sat^2 A_g cos(alpha) / mu_0 (force capacity)", "A")
    kp: float = param(8000.0, "A/m", 0.0, 1e9, "PID proportional gain (per AMB axis)", "A")
    ki: float = param(1e5, "A/(m s)", 0.0, 1e12, "PID integral gain", "A")
    kd: float = param(15.0, "A s/m", 0.0, 1e6, "PID derivative gain", "A")
    derivative_filter: float = param(2e-4, "s", 1e-6, 1.0, "time constant of the derivative filter", "A")
    coil_time_constant: float = param(0.0, "s", 0.0, 1.0,
                                      "coil current lag L/R (0: ideal current amplifier, no state)", "A")
    liftoff_ramp_time: float = param(0.05, "s", 0.0, 10.0,
                                     "after reactivation the reference ramps from the landing"
                                     " position to the centre in this time", "A")


@dataclass(frozen=True)
class Contact:
    clearance: float = param(300e-6, "m", 1e-6, 0.01, "rotor-sleeve radial air gap c = R - r (the retainer"
                                " clearance; not bearing.clearance, the ball bearing's play)")
    stiffness: float = param(1e8, "N/m^e", 1e5, 1e12,
                             "contact stiffness K (paper: 1e8, unit reading N/m^1.1 assumed;"
                             " the N-mm reading would be 2.0e8)")
    exponent: float = param(1.1, "-", 1.0, 2.0, "force-deflection exponent e")
    damping: float = param(1000.0, "N s/m", 0.0, 1e6, "maximum contact damping C_max")
    damping_depth: float = param(1e-5, "m", 1e-9, 1e-3, "penetration d at which damping is full")
    friction: float = param(0.25, "-", 0.0, 1.0, "rotor-sleeve friction coefficient mu")
    threshold_rpm: float = param(10.0, "rpm", 1e-3, 1e4,
                                 "friction threshold speed omega_l (kinematic slip: omega_l*r)")
    law: str = param("paper", "-", doc="rotor-sleeve normal force law: paper (K delta^e with the STEP"
                     " damping, eq. 14) or hertz_line (Johnson's internal line contact of steel on"
                     " steel over contact.length, Hunt-Crossley damping; docs/physics.md)",
                     tag="A", choices=tuple(CONTACT_LAWS))
    length: float = param(0.022, "m", 1e-4, 1.0, "hertz_line: axial contact length L of journal and"
                          " sleeve (the 6016's width)", "A")
    restitution: float = param(0.9, "-", 0.05, 1.0, "hertz_line: coefficient of restitution e of a"
                               " normal impact at the free-fall speed through the clearance"
                               " (sets the Hunt-Crossley damping)", "A")


@dataclass(frozen=True)
class Stator:
    """Rotor-stator contact at the AMB planes (effects.stator_contact; docs/physics.md)."""
    stiffness: float = param(2.0e9, "N/m", 1e6, 1e12,
                             "contact stiffness k of the laminated pole stack: secant of Johnson's"
                             " internal line contact (steel rotor on a 40 mm stack, 0.96 stacking"
                             " factor, air gap clearance) at 10 kN", "D")
    restitution: float = param(0.5, "-", 0.05, 1.0,
                               "coefficient of restitution e of a normal impact of the rotor's mass"
                               " share at the AMB plane (sets the contact damping)", "A")
    friction: float = param(0.3, "-", 0.0, 1.0, "dry rotor-stator friction coefficient mu_st", "A")
    rotor_radius: float = param(0.045, "m", 1e-3, 1.0,
                                "rotor radius R_a at the AMB planes (friction torque lever)", "A")
    # the stator on its mount (effects.stator_mount): no source gives these; a radial AMB stator
    # of a 100 kg rotor (stack ~200 mm outside, 40 mm long, with its coils) in a machine frame
    mount_stiffness: float = param(2e8, "N/m", 1e5, 1e12,
                                   "stiffness k_m of the stator's mount to the frame, per AMB plane"
                                   " and axis, in series with the contact", "A")
    mount_mass: float = param(8.0, "kg", 1e-2, 1e4,
                              "participating mass m_m of each AMB stator (stack, coils)", "A")
    mount_damping_ratio: float = param(0.05, "-", 0.0, 2.0,
                                       "damping ratio of the stator on its mount (dashpot"
                                       " c_m = 2 zeta sqrt(k_m m_m))", "A")


@dataclass(frozen=True)
class Sleeve:
    mass: float = param(0.78, "kg", 1e-4, 1e3, "sleeve + inner ring mass (share of balls/cage)", "A")
    spin_inertia: float = param(1.5e-3, "kg m^2", 1e-7, 10.0, "sleeve + inner ring spin inertia", "A")


@dataclass(frozen=True)
class Thermal:
    """Lumped heating of each sleeve + inner ring by the contact and bearing friction, and the
    friction coefficient's temperature law (effects.thermal; docs/physics.md "Friction heat")."""
    specific_heat: float = param(475.0, "J/(kg K)", 100.0, 2000.0,
                                 "specific heat c of the sleeve + inner ring (bearing steel"
                                 " 100Cr6 / AISI 52100: ~475); heat capacity sleeve.mass x c", "A")
    conductance: float = param(0.5, "W/K", 0.0, 1e4,
                               "heat loss G from a sleeve to the housing per kelvin (ball set,"
                               " air); 0 = adiabatic; time constant sleeve.mass c / G = 741 s"
                               " at the defaults", "A")
    heat_partition: float = param(0.5, "-", 0.0, 1.0,
                                  "share of the rotor-sleeve friction heat entering the sleeve"
                                  " (the rest heats the rotor, counted as lost)", "A")
    drag_heat_partition: float = param(0.5, "-", 0.0, 1.0,
                                       "share of the retainer bearing's friction heat (drag torque x"
                                       " sleeve speed) entering the inner ring (the outer ring,"
                                       " balls and oil take the rest, counted as lost)", "A")
    mu_slope: float = param(-1e-3, "1/K", -0.02, 0.02,
                            "relative change kappa of the friction coefficient per kelvin of"
                            " sleeve temperature rise: mu = contact.friction x clamp(1 + kappa"
                            " theta, mu_ratio_min, mu_ratio_max); < 0: oxide films (default),"
                            " > 0: the paper's rise with heat and wear", "A")
    mu_ratio_min: float = param(0.5, "-", 0.0, 1.0,
                                "floor of mu / contact.friction under heating", "A")
    mu_ratio_max: float = param(2.0, "-", 1.0, 10.0,
                                "ceiling of mu / contact.friction under heating (mu_slope > 0)",
                                "A")
    initial_rise: float = param(0.0, "K", 0.0, 1000.0,
                                "sleeve temperature rise above ambient at t = 0 (e.g. after an"
                                " earlier drop)", "A")


@dataclass(frozen=True)
class Bearing:
    """Retainer ball bearing 6016 (spec §4)."""
    pitch_diameter: float = param(0.110, "m", 1e-3, 2.0, "pitch diameter d_m")
    ball_diameter: float = param(0.01905, "m", 1e-4, 0.5, "ball diameter D")
    balls: int = param(10, "-", 3, 100, "number of balls z")
    clearance: float = param(15e-6, "m", 0.0, 1e-3, "ball-bearing internal diametral play P_d (not"
                                " contact.clearance, the rotor-sleeve air gap)")
    damping: float = param(250.0, "N s/m", 0.0, 1e6, "bearing damping c_b")
    conformity: float = param(0.52, "-", 0.501, 0.7, "race conformity f (inner and outer)")
    static_load_rating: float = param(40e3, "N", 1.0, 1e8, "static load rating C_0")
    youngs_modulus: float = param(206e9, "Pa", 1e9, 1e13, "Young's modulus E")
    poisson: float = param(0.3, "-", 0.0, 0.49, "Poisson's ratio nu")
    pressure_viscosity: float = param(2.3e-8, "m^2/N", 0.0, 1e-6, "pressure-viscosity coefficient alpha")
    viscosity: float = param(0.04, "Pa s", 1e-5, 10.0, "dynamic viscosity eta_0")
    oil_density: float = param(870.0, "kg/m^3", 100.0, 3000.0, "oil density (kinematic viscosity)", "A")
    f0: float = param(0.7, "-", 0.0, 20.0, "Palmgren viscous-friction factor f_0", "A")
    seal_torque: float = param(0.0, "N m", 0.0, 100.0, "seal friction torque M_s", "A")
    linear_stiffness: float = param(1.16e8, "N/m", 1e4, 1e12,
                                    "radial stiffness of the 'linear' retainer-bearing model", "D")


@dataclass(frozen=True)
class Support:
    stiffness: float = param(5e7, "N/m", 1e4, 1e11, "housing support stiffness K_s (X and Y)")
    damping: float = param(5000.0, "N s/m", 0.0, 1e7, "housing support damping C_s (X and Y)")
    housing_mass: float = param(5.0, "kg", 1e-3, 1e4, "housing + outer ring mass", "A")
    # semi-active damper (effects.semi_active_damper, spec §6)
    damping_min: float = param(2790.0, "N s/m", 0.0, 1e7, "semi-active damper: lowest C_s (C_min)")
    damping_max: float = param(27900.0, "N s/m", 0.0, 1e7, "semi-active damper: highest C_s (C_max)")
    damper_time_constant: float = param(0.01, "s", 1e-5, 1.0,
                                        "semi-active damper: first-order lag of C_s behind its"
                                        " command", "A")


@dataclass(frozen=True)
class Solver:
    method: str = param("adaptive", "-", doc="adaptive (Dormand-Prince 5(4)) or fixed (same tableau,"
                        " constant step solver.dt)", tag="A", choices=("adaptive", "fixed"))
    rtol: float = param(1e-5, "-", 1e-12, 1e-3, "relative tolerance (absolute = rtol x state scale);"
                        " default chosen by `rotordrop accuracy`; looser than 1e-3 gives wrong"
                        " bearing loads (docs/accuracy.md)", "A")
    dt: float = param(2e-6, "s", 1e-9, 1e-2, "step of the fixed-step method", "A")
    max_step: float = param(1e-3, "s", 1e-9, 1.0, "largest adaptive step", "A")
    min_step: float = param(1e-12, "s", 1e-16, 1e-6,
                            "adaptive step below which integration stops with an error", "A")
    max_steps: int = param(20_000_000, "-", 100, 1_000_000_000,
                           "step budget; exceeding it stops with an error instead of hanging", "A")
    t_end: float = param(1.0, "s", 1e-6, 100.0, "simulated time")
    output_rate: float = param(20000.0, "Hz", 10.0, 1e7, "output sampling rate (dense output)", "A")


@dataclass(frozen=True)
class Sensor:
    """Position sensing at the AMB planes (physics/sensor.py; docs/physics.md "Position
    sensing"): what the built-in AMB controller, the supervisor and the environments' observations
    see. Both zero (default): the true displacement, no state."""
    delay: float = param(0.0, "s", 0.0, 2e-3,
                         "transport delay tau of the displacement signal (sensor, anti-alias filter,"
                         " sampling, controller samples) as a (2,2) Pade approximant: 4 states per"
                         " AMB plane; 0: no state", "A")
    noise: float = param(0.0, "m", 0.0, 1e-4,
                         "standard deviation of the displacement noise: one Gaussian sample per"
                         " axis at each sensor sample (sensor.sample_rate), held until the next,"
                         " drawn by the environments (the drop driver has no noise source and"
                         " refuses it)", "A")
    sample_rate: float = param(1e4, "Hz", 1e3, 1e5,
                               "sample rate f_s of the displacement sensors: the noise is one"
                               " sample per axis at t = k / f_s, held until the next, whatever"
                               " the consumer's step (10 kHz: every controller step of 0.1 ms"
                               " or longer reads a fresh sample); used only with sensor.noise", "A")


@dataclass(frozen=True)
class Seal:
    """Seal cross-coupling at one axial station (physics/seal.py; effects.seal): F = -[[K, k],
    [-k, K]] r_s on the rotor axis displacement r_s at seal.z."""
    z: float = param(0.0, "m", -5.0, 5.0, "axial station of the seal (rotor frame)", "A")
    direct_stiffness: float = param(0.0, "N/m", -1e9, 1e9, "direct stiffness K", "A")
    cross_stiffness: float = param(2e5, "N/m", -1e9, 1e9,
                                   "cross-coupled stiffness k (> 0 drives a forward whirl)", "A")


@dataclass(frozen=True)
class Ground:
    """Base excitation (physics/ground.py; effects.base_excitation): the ground under the
    housings and the AMB stators accelerates by a half-sine pulse and/or a tabulated record; the
    model is written in the ground's frame (every body feels -m a_g)."""
    pulse_peak: float = param(0.0, "m/s^2", 0.0, 1e5, "half-sine pulse's peak acceleration A"
                              " (or ground.pulse_peak_g; 0: no pulse)", "A")
    pulse_peak_g: float = param(0.0, "g", 0.0, 1e4, "the pulse's peak in standard gravities"
                                " (9.80665 m/s^2; instead of ground.pulse_peak)", "A")
    pulse_duration: float = param(0.011, "s", 1e-4, 10.0, "the pulse's duration T (shock tests:"
                                  " ~6-18 ms)", "A")
    pulse_angle_deg: float = param(90.0, "deg", -360.0, 360.0, "direction of the pulse in the x-y"
                                   " plane, from +x towards +y (90: upward, against gravity)", "A")
    pulse_start: float = param(0.0, "s", 0.0, 100.0, "time t_0 the pulse starts", "A")
    record: str = param("", "-", doc="a tabulated acceleration record: the path of a CSV of t [s],"
                        " a_x, a_y [m/s^2] rows (linear between samples, zero outside; at most"
                        " 1024 rows); empty: none", tag="A")


@dataclass(frozen=True)
class UnbalanceChange:
    """A sudden unbalance change (physics/unbalance_change.py; effects.unbalance_change): at
    time t_s the rotor's unbalance steps from unbalance.* to the one given here (a blade or
    fragment loss), at the same axial station unbalance.z."""
    time: float = param(0.05, "s", 0.0, 100.0, "time t_s of the change", "A")
    mass: float = param(0.01, "kg", 0.0, 1.0, "unbalance mass m_u' after the change", "A")
    radius: float = param(0.0975, "m", 0.0, 1.0, "its radius e'", "A")
    angle_deg: float = param(90.0, "deg", -360.0, 360.0, "its angle from +X at spin angle 0 (as"
                             " unbalance.angle_deg)", "A")


@dataclass(frozen=True)
class ExternalLoad:
    """A transient external load on the rotor (physics/external_load.py; effects.external_load):
    a force of given peak, direction and axial position with a half-sine or a held-step time
    profile (a process load, possibly beyond the AMBs' force capacity)."""
    peak: float = param(0.0, "N", 0.0, 1e7, "peak force F", "A")
    angle_deg: float = param(-90.0, "deg", -360.0, 360.0, "direction of the force in the x-y"
                             " plane, from +x towards +y (-90: downward)", "A")
    z: float = param(0.0, "m", -5.0, 5.0, "axial position of the force (centre-of-mass frame);"
                     " a flexible rotor takes it at unbalance.z", "A")
    start: float = param(0.05, "s", 0.0, 100.0, "time t_0 the load starts", "A")
    duration: float = param(0.011, "s", 1e-5, 100.0, "duration T of the load", "A")
    profile: str = param("half_sine", "-", doc="time profile: half_sine (F sin(pi s / T)) or step"
                         " (F held for T, with linear ramps of external_load.ramp at both ends)",
                         choices=("half_sine", "step"), tag="A")
    ramp: float = param(0.0, "s", 0.0, 100.0, "rise and fall time of the step profile (<= T/2;"
                        " 0: a sharp step)", "A")


@dataclass(frozen=True)
class Flexible:
    """The flexible rotor (rotor.model = "flexible"; physics/flexible_rotor.py, docs/flexible.md):
    Timoshenko shaft elements reduced to the rigid-body motion plus elastic modes. The force
    stations are positions.* and unbalance.z, in the centre-of-mass frame."""
    shaft: str = param("paper", "-", doc="the shaft and disks: 'paper' (the paper rotor's m, I_d,"
                       " I_p on a stiff shaft, first bending 740 Hz), 'machine' (the same on a"
                       " slender shaft, first bending 399 Hz) or the path of a TOML rotor file"
                       " (rotordrop's, or ROSS's Rotor.save)", tag="A")
    modulus_scale: float = param(1.0, "-", 1e-3, 1e6, "factor on E and G_s of every shaft"
                                 " section (1000: the stiff limit)", "A")
    mode_cutoff_hz: float = param(2000.0, "Hz", 0.0, 1e6, "free-free bending modes below this"
                                  " frequency are kept", "A")
    static_modes: bool = param(False, "-", doc="add one static correction (inertia-relief"
                               " attachment) mode per force station, so that the local"
                               " compliance under a contact force is exact; they are the"
                               " highest modes and cost 2-5 x the steps (docs/accuracy.md:"
                               " what they change; docs/scaling.md: what they cost)", tag="A")
    damping_ratio: float = param(0.005, "-", 0.0, 1.0, "modal damping ratio zeta of every"
                                 " elastic mode (assumed; steel rotors 0.001-0.01)", "A")
    element_length: float = param(0.025, "m", 1e-4, 10.0, "longest shaft finite element", "A")


@dataclass(frozen=True)
class Effects:
    """Switches: an effect that is off adds no state and no right-hand-side work (spec §8)."""
    gravity: bool = param(True, "-", doc="gravity on all bodies")
    unbalance: bool = param(True, "-", doc="rotating unbalance force (adds the spin angle state)")
    gyroscopic: bool = param(True, "-", doc="gyroscopic coupling I_p Omega of the tilts")
    amb: str = param("linear", "-", doc="AMB model: linear spring-damper, or actuator (electromagnets,"
                     " current limit, PID; can be reactivated)", choices=("none", "linear", "actuator"))
    retainer_bearing: str = param("sopanen_mikkola", "-",
                                  doc="sleeve mount: rigid (moves with the housing), linear spring, or"
                                      " Sopanen-Mikkola ball bearing",
                                  choices=("rigid", "linear", "sopanen_mikkola"))
    ehl_film: bool = param(True, "-", doc="EHL film thickness in the ball contacts")
    bearing_friction: bool = param(True, "-", doc="retainer-bearing friction torque (M_0 + M_1 + M_s)")
    housing: bool = param(True, "-", doc="elastic housings (fixed to ground when off)")
    sleeve_inertia: bool = param(True, "-",
                                 doc="sleeve spin inertia; off = massless-sleeve limit (no spin state,"
                                     " the sleeve rolls with the rotor and transmits only the bearing"
                                     " drag)")
    thermal: bool = param(False, "-",
                          doc="friction heat warms each sleeve (one temperature state per plane"
                              " and two heat quadratures); the friction coefficient follows the"
                              " temperature (thermal.*); beyond the paper", tag="A")
    friction: str = param("kinematic", "-",
                          doc="rotor-sleeve friction slip law: kinematic (the friction opposes the"
                              " sliding velocity of the contact points, v = r Omega + e_t -"
                              " R omega_s, so it only dissipates) or paper (eq. 19 as printed: it"
                              " follows Omega - omega_s, which for r != R pushes along the sliding"
                              " and creates energy; for reproducing the paper, its metrics report"
                              " the energy created)",
                          choices=tuple(SLIP_LAWS))
    stator_contact: bool = param(False, "-",
                                 doc="rotor-stator contact at the AMB planes once the rotor reaches"
                                     " amb.air_gap (stator.* parameters; no state)", tag="A")
    stator_mount: bool = param(True, "-",
                               doc="with stator_contact: each AMB stator is a mass on a spring-damper"
                                   " mount (stator.mount_*; 4 states per AMB plane), so the"
                                   " contact and the mount share a whip's force; off: the stator is"
                                   " fixed to ground", tag="A")
    semi_active_damper: bool = param(False, "-",
                                     doc="support damping C_s is a controlled state lagging its command"
                                         " (needs housing; adds one state per housing)")
    seal: bool = param(False, "-",
                       doc="seal cross-coupling: a direct and cross-coupled stiffness load at"
                           " seal.z (seal.* parameters; no state)", tag="A")
    base_excitation: bool = param(False, "-",
                                  doc="the ground under the housings and AMB stators accelerates"
                                      " (ground.* parameters: a half-sine pulse and/or a record;"
                                      " no state)", tag="A")
    unbalance_change: bool = param(False, "-",
                                   doc="the rotor's unbalance steps to unbalance_change.* at"
                                       " unbalance_change.time (blade or fragment loss; no"
                                       " state)", tag="A")
    external_load: bool = param(False, "-",
                                doc="a transient external force on the rotor (external_load.*:"
                                    " half-sine or held step; no state)", tag="A")


#: the effects that are events for a levitated rotor (shock, unbalance change, external load):
#: a scene with one on is about the AMBs-on response, whether or not the AMBs fail later
EVENT_EFFECTS = ("base_excitation", "unbalance_change", "external_load")

GROUPS: dict[str, type] = {
    "rotor": Rotor, "positions": Positions, "unbalance": Unbalance, "world": World, "amb": Amb,
    "contact": Contact, "stator": Stator, "sleeve": Sleeve, "thermal": Thermal, "bearing": Bearing,
    "support": Support, "sensor": Sensor, "seal": Seal, "ground": Ground,
    "unbalance_change": UnbalanceChange, "external_load": ExternalLoad, "flexible": Flexible,
    "solver": Solver, "effects": Effects,
}


@dataclass(frozen=True)
class Scene:
    """A complete, validated description of one simulation (see module docstring)."""
    name: str = "custom"
    rotor: Rotor = field(default_factory=Rotor)
    positions: Positions = field(default_factory=Positions)
    unbalance: Unbalance = field(default_factory=Unbalance)
    world: World = field(default_factory=World)
    amb: Amb = field(default_factory=Amb)
    contact: Contact = field(default_factory=Contact)
    stator: Stator = field(default_factory=Stator)
    sleeve: Sleeve = field(default_factory=Sleeve)
    thermal: Thermal = field(default_factory=Thermal)
    bearing: Bearing = field(default_factory=Bearing)
    support: Support = field(default_factory=Support)
    sensor: Sensor = field(default_factory=Sensor)
    seal: Seal = field(default_factory=Seal)
    ground: Ground = field(default_factory=Ground)
    unbalance_change: UnbalanceChange = field(default_factory=UnbalanceChange)
    external_load: ExternalLoad = field(default_factory=ExternalLoad)
    flexible: Flexible = field(default_factory=Flexible)
    solver: Solver = field(default_factory=Solver)
    effects: Effects = field(default_factory=Effects)

    def __post_init__(self):
        for key, value, meta in _leaves(self):
            _check_leaf(key, value, meta)
        _check_consistency(self)

    # -- access ---------------------------------------------------------------------------
    def events(self) -> list[str]:
        """The events this scene switches on that push a levitated rotor (AMBs on) into its
        retainers: the names of :data:`EVENT_EFFECTS` that are on, in that order."""
        return [name for name in EVENT_EFFECTS if getattr(self.effects, name)]

    def get(self, key: str) -> Any:
        group, name = _split_key(key)
        return getattr(getattr(self, group), name)

    def with_overrides(self, overrides: Mapping[str, Any] | None = None, **kw) -> "Scene":
        """A new scene with dotted-key overrides applied (``{"contact.friction": 0.4}``)."""
        items = dict(overrides or {})
        items.update({k.replace("__", "."): v for k, v in kw.items()})
        nested: dict[str, dict[str, Any]] = {}
        for key, raw in items.items():
            group, name = _split_key(key)
            meta = _meta(group, name)
            nested.setdefault(group, {})[name] = _coerce(key, raw, meta)
        return self._replace(nested)

    def _replace(self, nested: Mapping[str, Mapping[str, Any]], name: str | None = None) -> "Scene":
        groups = {g: dataclasses.replace(getattr(self, g), **vals) if vals else getattr(self, g)
                  for g, vals in nested.items()}
        return dataclasses.replace(self, name=name or self.name, **groups)

    def to_dict(self) -> dict[str, dict[str, Any]]:
        return {g: dataclasses.asdict(getattr(self, g)) for g in GROUPS}

    def to_toml(self) -> str:
        lines = [f'# rotordrop scene "{self.name}"']
        for g, vals in self.to_dict().items():
            lines.append(f"\n[{g}]")
            for k, v in vals.items():
                lines.append(f"{k} = {_toml_value(v)}")
        return "\n".join(lines) + "\n"

    def flat(self) -> dict[str, Any]:
        return {key: value for key, value, _ in _leaves(self)}

    def to_json(self) -> str:
        """The scene as JSON: ``{"name": ..., group: {key: value}}`` (the ``dataclasses.asdict``
        form, as in a Gymnasium ``env.spec.to_json()``); :meth:`from_json` gives the same scene."""
        return json.dumps({"name": self.name, **self.to_dict()})

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], name: str = "custom") -> "Scene":
        """A scene from ``{"name": ..., group: {key: value}}`` (:meth:`to_dict`, :meth:`to_json`,
        ``dataclasses.asdict``); groups and keys left out keep the defaults. Every value is
        checked as a TOML value is."""
        data = dict(data)
        given = data.pop("name", name)
        if not isinstance(given, str):
            raise SceneError(f"scene name = {given!r} must be a string")
        return dataclasses.replace(cls().with_overrides(_flatten(data, given)), name=given)

    @classmethod
    def from_json(cls, text: str) -> "Scene":
        """The scene written by :meth:`to_json`."""
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise SceneError(f"malformed scene JSON: {exc}") from None
        if not isinstance(data, dict):
            raise SceneError(f"scene JSON must be an object {{group: {{key: value}}}}, got {data!r}")
        return cls.from_dict(data)


# ---------------------------------------------------------------------------------------------
# Presets, TOML and the public loading function
# ---------------------------------------------------------------------------------------------
def preset_names() -> list[str]:
    return sorted(p.name[:-5] for p in resources.files("physics.presets").iterdir()
                  if p.name.endswith(".toml"))


def load_scene(source: str | Path = "paper", overrides: Mapping[str, Any] | None = None) -> Scene:
    """A scene from a preset name or a TOML file path, with optional dotted overrides."""
    scene = _load_base(str(source), ())
    return scene.with_overrides(overrides) if overrides else scene


def _load_base(src: str, chain: tuple[str, ...], base_dir: Path | None = None) -> Scene:
    """The scene ``src`` names: a preset, or a TOML file (a relative path is read from
    ``base_dir``, the directory of the file whose ``base`` names it; else the current directory).
    ``chain``: the scenes that led here through ``base``, to refuse a cycle."""
    if src in preset_names():
        ident, path = src, None
    else:
        path = (base_dir / src) if base_dir is not None and not Path(src).is_absolute() else Path(src)
        if not path.is_file():
            what = f"base {src!r} of {chain[-1]}" if chain else f"scene {src!r}"
            raise SceneError(f"{what} is neither a preset ({', '.join(preset_names())}) nor an existing"
                             " TOML file" + (f" (looked for {path})" if chain else ""))
        ident = str(path.resolve())
    if ident in chain:
        raise SceneError("scene base chain is a cycle: " + " -> ".join(chain + (ident,)))
    if path is None:
        text = resources.files("physics.presets").joinpath(src + ".toml").read_text()
        return scene_from_toml(text, name=src, _chain=chain + (ident,))
    return scene_from_toml(path.read_text(), name=path.stem, base_dir=path.parent,
                           _chain=chain + (ident,))


def scene_from_toml(text: str, name: str = "custom", base_dir: Path | None = None,
                    _chain: tuple[str, ...] = ()) -> Scene:
    """A scene from TOML text; ``base = "NAME"`` starts from a preset or another TOML file (a
    relative path is read from ``base_dir``, the directory of the file the text comes from)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"malformed TOML in scene {name!r}: {exc}") from None
    data.pop("name", None)
    base_name = data.pop("base", None)
    if base_name is not None and not isinstance(base_name, str):
        raise SceneError(f"scene {name!r}: base = {base_name!r} must be a string: a preset name or"
                         " a TOML file path")
    base = _load_base(base_name, _chain, base_dir) if base_name else Scene()
    flat = _flatten(data, name)
    for key, suffix in (("flexible.shaft", ".toml"), ("ground.record", "")):
        path = flat.get(key)                     # a rotor file or a record beside the scene's
        if isinstance(path, str) and path and path.endswith(suffix) and base_dir is not None \
                and not Path(path).is_absolute():
            flat[key] = str(base_dir / path)
    scene = base.with_overrides(flat)
    return dataclasses.replace(scene, name=name)


def _flatten(data: Mapping[str, Any], name: str) -> dict[str, Any]:
    """``{group: {key: value}}`` -> ``{"group.key": value}`` (a TOML file's or a JSON scene's)."""
    flat: dict[str, Any] = {}
    for group, vals in data.items():
        if not isinstance(vals, Mapping):
            raise SceneError(f"scene {name!r}: top-level key {group!r} must be a table "
                             f"[{group}] (one of {', '.join(GROUPS)})")
        for k, v in vals.items():
            flat[f"{group}.{k}"] = v
    return flat


def parse_assignment(text: str) -> tuple[str, str]:
    """``"contact.friction=0.4"`` -> ``("contact.friction", "0.4")`` (CLI ``--set``)."""
    if "=" not in text:
        raise SceneError(f"--set expects KEY=VALUE, got {text!r}")
    key, value = text.split("=", 1)
    return key.strip(), value.strip()


def parameter_table() -> list[dict[str, Any]]:
    """Every key with unit, default, allowed range and provenance (``rotordrop params``)."""
    rows = []
    for key, value, meta in _leaves(Scene()):
        allowed = ("|".join(meta["choices"]) if meta["choices"] else
                   "true|false" if isinstance(value, bool) else
                   "name|path.toml" if isinstance(value, str) else
                   f"[{meta['lo']:g}, {meta['hi']:g}]")
        rows.append(dict(key=key, default=value, unit=meta["unit"], allowed=allowed,
                         tag=meta["tag"], doc=meta["doc"]))
    return rows


# ---------------------------------------------------------------------------------------------
# Validation helpers
# ---------------------------------------------------------------------------------------------
def _leaves(scene: Scene) -> Iterator[tuple[str, Any, dict]]:
    for g in GROUPS:
        obj = getattr(scene, g)
        for f in fields(obj):
            yield f"{g}.{f.name}", getattr(obj, f.name), f.metadata


def _split_key(key: str) -> tuple[str, str]:
    parts = key.split(".")
    if len(parts) != 2 or parts[0] not in GROUPS:
        raise SceneError(f"unknown parameter key {key!r}: keys are GROUP.NAME with GROUP one of "
                         f"{', '.join(GROUPS)} (see `rotordrop params`)")
    return parts[0], parts[1]


def _meta(group: str, name: str) -> dict:
    for f in fields(GROUPS[group]):
        if f.name == name:
            return dict(f.metadata, type=type(f.default))
    names = ", ".join(f.name for f in fields(GROUPS[group]))
    raise SceneError(f"unknown parameter key '{group}.{name}': {group} has {names}")


def param_meta(key: str) -> dict:
    """Unit, allowed range (``lo``, ``hi``) or ``choices``, source and type of ``GROUP.NAME``."""
    return _meta(*_split_key(key))


def _allowed(meta: dict) -> str:
    if meta.get("choices"):
        return "one of " + ", ".join(meta["choices"])
    return f"in [{meta['lo']:g}, {meta['hi']:g}] {meta['unit']}"


def _coerce(key: str, raw: Any, meta: dict) -> Any:
    """Convert a TOML/CLI value to the parameter's type; strings from --set are parsed."""
    typ = meta["type"]
    try:
        if typ is bool:
            if isinstance(raw, str):
                low = raw.lower()
                if low in ("true", "1", "on", "yes"):
                    return True
                if low in ("false", "0", "off", "no"):
                    return False
                raise ValueError
            if isinstance(raw, (bool, int)) and raw in (0, 1):
                return bool(raw)
            raise ValueError
        if typ is str:
            if not isinstance(raw, str):
                raise ValueError
            return raw
        if typ is int:
            val = float(raw)
            if not val.is_integer():
                raise ValueError
            return int(val)
        if isinstance(raw, bool):
            raise ValueError
        return float(raw)
    except (TypeError, ValueError):
        allowed = "true or false" if typ is bool else _allowed(meta)
        raise SceneError(f"{key} = {raw!r} is not a valid {typ.__name__}; allowed: {allowed}") from None


def _check_leaf(key: str, value: Any, meta: Mapping) -> None:
    if meta.get("choices"):
        if value not in meta["choices"]:
            raise SceneError(f"{key} = {value!r} is not allowed; {_allowed(meta)}")
        return
    if isinstance(value, bool) or meta.get("lo") is None:
        return
    if not (isinstance(value, (int, float)) and math.isfinite(value)):
        raise SceneError(f"{key} = {value!r} must be a finite number {_allowed(meta)}")
    if not meta["lo"] <= value <= meta["hi"]:
        raise SceneError(f"{key} = {value!r} is out of range: must be {_allowed(meta)}")


def _check_consistency(s: Scene) -> None:
    """Cross-parameter rules (each names the keys involved)."""
    if s.positions.amb1 >= s.positions.amb2:
        raise SceneError("positions.amb1 must be < positions.amb2 (AMB planes must differ)")
    if s.positions.rb1 >= s.positions.rb2:
        raise SceneError("positions.rb1 must be < positions.rb2 (retainer planes must differ)")
    _check_bearing_geometry(s)
    if s.solver.output_rate * s.solver.t_end > 5e7:
        raise SceneError("solver.output_rate x solver.t_end must be <= 5e7 samples "
                         f"(got {s.solver.output_rate * s.solver.t_end:.3g})")
    if s.solver.method == "fixed" and s.solver.t_end / s.solver.dt > 1e9:
        raise SceneError("solver.t_end / solver.dt must be <= 1e9 steps for the fixed-step method")
    if s.effects.amb == "actuator":
        _check_actuator(s)
    if s.rotor.model == "flexible":
        _check_flexible(s)
    if s.effects.thermal:
        _check_thermal(s)
    if s.effects.base_excitation:
        _check_ground(s)
    if s.effects.unbalance_change:
        _check_unbalance_change(s)
    if s.effects.external_load:
        _check_external_load(s)
    if s.effects.semi_active_damper:
        sp = s.support
        if not s.effects.housing:
            raise SceneError("effects.semi_active_damper needs effects.housing = true (the damper"
                             " acts between housing and ground)")
        if not sp.damping_min < sp.damping_max:
            raise SceneError(f"support.damping_min ({sp.damping_min:g}) must be < support.damping_max"
                             f" ({sp.damping_max:g})")
        if not sp.damping_min <= sp.damping <= sp.damping_max:
            raise SceneError(f"support.damping = {sp.damping:g} must lie in [support.damping_min,"
                             f" support.damping_max] = [{sp.damping_min:g}, {sp.damping_max:g}] N s/m"
                             " with effects.semi_active_damper")


def _check_flexible(s: Scene) -> None:
    """The flexible rotor's shaft exists and carries the scene's mass properties; the stations
    lie on it; the reduction is possible (physics/flexible/shafts.py names what is wrong)."""
    from .flexible.shafts import ShaftError, drop_rotor, mass_properties
    if s.effects.seal:
        raise SceneError("effects.seal = true: allowed only with rotor.model = 'rigid' (the seal"
                         " load has no station on the flexible rotor yet)")
    try:
        props = mass_properties(s)
        for key, value in props.items():
            given = s.get(key)
            if not math.isclose(given, value, rel_tol=1e-6):
                exact = ", ".join(f"{k} = {v!r}" for k, v in props.items())
                raise SceneError(
                    f"{key} = {given:g}: allowed {value!r} (to 1e-6) with rotor.model ="
                    f" 'flexible': the shaft {s.flexible.shaft!r} has m, I_d, I_p of {exact}"
                    f" (kg, kg m^2, kg m^2); set these rotor.* keys")
        drop_rotor(s)
    except ShaftError as exc:
        raise SceneError(str(exc)) from None


def _check_bearing_geometry(s: Scene) -> None:
    """The balls fit on the pitch circle; the sleeve bore R = r + c lies inside the inner raceway."""
    b = s.bearing
    d_max = b.pitch_diameter * math.sin(math.pi / b.balls)     # neighbouring balls touch
    if b.ball_diameter >= d_max:
        raise SceneError(f"bearing.ball_diameter = {b.ball_diameter * 1e3:.4g} mm is too large for"
                         f" bearing.balls = {b.balls} on bearing.pitch_diameter ="
                         f" {b.pitch_diameter * 1e3:.4g} mm: neighbouring balls overlap; need"
                         f" ball_diameter < pitch_diameter sin(pi / balls) = {d_max * 1e3:.4g} mm")
    bore = s.rotor.journal_radius + s.contact.clearance
    race = 0.5 * (b.pitch_diameter - b.ball_diameter)
    if bore >= race:
        raise SceneError(f"rotor.journal_radius + contact.clearance = {bore * 1e3:.4g} mm (the sleeve"
                         f" bore) must be < the inner raceway radius (bearing.pitch_diameter -"
                         f" bearing.ball_diameter) / 2 = {race * 1e3:.4g} mm: the sleeve and the"
                         f" inner ring sit between them")


def _check_ground(s: Scene) -> None:
    """One peak key at most; something to excite with; a readable record."""
    from .ground import load_record
    g = s.ground
    if g.pulse_peak > 0.0 and g.pulse_peak_g > 0.0:
        raise SceneError(f"ground.pulse_peak = {g.pulse_peak:g} m/s^2 and ground.pulse_peak_g ="
                         f" {g.pulse_peak_g:g} g: give the pulse's peak once (set the other to 0)")
    if g.pulse_peak == 0.0 and g.pulse_peak_g == 0.0 and not g.record:
        raise SceneError("effects.base_excitation = true needs ground.pulse_peak (or"
                         " ground.pulse_peak_g) > 0 or a ground.record file")
    if g.record:
        try:
            load_record(g.record)
        except ValueError as exc:
            raise SceneError(str(exc)) from None


def _check_unbalance_change(s: Scene) -> None:
    """The change has a rotating unbalance to change (its spin angle state)."""
    if not s.effects.unbalance or s.unbalance.mass * s.unbalance.radius == 0.0:
        raise SceneError("effects.unbalance_change = true needs effects.unbalance = true and"
                         " unbalance.mass x unbalance.radius > 0 (the unbalance that changes;"
                         f" got effects.unbalance = {s.effects.unbalance},"
                         f" unbalance.mass = {s.unbalance.mass:g} kg,"
                         f" unbalance.radius = {s.unbalance.radius:g} m)")


def _check_external_load(s: Scene) -> None:
    """A force to apply; ramps that fit in the step; a station on a flexible rotor."""
    e = s.external_load
    if e.peak == 0.0:
        raise SceneError("effects.external_load = true needs external_load.peak > 0 N")
    if e.profile == "step" and 2.0 * e.ramp > e.duration:
        raise SceneError(f"external_load.ramp = {e.ramp:g} s must be <= external_load.duration / 2"
                         f" = {0.5 * e.duration:g} s (a rise and a fall within the load)")
    if s.rotor.model == "flexible" and e.z != s.unbalance.z:
        raise SceneError(f"external_load.z = {e.z:g} m: with rotor.model = 'flexible' the load acts"
                         f" at the unbalance station; allowed only unbalance.z = {s.unbalance.z:g} m")


MIN_THERMAL_TIME_CONSTANT = 0.1     # s: a lumped sleeve cools no faster (physics/thermal.py)


def _check_thermal(s: Scene) -> None:
    """The sleeve's cooling time constant m_s c / G is physical and leaves the steps alone."""
    C = s.sleeve.mass * s.thermal.specific_heat
    G = s.thermal.conductance
    if G * MIN_THERMAL_TIME_CONSTANT > C:
        raise SceneError(f"thermal.conductance = {G:g} W/K is too high for the sleeve's heat capacity"
                         f" sleeve.mass x thermal.specific_heat = {C:.3g} J/K: the cooling time"
                         f" constant {C / G:.3g} s must be >= {MIN_THERMAL_TIME_CONSTANT:g} s"
                         f" (thermal.conductance <= {C / MIN_THERMAL_TIME_CONSTANT:.4g} W/K)")


def _check_actuator(s: Scene) -> None:
    """The actuator AMBs must be able to carry the rotor (spec §5)."""
    from .amb import actuator_constants, weight_shares
    a = s.amb
    if a.current_limit > a.bias_current:
        raise SceneError(f"amb.current_limit ({a.current_limit:g} A) must be <= amb.bias_current"
                         f" ({a.bias_current:g} A): a coil current cannot reverse")
    g = s.world.gravity if s.effects.gravity else 0.0
    shares = weight_shares(s.rotor.mass * g, s.positions.amb1, s.positions.amb2)
    c = actuator_constants(a, *shares)
    need = max(abs(f) for f in c.feedforward)
    if need > a.current_limit:
        raise SceneError(f"the actuator AMBs cannot carry the rotor: the weight share needs {need:.3g} A"
                         f" of control current at the centre, above amb.current_limit ="
                         f" {a.current_limit:g} A (raise amb.bias_current, amb.turns or amb.pole_area)")
    if a.kp * c.current_gain <= c.negative_stiffness:
        raise SceneError(f"amb.kp = {a.kp:g} A/m is too low: k_i kp = {a.kp * c.current_gain:.3g} N/m must"
                         f" exceed the negative stiffness k_s = {c.negative_stiffness:.3g} N/m")


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    return repr(v)
