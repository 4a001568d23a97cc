"""Seal cross-coupling: the destabilising load of an annular seal or an impeller's gas forces.

An effect of the drop model (docs/architecture.md "Adding an effect"). At the axial station
``seal.z`` the rotor axis displaced by (x_s, y_s) = (x + z a, y + z b) feels

    [F_x]     [ K   k ] [x_s]
    [F_y] = - [-k   K ] [y_s]

(Childs, *Turbomachinery Rotordynamics*, 1993, ch. 4; the cross-coupled stiffness k > 0 drives
a forward whirl, Alford's and Wachel's estimates of aerodynamic cross-coupling have this form).
K is the seal's direct stiffness. The load is not a potential force for k != 0, so its power
F · v_s goes into the energy audit's external work. No state.
"""
from ._jit import njit, njit_inline
from .rotor import add_external, add_force_at

#: the scene keys this effect reads
SCENE_KEYS = ("seal.z", "seal.direct_stiffness", "seal.cross_stiffness", "effects.seal")


def declare(layout) -> None:
    """The station, the direct and cross-coupled stiffness, and the on/off flag."""
    layout.params.add_each("seal.z", "seal.direct_stiffness", "seal.cross_stiffness",
                           consts=("P_SEAL_Z", "P_SEAL_K", "P_SEAL_KC"))
    layout.index.add("flag.seal", const="F_SEAL")


def pack(scene, P, I, layout) -> None:
    p = layout.params
    I[layout.index["flag.seal"]] = scene.effects.seal
    P[p["seal.z"]] = scene.seal.z
    P[p["seal.direct_stiffness"]] = scene.seal.direct_stiffness
    P[p["seal.cross_stiffness"]] = scene.seal.cross_stiffness


@njit
def seal_load(z, K, k, x, y, a, b, vx, vy, va, vb):
    """(F_x, F_y, M_a, M_b, power) of the seal on the rotor (module docstring): the force at
    station z, its moments z F about the centre of mass, and F · v at the station."""
    xs, ys = x + z * a, y + z * b
    fx = -K * xs - k * ys
    fy = k * xs - K * ys
    return fx, fy, z * fx, z * fy, fx * (vx + z * va) + fy * (vy + z * vb)


@njit_inline
def force(y, P, I, load):
    """The load with the seal's force, moments and power added."""
    fx, fy, _, _, p = seal_load(P[P_SEAL_Z], P[P_SEAL_K], P[P_SEAL_KC], y[I[S_X]], y[I[S_Y]],
                                y[I[S_A]], y[I[S_B]], y[I[S_VX]], y[I[S_VY]], y[I[S_VA]],
                                y[I[S_VB]])
    return add_external(add_force_at(load, P[P_SEAL_Z], fx, fy), p)
