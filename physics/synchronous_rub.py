"""Steady synchronous forward rub with the AMBs on, by harmonic balance (docs/physics.md
"Persistent contact with the AMBs on", eqs. R1–R6).

The rotor presses into both retainer sleeves and whirls forward with its spin Ω on a circle: in
the frame turning with the whirl every quantity is constant. A symmetric machine (retainer planes
at ±z_b, AMB planes at ±z_a, the unbalance at the centre of mass) whirls in its cylindrical
mode, so one retainer plane carries half the rotor (m/2) and half the unbalance (U/2 = m_u ε/2).
With complex amplitudes in the contact's direction n = 1 (t = i n), one harmonic:

    (R1) rotor:     (K_amb(|X|) − m Ω²/2) X + (N + i F_μ) = (U/2) Ω² e^{iφ}
    (R2) contact:   X − S = c + δ,   N = F_r(δ, δ̇ = 0)  (the contact law; no damping in a
                    steady orbit: δ̇ = 0)
    (R3) sleeve:    −m_s Ω² S = (N + i F_μ) − B(u),    u = S − H
    (R4) housing:   −m_h Ω² H = B(u) − (K_s + i Ω C_s) H
    (R5) bearing:   B(u) = Q(|u|) u/|u| + i Ω c_b u   (the ball set's force averaged over the
                    cage angle, EHL film at the sleeve speed; or k_lin u + i Ω c_b u)
    (R6) friction:  F_μ = μ N sgn STEP(|v|, v_l),  v = Ω (c + δ) + Ω r − ω_s R, with the sleeve
                    spin in balance, R F_μ = M_drag(ω_s, |Q|)  (the kinematic slip law)

K_amb is the AMBs' describing function on the circular orbit: the fundamental of the magnet force
(its gap law and saturation) under the PID's current (clipped at the current limit, the coil lag
as a filter) over one revolution, −F₁/|X|; for a small orbit it is the PID's dynamic stiffness
k_i C(jΩ) H(jΩ) L(jΩ) − k_s (:func:`physics.amb.pid_dynamic_stiffness`; H: the sensor delay's
Padé), on the linear level (k_amb + i Ω c_amb) H. The PID's integral is taken unclipped (its
anti-windup changes it only while the current saturates; :attr:`RubSolution.current_peak`
says when).

Given δ, (R2)–(R6) fix N, F_μ, S and X; (R1) then holds for one magnitude of the unbalance
force, so a rub is a root δ of the scalar g(δ) = |LHS of R1| − (U/2) Ω², and the phase φ of
the unbalance force relative to the contact direction follows. :func:`rub_solutions` returns every
root on a grid of δ up to the contact law's validity bound. Gravity is not in the balance (it
would shift the orbit's centre): compare with runs without it.
"""
from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

import numpy as np

from . import laws
from .amb import actuator_constants, magnet_pair_force
from .ball_bearing import ball_forces, drag_torque_magnitude, film_thickness
from .laws.step import smooth_sign
from .model import (F_BFRIC, F_FILM, F_HOUSING, F_LAW, F_RB, P_CB, P_CLR, P_FILM, P_HALF_PLAY,
                    P_KLIN, P_KS, P_KTOT, P_M0_COEF, P_M0_LOW, P_M1_COEF, P_MH, P_MS, P_MSEAL,
                    P_MU, P_NB, P_RJ, P_RS, P_VL, RB_LINEAR, RB_SM, build_model)
from .roots import bisect_decreasing
from .scene import SceneError
from .sensor import pade_response
from .validity import validity_bound

#: samples per revolution of the AMB force's fundamental, cage angles of the ball set's mean
REVOLUTION_SAMPLES, CAGE_SAMPLES = 128, 8
#: penetration grid on which the roots of g(δ) are bracketed (log-spaced, from a tenth of a nm)
GRID_POINTS, GRID_LOW = 240, 1e-10


@dataclass(frozen=True)
class RubSolution:
    """One steady synchronous forward rub (per retainer plane; SI units, angles in degrees)."""
    speed: float              # Ω [rad/s]
    penetration: float        # δ
    amplitude: float          # |X|: the rotor's orbit radius at the retainer (and AMB) plane
    contact_force: float      # N
    friction_force: float     # F_μ (on the rotor along −t)
    phase_deg: float          # arg X − arg(unbalance force): the orbit's lead over the unbalance
    sleeve_amplitude: float   # |S|
    housing_amplitude: float  # |H|
    sleeve_speed: float       # ω_s [rad/s]
    amb_force: float          # |K_amb X|: the AMB force's fundamental [N]
    current_peak: float       # the PID's peak command |i| before clipping [A] (actuator level)
    residual: float           # |g(δ)| / ((U/2) Ω²) at the root


class RubPlant:
    """The model's parameters for the balance (built once per scene)."""

    def __init__(self, scene):
        check_rub_scene(scene)
        self.scene = scene
        self.model = build_model(scene)
        self.P, self.I = self.model.P, self.model.I
        u = scene.unbalance_change if scene.effects.unbalance_change else scene.unbalance
        self.U = u.mass * u.radius if scene.effects.unbalance else 0.0
        self.m = scene.rotor.mass
        self.c = self.P[P_CLR]
        self.bound = validity_bound(scene, "retainer").penetration

    # -- (R1): the AMBs ----------------------------------------------------------------
    def amb_stiffness(self, radius: float, omega: float) -> tuple[complex, float]:
        """(K_amb, the PID's peak command [A]) on a circular orbit of ``radius`` at ``omega``."""
        a, s = self.scene.amb, self.scene
        H = pade_response(omega, s.sensor.delay)
        if s.effects.amb == "linear":
            return (a.stiffness + 1j * omega * a.damping) * H, 0.0
        ac = actuator_constants(a, 0.0, 0.0)
        jw = 1j * omega
        C = a.kp + a.kd * jw / (1.0 + jw * a.derivative_filter) + (a.ki / jw if omega > 0 else 0)
        psi = 2.0 * np.pi * np.arange(REVOLUTION_SAMPLES) / REVOLUTION_SAMPLES
        r = max(radius, 1e-12)
        x = r * np.cos(psi)
        raw = -np.real(C * H * r * np.exp(1j * psi))
        cmd = np.clip(raw, -a.current_limit, a.current_limit)
        if a.coil_time_constant > 0.0:        # the coil lag on every harmonic of the command
            k = np.fft.rfftfreq(REVOLUTION_SAMPLES, 1.0 / REVOLUTION_SAMPLES)
            cmd = np.fft.irfft(np.fft.rfft(cmd) / (1.0 + 1j * k * omega * a.coil_time_constant),
                               REVOLUTION_SAMPLES)
        f = np.array([magnet_pair_force(i, xi, ac.force_constant, a.air_gap, a.bias_current,
                                        ac.ratio_max) for i, xi in zip(cmd, x)])
        f1 = 2.0 * np.mean(f * np.exp(-1j * psi))
        return -f1 / r, float(np.max(np.abs(raw)))

    # -- (R3)-(R5): sleeve and housing -------------------------------------------------
    def _housing(self, omega: float) -> complex:
        if not self.I[F_HOUSING]:
            return complex(np.inf)
        return self.P[P_KS] + 1j * omega * self.scene.support.damping - self.P[P_MH] * omega ** 2

    def _bearing(self, rho: float, omega: float, ws: float) -> tuple[complex, float]:
        """(B(u)/u, |Q|) for |u| = rho: the bearing's complex stiffness and its ball load."""
        P, cb = self.P, 1j * omega * self.P[P_CB]
        if self.I[F_RB] == RB_LINEAR:
            return P[P_KLIN] + cb, P[P_KLIN] * rho
        h = film_thickness(ws, P[P_FILM])[0] if self.I[F_FILM] else 0.0
        q = sum(complex(*ball_forces(rho, 0.0, 2 * math.pi * (k / CAGE_SAMPLES) / P[P_NB],
                                     int(P[P_NB]), P[P_HALF_PLAY], h, P[P_KTOT])[:2])
                for k in range(CAGE_SAMPLES)) / CAGE_SAMPLES
        return q / max(rho, 1e-15) + cb, abs(q)

    def support(self, f_s: complex, omega: float, ws: float) -> tuple[complex, complex, float]:
        """(S, H, bearing load) under the force ``f_s`` on the sleeve (R3–R5)."""
        Zh = self._housing(omega)
        if self.I[F_RB] not in (RB_LINEAR, RB_SM):        # the sleeve rides in its housing
            H = f_s / Zh if np.isfinite(Zh) else 0j
            return H, H, abs(f_s)
        ms = self.P[P_MS]

        def dyn(rho):                  # f_s = [kappa (1 - m_s w^2 / Z_h) - m_s w^2] u
            kappa, _ = self._bearing(rho, omega, ws)
            return kappa * (1.0 - ms * omega ** 2 / Zh) - ms * omega ** 2, kappa

        if abs(f_s) == 0.0:
            return 0j, 0j, 0.0
        hi = 1e-3
        rho = bisect_decreasing(lambda r: -abs(dyn(r)[0]) * r, -abs(f_s), 0.0, hi, 80)
        D, kappa = dyn(rho)
        u = f_s / D
        B = kappa * u
        H = B / Zh
        return H + u, H, self._bearing(rho, omega, ws)[1]

    # -- (R6): friction and sleeve spin ------------------------------------------------
    def friction(self, N: float, delta: float, omega: float, load: float) -> tuple[float, float]:
        """(F_μ, ω_s): the kinematic slip law's friction with the sleeve spin in balance."""
        P = self.P
        drive = omega * (self.c + delta) + omega * P[P_RJ]       # e_t + Ω r
        mu = P[P_MU]

        def net(ws):                   # R F_mu - M_drag, decreasing in ws
            f = mu * N * smooth_sign(drive - ws * P[P_RS], P[P_VL])
            m = drag_torque_magnitude(ws, load, P[P_M0_LOW], P[P_M0_COEF], P[P_M1_COEF],
                                      P[P_MSEAL]) if self.I[F_BFRIC] else 0.0
            return P[P_RS] * f - m

        ws = bisect_decreasing(net, 0.0, 0.0, 2.0 * drive / P[P_RS], 100)
        return mu * N * smooth_sign(drive - ws * P[P_RS], P[P_VL]), ws

    # -- the balance -------------------------------------------------------------------
    def state(self, delta: float, omega: float) -> dict:
        """Everything (R2)–(R6) fix at penetration ``delta``, and the left side of (R1)."""
        N = float(laws.normal_force(int(self.I[F_LAW]), delta, 0.0, self.P)[0])
        f_mu, ws, load = 0.0, omega * (self.P[P_RJ] + self.c + delta) / self.P[P_RS], N
        for _ in range(3):             # the drag depends on the bearing load and back
            S, H, load = self.support(N + 1j * f_mu, omega, ws)
            f_mu, ws = self.friction(N, delta, omega, load)
        S, H, load = self.support(N + 1j * f_mu, omega, ws)
        X = S + self.c + delta
        K, i_peak = self.amb_stiffness(abs(X), omega)
        lhs = (K - 0.5 * self.m * omega ** 2) * X + (N + 1j * f_mu)
        return dict(N=N, f_mu=f_mu, ws=ws, S=S, H=H, X=X, K=K, i_peak=i_peak, lhs=lhs)

    def residual(self, delta: float, omega: float) -> float:
        """g(δ) = |LHS of (R1)| − (U/2) Ω² [N]."""
        return abs(self.state(delta, omega)["lhs"]) - 0.5 * self.U * omega ** 2


def check_rub_scene(scene) -> None:
    """The balance holds for a symmetric rigid rotor with the kinematic slip law and AMBs on; a
    SceneError names what does not fit."""
    p = scene.positions
    if scene.rotor.model != "rigid":
        raise SceneError("rotor.model = 'flexible': the synchronous-rub balance is derived for"
                         " the rigid rotor (allowed: rigid)")
    if not (math.isclose(p.rb1, -p.rb2) and math.isclose(p.amb1, -p.amb2)
            and scene.unbalance.z == 0.0):
        raise SceneError("the synchronous-rub balance needs a symmetric machine (its cylindrical"
                         f" mode): positions.rb1 = -positions.rb2 (got {p.rb1:g}, {p.rb2:g}),"
                         f" positions.amb1 = -positions.amb2 (got {p.amb1:g}, {p.amb2:g}) and"
                         f" unbalance.z = 0 (got {scene.unbalance.z:g})")
    if scene.effects.amb == "none":
        raise SceneError("effects.amb = 'none': the balance is the rub with the AMBs on"
                         " (allowed: linear, actuator)")
    if scene.effects.friction != "kinematic":
        raise SceneError(f"effects.friction = {scene.effects.friction!r}: the balance uses the"
                         " kinematic slip law (allowed: kinematic)")


def rub_solutions(scene, speed_rpm: float | None = None,
                  plant: RubPlant | None = None) -> list[RubSolution]:
    """Every steady synchronous forward rub of ``scene`` at ``speed_rpm`` (default
    ``rotor.speed_rpm``): the roots of g(δ) bracketed on a log grid of δ up to the contact law's
    validity bound, each refined by bisection. Empty when there is none."""
    plant = plant or RubPlant(scene)
    rpm = scene.rotor.speed_rpm if speed_rpm is None else speed_rpm
    if not (isinstance(rpm, (int, float)) and 0.0 < rpm <= 60000.0):
        raise SceneError(f"speed_rpm = {rpm!r}: allowed (0, 60000] rpm")
    omega = rpm * math.pi / 30.0
    target = 0.5 * plant.U * omega ** 2
    if target <= 0.0:
        return []
    grid = np.geomspace(GRID_LOW, plant.bound, GRID_POINTS)
    g = np.array([plant.residual(d, omega) for d in grid])
    out = []
    for k in np.flatnonzero(np.sign(g[:-1]) != np.sign(g[1:])):
        lo, hi, glo = grid[k], grid[k + 1], g[k]
        for _ in range(60):
            mid = math.sqrt(lo * hi)
            gm = plant.residual(mid, omega)
            if np.sign(gm) == np.sign(glo):
                lo, glo = mid, gm
            else:
                hi = mid
        d = math.sqrt(lo * hi)
        st = plant.state(d, omega)
        X, lhs = st["X"], st["lhs"]
        out.append(RubSolution(
            speed=omega, penetration=d, amplitude=abs(X), contact_force=st["N"],
            friction_force=st["f_mu"],
            phase_deg=math.degrees(cmath.phase(X / lhs)), sleeve_amplitude=abs(st["S"]),
            housing_amplitude=abs(st["H"]), sleeve_speed=st["ws"],
            amb_force=abs(st["K"] * X), current_peak=st["i_peak"],
            residual=abs(abs(lhs) - target) / target))
    return out


def simulated_rub(result, window: float) -> dict:
    """What :class:`RubSolution` predicts, measured on a run over its last ``window`` seconds at
    retainer plane RB1: the mean orbit radius |X|, contact force N, penetration δ, spin speed Ω,
    and the orbit's lead over the unbalance force (the circular mean of arg X − (φ + φ₀),
    degrees)."""
    t_end = float(result.t[-1])
    if not (isinstance(window, (int, float)) and 0.0 < window <= t_end):
        raise ValueError(f"window = {window!r} s: allowed (0, {t_end:g}] s (the run's length)")
    i = int(np.searchsorted(result.t, t_end - window, "left"))
    X = result.orbit("RB1")[i:]
    u = result.model.scene.unbalance_change if result.model.scene.effects.unbalance_change \
        else result.model.scene.unbalance
    angle = result.state("phi")[i:] + math.radians(u.angle_deg)
    lead = np.angle(np.mean(np.exp(1j * (np.arctan2(X[:, 1], X[:, 0]) - angle))))
    return dict(amplitude=float(np.mean(np.hypot(X[:, 0], X[:, 1]))),
                contact_force=float(np.mean(result.contact_force("RB1")[i:])),
                penetration=float(np.mean(result.penetration("RB1")[i:])),
                speed=float(np.mean(result.rotor_speed[i:])), phase_deg=math.degrees(lead))


def free_orbit(scene, speed_rpm: float | None = None, plant: RubPlant | None = None) -> float | None:
    """The contact-free synchronous orbit's radius [m] by the same balance without the contact,
    |K_amb(|X|) − m Ω²/2| |X| = (U/2) Ω² (the smallest root), or None if the rotor cannot whirl
    inside the clearance (no root below c): then every steady state touches."""
    plant = plant or RubPlant(scene)
    omega = (scene.rotor.speed_rpm if speed_rpm is None else speed_rpm) * math.pi / 30.0
    target = 0.5 * plant.U * omega ** 2
    if target <= 0.0:
        return 0.0

    def g(a):
        return abs(plant.amb_stiffness(a, omega)[0] - 0.5 * plant.m * omega ** 2) * a - target

    grid = np.geomspace(1e-9, plant.c, 120)
    vals = np.array([g(a) for a in grid])
    up = np.flatnonzero((vals[:-1] < 0) & (vals[1:] >= 0))
    if up.size == 0:
        return None
    lo, hi = grid[up[0]], grid[up[0] + 1]
    for _ in range(50):
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if g(mid) < 0 else (lo, mid)
    return math.sqrt(lo * hi)


def contact_stiffened_speed(scene, load: float, plant: RubPlant | None = None) -> float | None:
    """The rotor's synchronous natural frequency [rpm] while it presses into its sleeves with the
    contact force ``load`` [N]: the lowest Ω with Re[K_amb(Ω) + K_c(Ω)] = m Ω²/2, K_c the series
    of the contact's tangent stiffness at ``load`` and the sleeve's dynamic stiffness on its
    bearing and housing (f_s / S of (R3)–(R5)); None if there is none below 60 000 rpm. Below it
    the in-contact response to the unbalance is in phase with it and pushes into the sleeve."""
    plant = plant or RubPlant(scene)
    if not load > 0.0:
        raise ValueError(f"load = {load!r} N: allowed > 0")
    c = scene.contact
    k_contact = c.exponent * c.stiffness * (load / c.stiffness) ** ((c.exponent - 1) / c.exponent)

    def net(omega):
        S = plant.support(complex(load), omega, omega)[0]
        k_chain = 1.0 / (1.0 / k_contact + S / load)
        return (plant.amb_stiffness(1e-7, omega)[0] + k_chain).real - 0.5 * plant.m * omega ** 2

    grid = np.linspace(10.0, 60000 * math.pi / 30, 600)
    vals = np.array([net(w) for w in grid])
    down = np.flatnonzero((vals[:-1] > 0) & (vals[1:] <= 0))
    if down.size == 0:
        return None
    lo, hi = grid[down[0]], grid[down[0] + 1]
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if net(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi) * 30 / math.pi
