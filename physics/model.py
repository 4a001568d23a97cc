"""The drop-down model compiled from a scene: state layout, packed parameters, right-hand side.

The model is composed of effects, one module each (:data:`EFFECTS`): each declares the scene keys
it reads, its named slots in the packed arrays (:mod:`physics.layout`), its states, how its
parameters pack, and owns its part of the equations of motion (its force kernel and energy),
which :func:`rhs` calls in a fixed order. :data:`LAYOUT` is built from those declarations at
import time, and the constants the kernels read (``P_M``, ``U_ICMD`` ...) are generated from it
and bound into every effect module and this one (numba compiles them in as constants). Effects are runtime flags in an int array (one compiled,
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
from . import (ball_bearing, contact, external_load, flexible_rotor, ground, laws, rotor, seal,
               sensor, stator, support, thermal, unbalance_change)
from ._jit import njit, njit_borrow, njit_inline
from .amb import (AMB_ACTUATOR, AMB_AXES, AMB_LINEAR, AMB_NONE, ORBIT_FRAME_CORE,  # noqa: F401
                  amb_currents, orbit_offset)
from .ball_bearing import RB_LINEAR, RB_RIGID, RB_SM, sleeve_motion  # noqa: F401
from .layout import Layout, StateSizes
from .rotor import FX_ROW, ST_AMB1, ST_RB1, ST_UB, add_dissipated, axis_motion  # noqa: F401
from .scene import Scene
from .sensor import delayed_motion, sensed_motion  # noqa: F401
from .stator import MOUNT_STRIDE, stator_motion  # noqa: F401
from .support import housing_motion  # noqa: F401

VELOCITY = 0.1      # m/s: size of translational velocities (a free fall through the gap: 0.077 m/s)


class EnergyAudit:
    """The energy audit (part of every model): the flag and the two quadratures, dissipated
    energy and work of external / non-potential forces; tolerance size the rotor's kinetic energy
    at VELOCITY, observation size its spin energy (about all a drop can dissipate: the
    observations stay within about [-1, 1])."""
    SCENE_KEYS: tuple[str, ...] = ()

    @staticmethod
    def declare(layout) -> None:
        layout.index.add("flag.audit", const="F_AUDIT")
        layout.index.add("state.E_dissipated", const="S_EDISS")
        layout.index.add("state.W_external", const="S_WEXT")

    @staticmethod
    def pack(scene, P, I, layout) -> None:
        I[layout.index["flag.audit"]] = 1

    @staticmethod
    def states(scene, I, layout, sizes, add) -> None:
        for name in ("E_dissipated", "W_external"):
            I[layout.index["state." + name]] = add(name, sizes.energy, sizes.spin_energy)


#: the registered effects, in the order their states are laid out (adding an effect: one line)
EFFECTS = (rotor, contact, ball_bearing, amb_mod, support, EnergyAudit, thermal, stator, sensor,
           seal, flexible_rotor, ground, unbalance_change, external_load)
#: the packed arrays' named slots, from the effects' declarations
LAYOUT = Layout.build(EFFECTS)
#: the constants the kernels index the packed arrays with (``P_M``, ``U_ICMD``, ``A_FR`` ...),
#: generated from the effects' declarations (:meth:`physics.layout.Layout.constants`) and bound
#: into every effect module (whose kernels read them) and this one (for the kernels above
#: physics, e.g. the environments' batch step, which import them from here)
CONSTANTS = LAYOUT.constants()
for _effect in EFFECTS + laws.MODULES:
    if not isinstance(_effect, type):
        LAYOUT.bind(_effect)
globals().update(CONSTANTS)

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
def rhs(t, y, P, I, U, dy, aux):
    """dy/dt of the drop-down model (spec §1, §3-6). Fills ``aux`` with per-plane diagnostics.

    The registered effects' kernels (:func:`loads`), then the rotor's equations of motion and
    the energy audit's rates under their load (:func:`close`); a kernel of its own composes an
    effect that is not registered the same way (docs/howto/physical-effect.md).
    ``dy = None``: the diagnostics alone (:func:`loads`)."""
    load = loads(t, y, P, I, U, dy, aux)
    if dy is not None:
        close(t, y, P, I, dy, aux, load)


@njit_inline
def loads(t, y, P, I, U, dy, aux):
    """The effects' kernels in a fixed order, each under its runtime flag: they thread the
    rotor's **load** (:mod:`physics.rotor`: forces, moments, spin torque, dissipated and
    external power), write their own bodies' rates and their diagnostics; returns the load.

    ``dy = None``: the diagnostics alone (the output samples', :func:`diagnostics`), the same
    values bit for bit; numba compiles that variant without the blocks under ``dy is not None``
    (unbalance, seal, AMBs, the bodies' and heat derivatives, the rotor's equations of motion),
    and the sums that only feed them (forces, moments, powers) go unused, and the second
    retainer plane copies the first one's diagnostics when its inputs are the first one's bit
    for bit (:func:`twin_planes`: a symmetric drop), which is what computing them again would
    give."""
    if dy is not None:
        for i in range(dy.shape[0]):
            dy[i] = 0.0
    load = rotor.weight(P)
    flexible_rotor.clear_station_forces(aux)
    if dy is not None and I[F_UNB]:
        load = rotor.unbalance(y, P, I, dy, aux, load)
        if I[F_UCHANGE]:
            load = unbalance_change.force(t, y, P, I, aux, load)
    if dy is not None and I[F_XLOAD]:
        load = external_load.force(t, y, P, I, aux, load)
    if dy is not None and I[F_SEAL]:
        load = seal.force(y, P, I, load)
    if dy is not None and amb_mod.acting(I, U):
        load = amb_mod.force(t, y, P, I, U, dy, aux, load)
    if dy is not None and I[I_SENS] >= 0:
        sensor.delay_states(y, P, I, dy)

    # retainer planes: rotor-sleeve contact, sleeve on its bearing, housing on its support
    twin = False
    if dy is None:
        twin = twin_planes(y, P, I)
    for k in range(2):
        if twin and k == 1:
            for j in range(N_AUX_PLANE):
                aux[N_AUX_PLANE + j] = aux[j]
            continue
        px, py, pvx, pvy = axis_motion(y, P, I, ST_RB1 + k)
        hx, hy, hvx, hvy = housing_motion(y, I, k)
        sx, sy, svx, svy = sleeve_motion(y, I, k)
        i_ws = I[I_PLANES + k * N_PLANE_IDX + J_WS]
        ws = y[i_ws] if i_ws >= 0 else 0.0
        load, f_r, f_mu, cfx, cfy, ws, p_drag = contact.sleeve_contact(
            y, P, I, aux, k, load, px, py, pvx, pvy, sx, sy, svx, svy, ws)
        load, rx, ry = ball_bearing.sleeve_on_bearing(
            y, P, I, dy, aux, k, load, f_r, f_mu, cfx, cfy, ws, p_drag, sx, sy, svx, svy, hx, hy,
            hvx, hvy)
        load = support.housing(y, P, I, U, dy, aux, k, load, rx, ry)

    if dy is not None and I[I_THERM] >= 0:
        thermal.heat(y, P, I, dy, aux)
    if I[F_STATOR]:
        load = stator.contact(y, P, I, dy, aux, load)
    else:
        stator.clear(aux)
    if I[I_FX_N] > 0:
        load = add_dissipated(load, flexible_rotor.modal_damping(y, P, I, aux))
    if dy is not None and I[F_GROUND]:
        load = ground.inertial_forces(t, y, P, I, dy, load)
    return load


@njit_inline
def close(t, y, P, I, dy, aux, load):
    """The rotor's equations of motion under the load, and the energy audit's rates."""
    rotor.equations_of_motion(y, P, I, dy, aux, load)
    if I[F_AUDIT]:
        dy[I[S_EDISS]] = load[5]
        dy[I[S_WEXT]] = load[6]


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


@njit_borrow
def mechanical_energy(y, P, I):
    """Kinetic + gravitational + elastic energy [J]: the sum of the effects' energies (the
    rotor's, then per retainer plane the housing's, the sleeve's, the contact's, the stator's
    and the bearing's)."""
    E = rotor.energy(y, P, I)
    for k in range(2):
        px, py, _, _ = axis_motion(y, P, I, ST_RB1 + k)
        hx, hy, _, _ = housing_motion(y, I, k)
        sx, sy, svx, svy = sleeve_motion(y, I, k)
        E = support.energy(y, P, I, k, E)
        E = ball_bearing.sleeve_energy(y, P, I, k, E, sx, sy, svx, svy)
        E = contact.energy(y, P, I, k, E, px, py, sx, sy)
        if I[F_STATOR]:
            E = stator.energy(y, P, I, k, E)
        E = ball_bearing.bearing_energy(y, P, I, k, E, sx, sy, hx, hy)
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
