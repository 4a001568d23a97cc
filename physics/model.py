"""The drop-down model compiled from a scene: state layout, packed parameters, right-hand side.

The model is composed of effects, one module each (:data:`EFFECTS`): each declares the scene keys
it reads, its named slots in the packed arrays (:mod:`physics.layout`), its states and how its
parameters pack. :data:`LAYOUT` is built from those declarations at import time, and the
module-level constants the kernels read (``P_M``, ``U_ICMD`` ...) are assigned from it by name
(numba compiles them in as constants). Effects are runtime flags in an int array (one compiled,
disk-cached kernel serves every scene); the state vector holds only the bodies and coordinates
the scene enables. Index -1 marks an absent coordinate, and the kernel never touches it.

Packed arrays passed to every kernel:

* ``P`` float64 parameters (indices ``P_*``),
* ``I`` int64 flags and state indices (``F_*`` flags, ``S_*`` rotor indices, per-plane blocks),
* ``U`` float64 controls that may change between integration segments (``U_*``).

Code above physics reads them by name: :meth:`Model.param`, :meth:`Model.state_index`,
:meth:`Model.control_index` and the helpers of :class:`Model`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import amb as amb_mod
from . import ball_bearing, contact, rotor, sensor, stator, support, thermal
from .amb import AMB_ACTUATOR, AMB_AXES, AMB_LINEAR, AMB_NONE  # noqa: F401  (re-exported)
from .ball_bearing import (RB_LINEAR, RB_RIGID, RB_SM, ball_forces, ball_forces_with_dry,  # noqa: F401
                           drag_torque_magnitude, film_thickness)
from .contact import (FRIC_KINEMATIC, FRIC_NONE, FRIC_PAPER, LAW_HERTZ_LINE,  # noqa: F401
                      LAW_PAPER, STANDARD_GRAVITY, contact_potential, friction_force, geometry,
                      hunt_crossley, line_elastic_force, line_potential, normal_force,
                      smooth_sign)
from ._jit import njit, njit_borrow
from .layout import Layout, StateSizes
from .rotor import axis_at, rotor_energy, tilt_accelerations, unbalance_load
from .scene import Scene
from . import sensor as sensor_mod
from . import flexible_rotor, seal
from .flexible_rotor import elastic_motion, elastic_rates, damping_power, tilt_coupling, elastic_energy
from .seal import seal_load
from .stator import mount_energy, mount_power, mount_rates, stator_force, stator_potential
from .support import (body_energy, damper_rate, housing_rates, spin_energy, spring_energy,
                      support_power)

VELOCITY = 0.1      # m/s: size of translational velocities (a free fall through the gap: 0.077 m/s)


class EnergyAudit:
    """The energy audit (part of every model): the flag and the two quadratures, dissipated
    energy and work of external / non-potential forces; tolerance size the rotor's kinetic energy
    at VELOCITY, observation size its spin energy (about all a drop can dissipate: the
    observations stay within about [-1, 1])."""
    SCENE_KEYS: tuple[str, ...] = ()

    @staticmethod
    def declare(layout) -> None:
        layout.index.add("flag.audit")
        layout.index.add("state.E_dissipated")
        layout.index.add("state.W_external")

    @staticmethod
    def pack(scene, P, I, layout) -> None:
        I[layout.index["flag.audit"]] = 1

    @staticmethod
    def states(scene, I, layout, sizes, add) -> None:
        for name in ("E_dissipated", "W_external"):
            I[layout.index["state." + name]] = add(name, sizes.energy, sizes.spin_energy)


#: the registered effects, in the order their states are laid out (adding an effect: one line)
EFFECTS = (rotor, contact, ball_bearing, amb_mod, support, EnergyAudit, thermal, stator, sensor,
           seal, flexible_rotor)
#: the packed arrays' named slots, from the effects' declarations
LAYOUT = Layout.build(EFFECTS)
_P, _I, _J, _U, _A, _AP = (LAYOUT.params, LAYOUT.index, LAYOUT.plane, LAYOUT.controls,
                           LAYOUT.aux, LAYOUT.plane_aux)

# ---------------------------------------------------------------------------- parameters P --
P_M, P_IP, P_ID, P_G, P_RJ = _P.indices("rotor.mass", "rotor.polar_inertia",
                                        "rotor.diametral_inertia", "world.gravity",
                                        "rotor.journal_radius")
# the force stations' block: station s is at P[P_Z_RB1 + s] (ST_* below)
P_Z_RB1, P_Z_RB2, P_Z_AMB1, P_Z_AMB2, P_Z_UB = _P.indices("rb1.z", "rb2.z", "amb1.z", "amb2.z",
                                                         "unbalance.z")
ST_RB1, ST_AMB1, ST_UB = P_Z_RB1 - P_Z_RB1, P_Z_AMB1 - P_Z_RB1, P_Z_UB - P_Z_RB1
P_MUE, P_UB_PHASE = _P.indices("unbalance.me", "unbalance.phase")
# flexible rotor (physics/flexible_rotor.py): omega^2, 2 zeta omega, station shapes (MAX_MODES
# per station), tilt-to-mode and mode-to-mode gyroscopic couplings
P_FX_W2, P_FX_DAMP, P_FX_SHAPE, P_FX_G1, P_FX_G = _P.indices(
    "flex.omega2", "flex.damping", "flex.shape", "flex.gyro_rigid", "flex.gyro")
FX_ROW = flexible_rotor.MAX_MODES
P_CLR, P_RS, P_KC, P_EC, P_CMAX, P_DC, P_MU, P_WL, P_VL, P_HL_A, P_HL_CHI = _P.indices(
    "contact.clearance", "sleeve.radius", "contact.stiffness", "contact.exponent",
    "contact.damping", "contact.damping_depth", "contact.friction", "contact.threshold_speed",
    "contact.threshold_velocity", "contact.line_coefficient", "contact.hysteresis")
(P_MS, P_JS, P_NB, P_HALF_PLAY, P_KTOT, P_FILM, P_CB, P_KLIN, P_CAGE, P_M0_LOW, P_M0_COEF,
 P_M1_COEF, P_MSEAL) = _P.indices(
    "sleeve.mass", "sleeve.spin_inertia", "bearing.balls", "bearing.half_play",
    "bearing.stiffness", "bearing.film_coef", "bearing.damping", "bearing.linear_stiffness",
    "bearing.cage_ratio", "bearing.m0_low", "bearing.m0_coef", "bearing.m1_coef",
    "bearing.seal_torque")
P_K_AMB, P_C_AMB, P_AMB_BIAS1, P_AMB_BIAS2 = _P.indices("amb.stiffness", "amb.damping",
                                                        "amb1.bias", "amb2.bias")
# actuator AMBs (spec §5): k cos(alpha), g_0, i_0, current limit, current/gap cap, PID gains,
# derivative filter, coil lag, lift-off ramp, gravity feed-forward currents of AMB1/AMB2
(P_AMB_KMAG, P_AMB_G0, P_AMB_I0, P_AMB_ILIM, P_AMB_RMAX, P_AMB_KP, P_AMB_KI, P_AMB_KD,
 P_AMB_TD, P_AMB_TL, P_AMB_RAMP) = _P.indices(*amb_mod.ACTUATOR_PARAMS)
P_AMB_IFF1, P_AMB_IFF2 = _P.indices("amb1.feedforward_current", "amb2.feedforward_current")
# support (spec §1) and semi-active damper (spec §6): K_s, housing mass, C_min, C_max, lag
P_KS, P_MH, P_CS_MIN, P_CS_MAX, P_CS_TAU = _P.indices(
    "support.stiffness", "support.housing_mass", "support.damping_min", "support.damping_max",
    "support.damper_time_constant")
# rotor-stator contact (physics/stator.py) and the stator mount (effects.stator_mount)
P_ST_GAP, P_ST_K, P_ST_C, P_ST_MU, P_ST_R, P_ST_VL, P_STM_K, P_STM_C, P_STM_M = _P.indices(
    "stator.gap", "stator.stiffness", "stator.damping", "stator.friction", "stator.rotor_radius",
    "stator.threshold_velocity", "stator.mount_stiffness", "stator.mount_damping",
    "stator.mount_mass")
# sleeve heating (effects.thermal, physics/thermal.py), one block in thermal.PARAM_NAMES order
P_TH_C, P_TH_G, P_TH_A, P_TH_SLOPE, P_TH_RMIN, P_TH_RMAX, P_TH_B = _P.indices(*thermal.PARAM_NAMES)
# position sensing (scene group sensor, physics/sensor.py): delay tau
P_SENS_TAU = _P["sensor.delay"]
# seal cross-coupling (physics/seal.py): station, direct and cross-coupled stiffness
P_SEAL_Z, P_SEAL_K, P_SEAL_KC = _P.indices("seal.z", "seal.direct_stiffness", "seal.cross_stiffness")
N_P = _P.size

# ------------------------------------------------------------------- flags and indices I --
F_GRAV, F_UNB, F_GYRO, F_AMB, F_RB, F_FILM, F_BFRIC, F_HOUSING, F_SLEEVE_J, F_FRIC, F_AUDIT = (
    _I.indices("flag.gravity", "flag.unbalance", "flag.gyroscopic", "flag.amb",
               "flag.retainer_bearing", "flag.ehl_film", "flag.bearing_friction", "flag.housing",
               "flag.sleeve_inertia", "flag.friction", "flag.audit"))
# flags: rotor-stator contact on/off, rotor-sleeve contact law (LAW_*), position sensing (on
# when sensor.delay or sensor.noise > 0)
F_STATOR, F_LAW, F_SENSOR, F_SEAL = _I.indices("flag.stator", "flag.law", "flag.sensor",
                                               "flag.seal")
S_X, S_Y, S_A, S_B, S_VX, S_VY, S_VA, S_VB, S_W, S_PHI = _I.indices(
    *("state." + n for n in rotor.STATE_NAMES + ("phi",)))
S_EDISS, S_WEXT = _I.indices("state.E_dissipated", "state.W_external")
# elastic modes of a flexible rotor: their number (0: rigid) and the first modal state
I_FX_N, I_FX = _I.indices("flex.modes", "state.elastic")
# per retainer plane k, the block I[I_PLANES + k*N_PLANE_IDX + j]:
I_PLANES = _I["planes"]
J_SX, J_SY, J_SVX, J_SVY, J_TH, J_WS = _J.indices(*ball_bearing.PLANE_STATES)
J_HX, J_HY, J_HVX, J_HVY = _J.indices(*support.PLANE_STATES)
N_PLANE_IDX = _J.size
# first state of a block (-1 when absent): actuator PID integrals, derivative-filter states and
# coil currents (4 axes each: AMB_AXES), damper C_s (2 housings), sleeve temperatures of RB1 and
# RB2 then the heat audit's heat_lost and friction_work (thermal.STATE_NAMES), the stators on
# their mounts (x, y, vx, vy of AMB1's, then AMB2's), the Pade delay states q1, q2 of AMB1 x,
# AMB1 y, AMB2 x, AMB2 y (physics/sensor.py)
I_AMB_INT, I_AMB_FILT, I_AMB_COIL, I_CS, I_THERM, I_STM, I_SENS = _I.indices(
    "state.amb_integral", "state.amb_filter", "state.amb_current", "state.damper",
    "state.thermal", "state.stator_mount", "state.sensor")
N_I = _I.size
MOUNT_STRIDE = len(stator.MOUNT_STATES)      # the stator-mount states of one AMB plane

# ------------------------------------------------------------------------- controls U --
# U_AMB_POWER > 0: the AMBs run under their built-in controller (linear law or PID);
# U_CS1/2: support damping of each housing (the damper's command with effects.semi_active_damper).
# Actuator level only: U_AMB_DIRECT > 0 applies the control currents U_ICMD + j (j = axis, see
# AMB_AXES) instead of the PID; U_T_ON is the time the PID was switched on and U_REF0 + j the
# reference it ramps from (spec §5 reactivation). A supervisor over the PID (the environments'
# ``command="supervisor"``) shifts the reference of AMB plane k by U_REF_OFF + 2k (radial) and
# U_REF_OFF + 2k + 1 (tangential, along a forward orbit) [m] in the frame of the sensed orbit
# (:func:`orbit_offset`) and scales the three PID gains by U_AMB_GAIN (1 = the scene's gains).
# With position sensing (I[F_SENSOR]) U_SENS_NOISE + j is the noise sample [m] of AMB axis j
# (AMB_AXES) that the sensed displacement carries until the next sample (physics/sensor.py).
U_AMB_POWER, U_AMB_DIRECT, U_ICMD, U_T_ON, U_REF0, U_REF_OFF, U_AMB_GAIN = _U.indices(
    "amb.power", "amb.direct", "amb.current_command", "amb.t_on", "amb.reference0",
    "amb.reference_offset", "amb.gain")
U_CS1, U_CS2 = _U.indices("rb1.support_damping", "rb2.support_damping")
U_SENS_NOISE = _U["sensor.noise"]
N_U = _U.size

# ------------------------------------------------------------------- diagnostics aux --
# per plane k at aux[k*N_AUX_PLANE + j] (contact.PLANE_DIAGNOSTICS); A_P* are the powers [W]
# each dissipative element takes out of the mechanical energy (physics/dissipation.py checks
# each is >= 0): contact friction, contact normal damping, ball-bearing dashpot, bearing drag,
# support dashpot
(A_FR, A_FMU, A_DELTA, A_LOAD, A_WS, A_DRAG, A_PFRIC, A_QMAX, A_PCDAMP, A_PBDAMP, A_PDRAG,
 A_PSUPPORT) = _AP.indices(*contact.PLANE_DIAGNOSTICS)
N_AUX_PLANE = _AP.size
# then per AMB plane k: the stator's normal force at aux[A_STATOR + k] (zero without stator
# contact), the stator contact's dashpot and friction powers at A_ST_PDAMP + k, A_ST_PFRIC + k,
# and its mount's dashpot (effects.stator_mount) at A_ST_PMOUNT + k
A_STATOR, A_ST_PDAMP, A_ST_PFRIC, A_ST_PMOUNT = _A.indices(
    "stator.normal_force", "stator.damping_power", "stator.friction_power", "stator.mount_power")
# the flexible rotor's station forces (x, y per station: the rhs's scratch for the modal forces;
# in the output samples' diagnostics only the contact and stator forces, the dy = None variant
# skips the AMBs and the unbalance) and its modal damping power
A_STF, A_FX_PDAMP = _A.indices("rotor.station_force", "rotor.damping_power")
N_AUX = _A.size

PLANES = ("RB1", "RB2")


@dataclass(frozen=True)
class Model:
    """A scene compiled for the kernels. ``names[i]`` names state i; ``scale[i]`` its size for
    the integrator's absolute tolerance (rtol x scale) and ``obs_scale[i]`` its physical size for
    observations (``full_state``): equal except where the tolerance is deliberately tighter
    (tilt rates, housing, energy-audit quadratures; see :func:`build_model`).

    Code above physics reads the packed arrays by name: :meth:`state_index`, :meth:`param`,
    :meth:`param_index`, :meth:`control_index`, :meth:`flag`, and the helpers below."""
    scene: Scene
    P: np.ndarray
    I: np.ndarray
    names: tuple[str, ...]
    scale: np.ndarray
    obs_scale: np.ndarray

    @property
    def n_state(self) -> int:
        return len(self.names)

    @property
    def layout(self) -> Layout:
        """The packed arrays' named slots (the same for every model)."""
        return LAYOUT

    def index(self, name: str) -> int:
        return self.names.index(name)

    def state_index(self, name: str) -> int:
        """Index of state ``name`` (``model.names``) in the state vector; KeyError naming it
        when this model has no such state (its effect is off, or the name is wrong)."""
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(f"unknown state {name!r}: this model's states are "
                           + ", ".join(self.names)) from None

    def has_state(self, name: str) -> bool:
        return name in self.names

    def param_index(self, name: str) -> int:
        """Index of parameter ``name`` in ``P`` (``physics.model.LAYOUT.params``); KeyError
        naming it when there is no such parameter."""
        return LAYOUT.params[name]

    def param(self, name: str) -> float:
        """The packed value of parameter ``name`` (SI units)."""
        return float(self.P[LAYOUT.params[name]])

    def control_index(self, name: str) -> int:
        """First index of control ``name`` in ``U`` (``physics.model.LAYOUT.controls``)."""
        return LAYOUT.controls[name]

    def flag(self, name: str) -> int:
        """The runtime flag ``name`` (``"amb"``, ``"retainer_bearing"`` ...: ``flag.<name>``
        of ``physics.model.LAYOUT.index``)."""
        return int(self.I[LAYOUT.index["flag." + name]])

    @property
    def has_ball_bearing(self) -> bool:
        """The retainer bearings are Sopanen-Mikkola ball bearings."""
        return self.flag("retainer_bearing") == RB_SM

    @property
    def elastic_modes(self) -> int:
        """Elastic modes per bending plane of a flexible rotor (0: rigid)."""
        return int(self.I[I_FX_N])

    @property
    def has_ambs(self) -> bool:
        """The scene has AMBs (``effects.amb`` is not ``none``)."""
        return self.flag("amb") != AMB_NONE

    @property
    def sizes(self) -> dict[str, int]:
        """Lengths of the packed arrays a kernel caller allocates: ``P``, ``I``, ``U``, ``aux``."""
        return {"P": N_P, "I": N_I, "U": N_U, "aux": N_AUX}

    def retainer_z(self) -> tuple[float, float]:
        """Axial stations of the retainer planes RB1, RB2 [m]."""
        return self.param("rb1.z"), self.param("rb2.z")

    def amb_z(self) -> tuple[float, float]:
        """Axial stations of the AMB (sensor) planes AMB1, AMB2 [m]."""
        return self.param("amb1.z"), self.param("amb2.z")

    def sensor_positions(self, y: np.ndarray) -> np.ndarray:
        """(4,) x1, y1, x2, y2 [m]: the rotor axis at the AMB (sensor) planes in state ``y``."""
        return np.array([v for k in range(2)
                         for v in axis_motion(y, self.P, self.I, ST_AMB1 + k)[:2]])

    def rotor_axis_indices(self) -> np.ndarray:
        """State indices of the rotor's centre and tilt: x, y, a, b."""
        return np.array([self.state_index(n) for n in ("x", "y", "a", "b")])

    def controls(self, amb_power: bool) -> np.ndarray:
        """The control vector for a segment: AMB power and the support damping of each housing."""
        U = np.zeros(N_U)
        U[U_AMB_POWER] = 1.0 if amb_power else 0.0
        U[U_CS1] = U[U_CS2] = self.scene.support.damping
        U[U_AMB_GAIN] = 1.0
        return U


def build_model(scene: Scene) -> Model:
    """Compile a scene: each effect packs its parameters and flags, then lays out its states
    (only the enabled ones): the rotor's, each retainer plane's (sleeve, housing), then the other
    effects' in :data:`EFFECTS` order."""
    s = scene
    P = np.zeros(N_P)
    I = np.full(N_I, -1, dtype=np.int64)
    names: list[str] = []
    scale: list[float] = []
    obs_scale: list[float] = []
    c = s.contact.clearance
    omega0 = s.rotor.speed_rpm * math.pi / 30.0

    def add(name: str, size: float, obs: float | None = None) -> int:
        """State ``name``: tolerance size ``size``, observation size ``obs`` (default: size)."""
        names.append(name)
        scale.append(size)
        obs_scale.append(size if obs is None else obs)
        return len(names) - 1

    for effect in EFFECTS:
        effect.pack(s, P, I, LAYOUT)
    lever = max(abs(s.positions.rb1), abs(s.positions.rb2), 1e-3)
    spin = max(omega0, 100.0)
    sizes = StateSizes(clearance=c, tilt=c / lever, spin=spin, velocity=VELOCITY, lever=lever,
                       energy=0.5 * s.rotor.mass * VELOCITY ** 2,
                       spin_energy=0.5 * s.rotor.polar_inertia * spin ** 2)
    rotor.states(s, I, LAYOUT, sizes, add)
    for k, plane in enumerate(PLANES):
        for effect in EFFECTS:
            if hasattr(effect, "plane_states"):
                effect.plane_states(s, I, I_PLANES + k * N_PLANE_IDX, LAYOUT, sizes, plane, add)
    for effect in EFFECTS:
        if effect is not rotor and hasattr(effect, "states"):
            effect.states(s, I, LAYOUT, sizes, add)
    return Model(scene, P, I, tuple(names), np.asarray(scale), np.asarray(obs_scale))


# ------------------------------------------------------------------------------- kernels --
@njit_borrow
def axis_motion(y, P, I, s):
    """Rotor axis position and velocity (px, py, vx, vy) at force station s (``ST_RB1 + k``,
    ``ST_AMB1 + k``, ``ST_UB``; axial station P[P_Z_RB1 + s]): the rigid body's, plus the elastic
    modes' of a flexible rotor (physics/flexible_rotor.py)."""
    z = P[P_Z_RB1 + s]
    px, py = axis_at(z, y[I[S_X]], y[I[S_Y]], y[I[S_A]], y[I[S_B]])
    vx, vy = axis_at(z, y[I[S_VX]], y[I[S_VY]], y[I[S_VA]], y[I[S_VB]])
    if I[I_FX_N] > 0:
        ex, ey, evx, evy = elastic_motion(y, P, I[I_FX], I[I_FX_N], P_FX_SHAPE + s * FX_ROW)
        return px + ex, py + ey, vx + evx, vy + evy
    return px, py, vx, vy


@njit
def stator_motion(y, I, k):
    """Stator position and velocity at AMB plane k on its mount; zeros when fixed to ground."""
    i = I[I_STM]
    if i < 0:
        return 0.0, 0.0, 0.0, 0.0
    i += MOUNT_STRIDE * k
    return y[i], y[i + 1], y[i + 2], y[i + 3]


@njit
def delayed_motion(y, P, I, k, px, py, vx, vy):
    """The true motion (px, py, vx, vy) of AMB plane k as its sensors' delay passes it on (the
    Pade states, physics/sensor.py S1); unchanged without ``sensor.delay``."""
    i = I[I_SENS]
    if i >= 0:
        i += sensor_mod.STATES_PER_PLANE * k
        tau = P[P_SENS_TAU]
        px, vx = sensor_mod.delayed(px, vx, y[i], y[i + 1], tau)
        py, vy = sensor_mod.delayed(py, vy, y[i + 2], y[i + 3], tau)
    return px, py, vx, vy


@njit
def sensed_motion(y, P, I, U, k, px, py, vx, vy):
    """What the sensors of AMB plane k report of its true motion (px, py, vx, vy): delayed, plus
    the held noise samples U_SENS_NOISE (physics/sensor.py). Only called with I[F_SENSOR] set;
    the velocities carry the delay, not the noise."""
    px, py, vx, vy = delayed_motion(y, P, I, k, px, py, vx, vy)
    return px + U[U_SENS_NOISE + 2 * k], py + U[U_SENS_NOISE + 2 * k + 1], vx, vy


@njit
def housing_motion(y, I, k):
    """Housing (outer ring) position and velocity at retainer plane k; zeros when fixed."""
    base = I_PLANES + k * N_PLANE_IDX
    i = I[base + J_HX]
    if i < 0:
        return 0.0, 0.0, 0.0, 0.0
    j = I[base + J_HVX]
    return y[i], y[i + 1], y[j], y[j + 1]


@njit
def sleeve_motion(y, I, k):
    """Sleeve centre position and velocity at plane k (the housing's when rigidly mounted)."""
    base = I_PLANES + k * N_PLANE_IDX
    i, j = I[base + J_SX], I[base + J_SVX]
    if i < 0:
        i, j = I[base + J_HX], I[base + J_HVX]
        if i < 0:
            return 0.0, 0.0, 0.0, 0.0
    return y[i], y[i + 1], y[j], y[j + 1]


@njit_borrow
def rhs(t, y, P, I, U, dy, aux):
    """dy/dt of the drop-down model (spec §1, §3-6). Fills ``aux`` with per-plane diagnostics.

    ``dy = None``: the diagnostics alone (the output samples', :func:`diagnostics`), the same
    values bit for bit; numba compiles that variant without the blocks under ``dy is not None``
    (unbalance, AMBs, the bodies' and heat derivatives, the rotor's equations of motion), and
    the sums that only feed them (forces, moments, powers) go unused, and the second retainer
    plane copies the first one's diagnostics when its inputs are the first one's bit for bit
    (:func:`twin_planes`: a symmetric drop), which is what computing them again would give."""
    if dy is not None:
        for i in range(dy.shape[0]):
            dy[i] = 0.0
    m = P[P_M]
    g = P[P_G]
    vx, vy, va, vb = y[I[S_VX]], y[I[S_VY]], y[I[S_VA]], y[I[S_VB]]
    W = y[I[S_W]]
    Fx = 0.0
    Fy = -m * g
    Ma = 0.0            # sum z Fx
    Mb = 0.0            # sum z Fy
    T = 0.0             # spin torque
    p_diss = 0.0        # power dissipated by dampers, friction and drag
    p_ext = 0.0         # power of external and non-potential forces (unbalance, AMB, film, cage)
    n_fx = I[I_FX_N]    # elastic modes of a flexible rotor (0: rigid)
    for j in range(A_STF, A_FX_PDAMP + 1):
        aux[j] = 0.0

    # unbalance (physics/rotor.py)
    if dy is not None and I[F_UNB]:
        iphi = I[S_PHI]
        ux, uy, mx, my, p = unbalance_load(P[P_MUE], W, y[iphi], P[P_UB_PHASE], P[P_Z_UB],
                                           vx, vy, va, vb)
        Fx += ux
        Fy += uy
        Ma += mx
        Mb += my
        p_ext += p
        dy[iphi] = W
        if n_fx > 0:                             # the unbalance station's elastic motion
            aux[A_STF + 2 * ST_UB] += ux
            aux[A_STF + 2 * ST_UB + 1] += uy
            _, _, evx, evy = elastic_motion(y, P, I[I_FX], n_fx, P_FX_SHAPE + ST_UB * FX_ROW)
            p_ext += ux * evx + uy * evy

    # seal cross-coupling (physics/seal.py)
    if dy is not None and I[F_SEAL]:
        sx, sy, smx, smy, p = seal_load(P[P_SEAL_Z], P[P_SEAL_K], P[P_SEAL_KC], y[I[S_X]],
                                        y[I[S_Y]], y[I[S_A]], y[I[S_B]], vx, vy, va, vb)
        Fx += sx
        Fy += sy
        Ma += smx
        Mb += smy
        p_ext += p

    # AMBs (hold the rotor until the fault)
    amb = I[F_AMB]
    if dy is not None and (amb == AMB_ACTUATOR or (amb == AMB_LINEAR and U[U_AMB_POWER] > 0.0)):
        # actuator (spec §5): the PID states evolve only under the built-in controller; the
        # magnets pull while powered or driven directly. The per-axis law takes scalars so that
        # it compiles inline here (as an array-taking call it cost ~90 ns per axis)
        pid_on = U[U_AMB_POWER] > 0.0 and U[U_AMB_DIRECT] <= 0.0
        pulls = U[U_AMB_POWER] > 0.0 or U[U_AMB_DIRECT] > 0.0
        for k in range(2):
            z = P[P_Z_AMB1 + k]
            dx, dyy, ddx, ddy = axis_motion(y, P, I, ST_AMB1 + k)
            # the controller's view (physics/sensor.py): the true motion without sensing
            sx, sy, svx, svy = dx, dyy, ddx, ddy
            if I[F_SENSOR]:
                sx, sy, svx, svy = sensed_motion(y, P, I, U, k, dx, dyy, ddx, ddy)
            ox, oy = orbit_offset(sx, sy, U[U_REF_OFF + 2 * k], U[U_REF_OFF + 2 * k + 1],
                                  y[I[S_W]], P[P_CLR])
            if amb == AMB_LINEAR:
                fx = amb_mod.linear_force(sx, svx, P[P_K_AMB], P[P_C_AMB], 0.0)
                fy = amb_mod.linear_force(sy, svy, P[P_K_AMB], P[P_C_AMB], P[P_AMB_BIAS1 + k])
            else:
                fx = fy = 0.0
                for a in range(2):                      # x, then y axis of AMB k
                    j = 2 * k + a
                    d = dyy if a == 1 else dx
                    i_int, i_q = I[I_AMB_INT] + j, I[I_AMB_FILT] + j
                    i_cmd, e, de_int = amb_mod.actuator_command(
                        t, sy if a == 1 else sx, y[i_int], y[i_q], U[U_AMB_DIRECT],
                        U[U_AMB_POWER], U[U_ICMD + j],
                        U[U_T_ON], U[U_REF0 + j], oy if a == 1 else ox, P[P_AMB_ILIM],
                        P[P_AMB_RAMP], P[P_AMB_IFF1 + k] if a == 1 else 0.0,
                        U[U_AMB_GAIN] * P[P_AMB_KP],
                        U[U_AMB_GAIN] * P[P_AMB_KI], U[U_AMB_GAIN] * P[P_AMB_KD], P[P_AMB_TD])
                    i_act = i_cmd
                    if I[I_AMB_COIL] >= 0:               # first-order coil lag
                        ic = I[I_AMB_COIL] + j
                        i_act = y[ic]
                        dy[ic] = (i_cmd - i_act) / P[P_AMB_TL]
                    if pid_on:
                        dy[i_int] = de_int
                        dy[i_q] = (e - y[i_q]) / P[P_AMB_TD]
                    if pulls:
                        f = amb_mod.magnet_pair_force(i_act, d, P[P_AMB_KMAG], P[P_AMB_G0],
                                                      P[P_AMB_I0], P[P_AMB_RMAX])
                        if a == 1:
                            fy = f
                        else:
                            fx = f
            Fx += fx
            Fy += fy
            Ma += z * fx
            Mb += z * fy
            p_ext += fx * ddx + fy * ddy
            if n_fx > 0:
                aux[A_STF + 2 * (ST_AMB1 + k)] += fx
                aux[A_STF + 2 * (ST_AMB1 + k) + 1] += fy
    i_sens = I[I_SENS]
    if dy is not None and i_sens >= 0:           # sensor delay states (physics/sensor.py, S1)
        tau = P[P_SENS_TAU]
        for k in range(2):
            dx, dyy, _, _ = axis_motion(y, P, I, ST_AMB1 + k)
            sensor_mod.delay_rates(dx, dyy, y, i_sens + sensor_mod.STATES_PER_PLANE * k, tau, dy)

    # retainer planes: rotor-sleeve contact, sleeve on ball bearing, housing
    twin = False
    if dy is None:
        twin = twin_planes(y, P, I)
    for k in range(2):
        if twin and k == 1:
            for j in range(N_AUX_PLANE):
                aux[N_AUX_PLANE + j] = aux[j]
            continue
        base = I_PLANES + k * N_PLANE_IDX
        z = P[P_Z_RB1 + k]
        px, py, pvx, pvy = axis_motion(y, P, I, ST_RB1 + k)
        i_sx = I[base + J_SX]
        i_hx = I[base + J_HX]
        hx, hy, hvx, hvy = housing_motion(y, I, k)
        # the sleeve read is sleeve_motion() written out: as a call it costs ~40 ns per rhs here
        if i_sx >= 0:
            sx, sy = y[i_sx], y[i_sx + 1]
            svx, svy = y[I[base + J_SVX]], y[I[base + J_SVX] + 1]
        else:                                   # sleeve rigidly mounted in the housing
            sx, sy, svx, svy = hx, hy, hvx, hvy
        i_ws = I[base + J_WS]
        ws = y[i_ws] if i_ws >= 0 else 0.0
        mu = P[P_MU]
        if I[I_THERM] >= 0:                      # effects.thermal: mu follows the sleeve's heat
            mu = thermal.friction_coefficient(mu, y[I[I_THERM] + k], P[P_TH_SLOPE],
                                              P[P_TH_RMIN], P[P_TH_RMAX])

        # --- contact, eqs. 14-19 ---
        er, nx, ny = geometry(px - sx, py - sy)
        tx, ty = -ny, nx
        delta = er - P[P_CLR]
        rel_vx, rel_vy = pvx - svx, pvy - svy
        f_r = 0.0
        f_mu = 0.0
        p_fric = 0.0                             # power dissipated by the contact friction
        p_cdamp = 0.0                            # ... by the contact's normal damping
        p_drag = 0.0                             # ... by the retainer bearing's drag torque
        if delta > 0.0:
            ddelta = nx * rel_vx + ny * rel_vy
            if I[F_LAW] == LAW_PAPER:
                f_r, f_el = normal_force(delta, ddelta, P[P_KC], P[P_EC], P[P_CMAX], P[P_DC])
            else:
                f_el = line_elastic_force(delta, P[P_HL_A], P[P_CLR])
                f_r = hunt_crossley(f_el, ddelta, P[P_HL_CHI])
            p_cdamp = (f_r - f_el) * ddelta
            p_diss += p_cdamp
        et = tx * rel_vx + ty * rel_vy           # whirl velocity along t
        fric = I[F_FRIC]
        if fric != FRIC_NONE and f_r > 0.0:
            if I[F_SLEEVE_J]:
                if fric == FRIC_PAPER:
                    f_mu = friction_force(mu, f_r, W - ws, P[P_WL])
                else:
                    f_mu = friction_force(mu, f_r, et + W * P[P_RJ] - ws * P[P_RS], P[P_VL])
                p_fric = f_mu * (et + W * P[P_RJ] - ws * P[P_RS])
                p_diss += p_fric
            else:
                # massless-sleeve limit: the sleeve rolls at w* and passes on only the drag torque
                if fric == FRIC_PAPER:
                    w_roll = W
                    sgn = smooth_sign(W, P[P_WL])
                else:
                    w_roll = (et + W * P[P_RJ]) / P[P_RS]
                    sgn = smooth_sign(et + W * P[P_RJ], P[P_VL])
                drag = 0.0
                if I[F_BFRIC]:
                    drag = drag_torque_magnitude(w_roll, f_r, P[P_M0_LOW], P[P_M0_COEF],
                                                 P[P_M1_COEF], P[P_MSEAL]) / P[P_RS]
                f_mu = sgn * min(mu * f_r, drag)
                ws = w_roll * min(1.0, mu * f_r / drag) if drag > 0.0 else w_roll
                p_fric = f_mu * (et + W * P[P_RJ] - ws * P[P_RS])
                # all the rotor loses: p_fric plus the bearing drag f_mu ws R the sleeve passes on
                p_drag = f_mu * P[P_RS] * ws      # the drag F_mu R the sleeve passes on
                p_diss += f_mu * (et + W * P[P_RJ])
        # forces on the rotor at this plane: -F_r n - F_mu t, spin torque -r F_mu
        cfx = f_r * nx + f_mu * tx               # force on the sleeve side
        cfy = f_r * ny + f_mu * ty
        Fx -= cfx
        Fy -= cfy
        Ma -= z * cfx
        Mb -= z * cfy
        T -= P[P_RJ] * f_mu
        if n_fx > 0:
            aux[A_STF + 2 * (ST_RB1 + k)] -= cfx
            aux[A_STF + 2 * (ST_RB1 + k) + 1] -= cfy

        # --- retainer bearing between sleeve (inner ring) and housing (outer ring) ---
        bfx = 0.0                                # bearing force on the sleeve
        bfy = 0.0
        p_bdamp = 0.0                            # power of the bearing's dashpot c_b
        load = f_r
        qsum = 0.0
        qmax = 0.0                               # most heavily loaded ball (SM bearing only)
        dh_dw = 0.0
        ux, uy = sx - hx, sy - hy
        uvx, uvy = svx - hvx, svy - hvy
        i_th = I[base + J_TH]
        if I[F_RB] == RB_SM:
            h = 0.0
            if I[F_FILM]:
                h, dh_dw = film_thickness(ws, P[P_FILM])
            cage = P[P_CAGE] * y[i_th]
            if I[F_FILM] and i_ws < 0:
                # massless sleeve: the film follows the algebraic rolling speed, so the audit
                # keeps the ball potential at zero film (mechanical_energy) and counts the
                # film's share of the ball forces as a non-potential force (dV: the zero-film
                # cage derivative, to match); one pass over the balls gives both
                qx, qy, _, _, qsum, qmax, qx0, qy0, dV = ball_forces_with_dry(
                    ux, uy, cage, int(P[P_NB]), P[P_HALF_PLAY], h, P[P_KTOT])
                p_ext += (qx0 - qx) * uvx + (qy0 - qy) * uvy
            else:
                qx, qy, _, dV, qsum, qmax = ball_forces(ux, uy, cage, int(P[P_NB]),
                                                        P[P_HALF_PLAY], h, P[P_KTOT])
            bfx = -qx - P[P_CB] * uvx
            bfy = -qy - P[P_CB] * uvy
            load = math.sqrt(qx * qx + qy * qy)
            p_bdamp = P[P_CB] * (uvx * uvx + uvy * uvy)
            p_diss += p_bdamp
            p_ext += dV * P[P_CAGE] * ws          # cage rotation under load (no torque in the model)
            if dy is not None:
                dy[i_th] = ws
        elif I[F_RB] == RB_LINEAR:
            bfx = -P[P_KLIN] * ux - P[P_CB] * uvx
            bfy = -P[P_KLIN] * uy - P[P_CB] * uvy
            load = P[P_KLIN] * math.sqrt(ux * ux + uy * uy)
            p_bdamp = P[P_CB] * (uvx * uvx + uvy * uvy)
            p_diss += p_bdamp

        # --- sleeve spin ---
        drag_t = 0.0
        if i_ws >= 0:
            if I[F_BFRIC]:
                drag_t = drag_torque_magnitude(ws, load, P[P_M0_LOW], P[P_M0_COEF], P[P_M1_COEF],
                                               P[P_MSEAL]) * smooth_sign(ws, P[P_WL])
                p_drag = drag_t * ws
                p_diss += p_drag
            if dy is not None:
                dws = (P[P_RS] * f_mu - drag_t) / P[P_JS]
                dy[i_ws] = dws
                if I[F_RB] == RB_SM and I[F_FILM]:
                    # film growth changes the ball potential without a force doing work
                    p_ext += qsum * dh_dw * dws

        # --- sleeve translation ---
        if dy is not None and i_sx >= 0:
            ms = P[P_MS]
            dy[i_sx] = svx
            dy[I[base + J_SY]] = svy
            dy[I[base + J_SVX]] = (cfx + bfx) / ms
            dy[I[base + J_SVY]] = (cfy + bfy) / ms - g
        # --- housing ---
        # --- housing (physics/support.py) ---
        p_support = 0.0                          # power of the support dashpot C_s
        if i_hx >= 0:
            cs = U[U_CS1 + k]
            if I[I_CS] >= 0:                     # semi-active damper lags its command (spec §6)
                cs = y[I[I_CS] + k]
            p_support = support_power(hvx, hvy, cs)
            p_diss += p_support
        if dy is not None and i_hx >= 0:
            if I[I_CS] >= 0:
                dy[I[I_CS] + k] = damper_rate(U[U_CS1 + k], cs, P[P_CS_MIN], P[P_CS_MAX],
                                              P[P_CS_TAU])
            if i_sx >= 0:                        # reaction of the bearing
                rx, ry = -bfx, -bfy
            else:                                # sleeve in the housing: contact acts directly
                rx, ry = cfx, cfy
            i_hvx = I[base + J_HVX]
            dy[i_hx], dy[i_hx + 1], dy[i_hvx], dy[i_hvx + 1] = housing_rates(
                hx, hy, hvx, hvy, P[P_KS], cs, rx, ry, P[P_MH], g)

        o = k * N_AUX_PLANE
        aux[o + A_FR] = f_r
        aux[o + A_FMU] = f_mu
        aux[o + A_DELTA] = delta
        aux[o + A_LOAD] = load
        aux[o + A_WS] = ws
        aux[o + A_DRAG] = drag_t
        aux[o + A_PFRIC] = p_fric
        aux[o + A_QMAX] = qmax
        aux[o + A_PCDAMP] = p_cdamp
        aux[o + A_PBDAMP] = p_bdamp
        aux[o + A_PDRAG] = p_drag
        aux[o + A_PSUPPORT] = p_support

    i_heat = I[I_THERM]
    if dy is not None and i_heat >= 0:           # effects.thermal: sleeve heating, heat audit
        thermal.rates(y, dy, i_heat, aux[A_PFRIC], aux[A_PDRAG], aux[N_AUX_PLANE + A_PFRIC],
                      aux[N_AUX_PLANE + A_PDRAG], P[P_TH_C], P[P_TH_G], P[P_TH_A], P[P_TH_B])
    if I[F_STATOR]:                              # rotor-stator contact at the AMB planes
        for k in range(2):
            z = P[P_Z_AMB1 + k]
            px, py, pvx, pvy = axis_motion(y, P, I, ST_AMB1 + k)
            qx, qy, qvx, qvy = stator_motion(y, I, k)
            sfx, sfy, torque, f_n, _, p_sd, p_sf = stator_force(
                px - qx, py - qy, pvx - qvx, pvy - qvy, W, P[P_ST_GAP], P[P_ST_K], P[P_ST_C],
                P[P_ST_MU], P[P_ST_R], P[P_ST_VL])
            p_mount = 0.0
            i_q = I[I_STM]
            if i_q >= 0:                         # the stator on its mount takes the reaction
                i_q += MOUNT_STRIDE * k
                p_mount = mount_power(qvx, qvy, P[P_STM_C])
                p_diss += p_mount
                if dy is not None:
                    dy[i_q], dy[i_q + 1], dy[i_q + 2], dy[i_q + 3] = mount_rates(
                        sfx, sfy, qx, qy, qvx, qvy, P[P_STM_K], P[P_STM_C], P[P_STM_M])
            Fx += sfx
            Fy += sfy
            Ma += z * sfx
            Mb += z * sfy
            T += torque
            if n_fx > 0:
                aux[A_STF + 2 * (ST_AMB1 + k)] += sfx
                aux[A_STF + 2 * (ST_AMB1 + k) + 1] += sfy
            p_diss += p_sd + p_sf
            aux[A_STATOR + k] = f_n
            aux[A_ST_PDAMP + k] = p_sd
            aux[A_ST_PFRIC + k] = p_sf
            aux[A_ST_PMOUNT + k] = p_mount
    else:
        for j in range(A_STATOR, A_STF):
            aux[j] = 0.0
    if n_fx > 0:                                 # structural damping of the elastic modes
        p_fd = damping_power(y, P, I[I_FX], n_fx, P_FX_DAMP)
        aux[A_FX_PDAMP] = p_fd
        p_diss += p_fd

    if dy is None:
        return
    # rotor equations of motion
    dy[I[S_X]] = vx
    dy[I[S_Y]] = vy
    dy[I[S_A]] = va
    dy[I[S_B]] = vb
    dy[I[S_VX]] = Fx / m
    dy[I[S_VY]] = Fy / m
    if n_fx > 0:                                 # elastic modes (physics/flexible_rotor.py)
        spin = W if I[F_GYRO] else 0.0
        if spin != 0.0:
            cx, cy = tilt_coupling(y, P, I[I_FX], n_fx, P_FX_G1)
            Ma -= spin * cy
            Mb += spin * cx
        elastic_rates(y, P, I[I_FX], n_fx, aux, A_STF, P_FX_W2, P_FX_DAMP, P_FX_SHAPE, P_FX_G1,
                      P_FX_G, spin, va, vb, dy)
    aa, ab = tilt_accelerations(Ma, Mb, va, vb, W, P[P_ID], P[P_IP], I[F_GYRO])
    dy[I[S_VA]] = aa
    dy[I[S_VB]] = ab
    dy[I[S_W]] = T / P[P_IP]
    if I[F_AUDIT]:
        dy[I[S_EDISS]] = p_diss
        dy[I[S_WEXT]] = p_ext


@njit
def _same(a, b):
    """a and b are the same float bit for bit (0.0 and -0.0 differ, NaN never matches)."""
    return a == b and math.copysign(1.0, a) == math.copysign(1.0, b)


@njit_borrow
def twin_planes(y, P, I):
    """The second retainer plane's inputs to :func:`rhs` (rotor axis, sleeve and housing motion,
    sleeve speed, cage angle, sleeve temperature) are the first one's bit for bit, so are its
    diagnostics: what a symmetric rotor on symmetric supports keeps through a drop."""
    px, py, vx, vy = axis_motion(y, P, I, ST_RB1)
    qx, qy, wx, wy = axis_motion(y, P, I, ST_RB1 + 1)
    if not (_same(px, qx) and _same(py, qy) and _same(vx, wx) and _same(vy, wy)):
        return False
    for j in range(N_PLANE_IDX):                 # the plane's bodies: every state or none
        i = I[I_PLANES + j]
        if i >= 0 and not _same(y[i], y[I[I_PLANES + N_PLANE_IDX + j]]):
            return False
    i = I[I_THERM]
    return i < 0 or _same(y[i], y[i + 1])


#: the orbit frame's unit vectors are regularised within this fraction of the clearance of the
#: centre (an offset fades out there instead of jumping with the direction of a tiny orbit)
ORBIT_FRAME_CORE = 0.05


@njit
def orbit_offset(dx, dy, radial, tangential, spin, clearance):
    """(x, y) reference offset [m] of ``radial`` along the sensed displacement (dx, dy) and
    ``tangential`` perpendicular to it along a forward orbit (the direction of ``spin``), with
    unit vectors (dx, dy) / sqrt(r^2 + r_0^2), r_0 = ``ORBIT_FRAME_CORE`` x clearance."""
    if radial == 0.0 and tangential == 0.0:
        return 0.0, 0.0
    n = math.sqrt(dx * dx + dy * dy + (ORBIT_FRAME_CORE * clearance) ** 2)
    ux, uy = dx / n, dy / n
    s = 1.0 if spin >= 0.0 else -1.0
    return radial * ux - tangential * s * uy, radial * uy + tangential * s * ux


@njit
def amb_currents(t, y, P, I, U, out):
    """Control currents of the 4 actuator axes (AMB1 x, AMB1 y, AMB2 x, AMB2 y) now [A]: the coil
    currents when they lag, else the command of the law ``rhs`` applies."""
    for j in range(4):
        if I[I_AMB_COIL] >= 0:
            out[j] = y[I[I_AMB_COIL] + j]
            continue
        k = j // 2
        dx, dyy, ddx, ddy = axis_motion(y, P, I, ST_AMB1 + k)
        if I[F_SENSOR]:
            dx, dyy, _, _ = sensed_motion(y, P, I, U, k, dx, dyy, ddx, ddy)
        ox, oy = orbit_offset(dx, dyy, U[U_REF_OFF + 2 * k], U[U_REF_OFF + 2 * k + 1], y[I[S_W]],
                              P[P_CLR])
        out[j] = amb_mod.actuator_command(
            t, dyy if j % 2 == 1 else dx, y[I[I_AMB_INT] + j], y[I[I_AMB_FILT] + j],
            U[U_AMB_DIRECT], U[U_AMB_POWER], U[U_ICMD + j], U[U_T_ON], U[U_REF0 + j],
            oy if j % 2 == 1 else ox, P[P_AMB_ILIM], P[P_AMB_RAMP],
            P[P_AMB_IFF1 + k] if j % 2 == 1 else 0.0,
            U[U_AMB_GAIN] * P[P_AMB_KP], U[U_AMB_GAIN] * P[P_AMB_KI], U[U_AMB_GAIN] * P[P_AMB_KD],
            P[P_AMB_TD])[0]


@njit
def mechanical_energy(y, P, I):
    """Kinetic + gravitational + elastic energy (contact, balls, housing springs) [J]."""
    m = P[P_M]
    g = P[P_G]
    yy = y[I[S_Y]]
    vx, vy, va, vb = y[I[S_VX]], y[I[S_VY]], y[I[S_VA]], y[I[S_VB]]
    W = y[I[S_W]]
    E = rotor_energy(m, P[P_ID], P[P_IP], vx, vy, va, vb, W)
    if I[I_FX_N] > 0:
        E += elastic_energy(y, P, I[I_FX], I[I_FX_N], P_FX_W2)
    E += m * g * yy
    for k in range(2):
        base = I_PLANES + k * N_PLANE_IDX
        px, py, _, _ = axis_motion(y, P, I, ST_RB1 + k)
        hx, hy, hvx, hvy = housing_motion(y, I, k)
        sx, sy, svx, svy = sleeve_motion(y, I, k)
        if I[base + J_HX] >= 0:
            E += body_energy(P[P_MH], hvx, hvy, g, hy)
            E += spring_energy(P[P_KS], hx, hy)
        if I[base + J_SX] >= 0:
            E += body_energy(P[P_MS], svx, svy, g, sy)
        i_ws = I[base + J_WS]
        ws = y[i_ws] if i_ws >= 0 else 0.0
        if i_ws >= 0:
            E += spin_energy(P[P_JS], ws)
        er, _, _ = geometry(px - sx, py - sy)
        if I[F_LAW] == LAW_PAPER:
            E += contact_potential(er - P[P_CLR], P[P_KC], P[P_EC])
        else:
            E += line_potential(er - P[P_CLR], P[P_HL_A], P[P_CLR])
        if I[F_STATOR]:
            ax, ay, _, _ = axis_motion(y, P, I, ST_AMB1 + k)
            qx, qy, qvx, qvy = stator_motion(y, I, k)
            E += stator_potential(ax - qx, ay - qy, P[P_ST_GAP], P[P_ST_K])
            E += mount_energy(qx, qy, qvx, qvy, P[P_STM_K], P[P_STM_M])
        ux, uy = sx - hx, sy - hy
        if I[F_RB] == RB_SM:        # zero film without sleeve inertia (see rhs)
            h = film_thickness(ws, P[P_FILM])[0] if I[F_FILM] and i_ws >= 0 else 0.0
            _, _, V, _, _, _ = ball_forces(ux, uy, P[P_CAGE] * y[I[base + J_TH]], int(P[P_NB]),
                                           P[P_HALF_PLAY], h, P[P_KTOT])
            E += V
        elif I[F_RB] == RB_LINEAR:
            E += spring_energy(P[P_KLIN], ux, uy)
    return E


@njit
def diagnostics(T, Y, P, I, U, AUX):
    """Fill AUX[k] with the per-plane diagnostics at each output sample (post-processing)."""
    for k in range(Y.shape[0]):
        rhs(T[k], Y[k], P, I, U, None, AUX[k])


@njit
def energies(Y, P, I):
    out = np.empty(Y.shape[0])
    for k in range(Y.shape[0]):
        out[k] = mechanical_energy(Y[k], P, I)
    return out
