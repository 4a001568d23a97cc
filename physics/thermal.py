"""Friction heat in the retainer sleeves and the friction coefficient's temperature law
(``effects.thermal``; docs/physics.md, "Friction heat and mu(T)").

The paper keeps mu constant and names its change with heat and wear as the model's main
limitation. Here each retainer plane k's sleeve + inner ring is one lumped body at the
temperature rise theta_k above ambient, heat capacity C = m_s c (``sleeve.mass`` x
``thermal.specific_heat``). It takes the share a (``thermal.heat_partition``) of the rotor-sleeve
friction power P_k (``Result.friction_power``; the rest heats the rotor, whose ~45 kJ/K leave it
practically cold, so it counts as lost) and the share b (``thermal.drag_heat_partition``) of its
ball bearing's friction power D_k = M omega_s (the drag torque times the sleeve speed; the outer
ring, balls and oil take the rest), and loses G theta_k to the housing:

    C dtheta_k/dt = a P_k + b D_k - G theta_k,   mu_k = mu_0 clamp(1 + kappa theta_k, r_min, r_max)

Heat audit (states ``heat_lost`` and ``friction_work``): C (theta_1 + theta_2 - 2 theta_0) +
Q_lost = W_fric = integral of sum_k (P_k + D_k), with Q_lost = integral of sum_k [(1 - a) P_k +
(1 - b) D_k + G theta_k]. W_fric is part of the mechanical audit's E_dissipated.
"""
from __future__ import annotations

from ._jit import njit, njit_inline

STATE_NAMES = ("RB1.temperature", "RB2.temperature", "heat_lost", "friction_work")
SCENE_KEYS = ("thermal.*", "effects.thermal", "sleeve.mass", "contact.friction")
#: the parameters, in the order of :func:`parameters`: heat capacity, loss conductance, contact
#: heat partition, relative mu slope, mu ratio floor and ceiling, bearing heat partition
PARAM_NAMES = ("thermal.heat_capacity", "thermal.conductance", "thermal.heat_partition",
               "thermal.mu_slope", "thermal.mu_ratio_min", "thermal.mu_ratio_max",
               "thermal.drag_heat_partition")
TEMPERATURE_SIZE = 10.0          # K: tolerance size of a temperature state (atol = rtol x size)
TEMPERATURE_OBS = 100.0          # K: its observation size


def declare(layout) -> None:
    """The thermal parameters (one block, in PARAM_NAMES order) and the first state's slot."""
    layout.params.block(*PARAM_NAMES, consts=("P_TH_C", "P_TH_G", "P_TH_A", "P_TH_SLOPE",
                                              "P_TH_RMIN", "P_TH_RMAX", "P_TH_B"))
    layout.index.add("state.thermal", const="I_THERM")


def pack(scene, P, I, layout) -> None:
    """The thermal parameters (only with effects.thermal; zero otherwise)."""
    if scene.effects.thermal:
        first = layout.params[PARAM_NAMES[0]]
        P[first:first + len(PARAM_NAMES)] = parameters(scene)


def states(scene, I, layout, sizes, add) -> None:
    """Sleeve temperatures of RB1 and RB2, then the heat audit's heat_lost and friction_work."""
    if not scene.effects.thermal:
        return
    first = -1
    for name in STATE_NAMES:
        if name.endswith("temperature"):
            i = add(name, TEMPERATURE_SIZE, TEMPERATURE_OBS)
        else:
            i = add(name, sizes.energy, sizes.spin_energy)
        first = i if first < 0 else first
    I[layout.index["state.thermal"]] = first


def heat_capacity(scene) -> float:
    """C = m_s c of one sleeve + inner ring [J/K]."""
    return scene.sleeve.mass * scene.thermal.specific_heat


def time_constant(scene) -> float:
    """C / G [s]: how fast a warm sleeve cools to the housing (inf when adiabatic)."""
    g = scene.thermal.conductance
    return heat_capacity(scene) / g if g > 0.0 else float("inf")


def parameters(scene) -> tuple[float, ...]:
    """(C, G, a, kappa, r_min, r_max, b) in the order of the model's P_TH_* entries."""
    t = scene.thermal
    return (heat_capacity(scene), t.conductance, t.heat_partition, t.mu_slope, t.mu_ratio_min,
            t.mu_ratio_max, t.drag_heat_partition)


@njit
def friction_coefficient(mu0, theta, kappa, r_min, r_max):
    """mu(theta) = mu_0 clamp(1 + kappa max(theta, 0), r_min, r_max): linear in the temperature
    rise, bounded (a floor for oxide films, a ceiling for the paper's rise with heat and wear).
    Friction cannot cool a sleeve below ambient: a negative contact friction power (possible
    under the paper's slip definition, which sets the friction direction from Omega r + omega_s R
    rather than the surface slip) is kept in the heat audit but does not move mu; otherwise
    the sub-ambient "temperature" and mu feed each other (a 0.5 s undamped drop ran to
    -4e4 K and -29 MJ of friction work)."""
    r = 1.0 + kappa * max(theta, 0.0)
    if r < r_min:
        r = r_min
    elif r > r_max:
        r = r_max
    return mu0 * r


@njit
def rates(y, dy, i, p_fric1, p_drag1, p_fric2, p_drag2, C, G, a, b):
    """Write the rates of the thermal states y[i:i + 4] (STATE_NAMES: the two sleeve
    temperatures, heat_lost, friction_work) into ``dy`` for each plane's contact friction power
    ``p_fric`` and bearing friction power ``p_drag``."""
    dy[i], q1 = heat_rates(p_fric1, p_drag1, y[i], C, G, a, b)
    dy[i + 1], q2 = heat_rates(p_fric2, p_drag2, y[i + 1], C, G, a, b)
    q_lost = 0.0
    q_lost += q1
    q_lost += q2
    w_fric = 0.0
    w_fric += p_fric1 + p_drag1
    w_fric += p_fric2 + p_drag2
    dy[i + 2] = q_lost
    dy[i + 3] = w_fric


@njit
def heat_rates(p_fric, p_drag, theta, C, G, a, b):
    """(dtheta/dt, heat lost per second) of one sleeve + inner ring with the contact friction
    power ``p_fric`` and its ball bearing's friction power ``p_drag``."""
    loss = G * theta
    return (a * p_fric + b * p_drag - loss) / C, (1.0 - a) * p_fric + (1.0 - b) * p_drag + loss


@njit_inline
def contact_friction(y, P, I, k):
    """The rotor-sleeve friction coefficient at retainer plane k: the scene's, or with
    effects.thermal its value at the sleeve's temperature (:func:`friction_coefficient`)."""
    mu = P[P_MU]
    if I[I_THERM] >= 0:
        mu = friction_coefficient(mu, y[I[I_THERM] + k], P[P_TH_SLOPE], P[P_TH_RMIN],
                                  P[P_TH_RMAX])
    return mu


@njit_inline
def heat(y, P, I, dy, aux):
    """The thermal states' rates from both planes' friction and drag powers (aux)."""
    rates(y, dy, I[I_THERM], aux[A_PFRIC], aux[A_PDRAG], aux[N_AUX_PLANE + A_PFRIC],
          aux[N_AUX_PLANE + A_PDRAG], P[P_TH_C], P[P_TH_G], P[P_TH_A], P[P_TH_B])
