"""Results of a run: time, states, per-plane diagnostics and named accessors (SI units)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import thermal
from .model import (A_DELTA, A_DRAG, A_FMU, A_FR, A_LOAD, A_PFRIC, A_QMAX, A_STATOR, A_WS, FX_ROW,
                    I_FX, I_PLANES, I_STM, I_THERM, J_HX, J_SX, N_AUX_PLANE, N_PLANE_IDX, PLANES,
                    P_FX_SHAPE, P_MU, P_TH_C, P_TH_RMAX, P_TH_RMIN, P_TH_SLOPE, P_Z_RB1, ST_AMB1,
                    ST_RB1, S_EDISS, S_W, S_WEXT, S_X, Model, energies)

AMB_PLANES = ("AMB1", "AMB2")


def _axis_series(Y: np.ndarray, i: int, z: float) -> np.ndarray:
    """(Y[:, i] + z Y[:, i + 2], Y[:, i + 1] + z Y[:, i + 3]) as an (N, 2) array, computed in
    place (the same sums: IEEE addition is commutative)."""
    out = np.empty((len(Y), 2))
    for c in range(2):
        np.multiply(Y[:, i + 2 + c], z, out=out[:, c])
        out[:, c] += Y[:, i + c]
    return out


def station_series(model: Model, Y: np.ndarray, s: int, velocity: bool = False) -> np.ndarray:
    """The rotor axis (x, y) at force station s (``physics.model.ST_*``) over the state rows
    ``Y``, as an (N, 2) array: the rigid body's (x + z a, y + z b), plus a flexible rotor's
    elastic modes there (what :func:`physics.model.axis_motion` gives one state); ``velocity``:
    its velocity."""
    out = _axis_series(Y, model.I[S_X] + (4 if velocity else 0), model.P[P_Z_RB1 + s])
    n = model.elastic_modes
    if n:
        i0 = model.I[I_FX] + (2 * n if velocity else 0)
        shape = model.P[P_FX_SHAPE + s * FX_ROW:P_FX_SHAPE + s * FX_ROW + n]
        out[:, 0] += Y[:, i0:i0 + n] @ shape
        out[:, 1] += Y[:, i0 + n:i0 + 2 * n] @ shape
    return out


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    """The float64 arrays ``a`` and ``b`` hold the same bits (0.0 and -0.0 differ, as in
    :func:`physics.model.twin_planes`)."""
    return bool(np.array_equal(a.view(np.int64), b.view(np.int64)))


@dataclass
class RunStats:
    rhs_evaluations: int = 0
    steps: int = 0
    rejected_steps: int = 0
    wall_time_s: float = 0.0       # integration only, JIT compilation excluded
    cpu_time_s: float = 0.0        # its CPU time (robust to a loaded machine; 0 with a progress bar)
    compile_time_s: float = 0.0    # JIT compilation or cache load before the run


@dataclass
class Result:
    model: Model
    t: np.ndarray                  # (N,)
    Y: np.ndarray                  # (N, n_state)
    aux: np.ndarray                # (N, N_AUX) per-plane diagnostics
    stats: RunStats = field(default_factory=RunStats)
    t_fault: float | None = None   # time the AMBs switched off (None: never on)
    # after the fault, per plane (RB1, RB2): the contact force, bearing load and largest ball load
    # at every accepted integrator step (physics.integrate.P_*), whatever the output rate
    step_peaks: np.ndarray | None = None
    _derived: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def until(self, t_end: float) -> "Result":
        """The samples t < ``t_end`` as a new result (at least the first sample), without the
        step-resolved peaks (they cover the whole run): the run up to a time, e.g. up to where
        it left the contact law's validity (``physics.metrics``)."""
        k = max(int(np.searchsorted(self.t, t_end, "left")), 1)
        return Result(self.model, self.t[:k], self.Y[:k], self.aux[:k], self.stats, self.t_fault)

    # -- rotor ----------------------------------------------------------------------------
    def state(self, name: str) -> np.ndarray:
        """The time series of one state by name (``Model.names``, e.g. ``"x"``, ``"Omega"``)."""
        if name not in self.model.names:
            raise ValueError(f"state must be one of {', '.join(self.model.names)}; got {name!r}")
        return self.Y[:, self.model.index(name)]

    @property
    def rotor_speed(self) -> np.ndarray:
        """Rotor spin speed Omega [rad/s]."""
        return self.Y[:, self.model.I[S_W]]

    def _plane(self, plane: str, planes: tuple[str, ...] = PLANES) -> int:
        try:
            return planes.index(plane)
        except ValueError:
            raise ValueError(f"plane must be one of {planes}, got {plane!r}") from None

    def _axis(self, s: int, offset: int = 0) -> np.ndarray:
        """Rotor axis (x + z a, y + z b) at force station s (``physics.model.ST_*``), plus a
        flexible rotor's elastic modes there; offset 4: its velocity. Computed once per station
        (the metrics ask several times), read-only."""
        return self._memo((s, offset), lambda: station_series(self.model, self.Y, s, offset == 4))

    def orbit(self, plane: str) -> np.ndarray:
        """Rotor axis position (x, y) at a retainer plane, relative to the nominal centre [m]."""
        return self._axis(ST_RB1 + self._plane(plane))

    def amb_orbit(self, plane: str) -> np.ndarray:
        """Rotor axis position (x, y) at AMB plane ``AMB1``/``AMB2`` [m], relative to the stator
        centre: what the environments check against the stator (``amb.air_gap``)."""
        return self._axis(ST_AMB1 + self._plane(plane, AMB_PLANES))

    def stator(self, plane: str) -> np.ndarray:
        """Stator centre (x, y) at AMB plane ``AMB1``/``AMB2`` on its mount [m] (zeros when the
        stator is fixed: without ``effects.stator_mount`` or stator contact)."""
        i = self.model.I[I_STM]
        if i < 0:
            return np.zeros((len(self.t), 2))
        i += 4 * self._plane(plane, AMB_PLANES)
        return self.Y[:, i:i + 2]

    def stator_penetration(self, plane: str) -> np.ndarray:
        """Rotor-stator penetration |p - q| - g_0 at AMB plane ``AMB1``/``AMB2`` [m] (negative
        inside the air gap): rotor axis p relative to the stator centre q (on its mount)."""
        d = self.amb_orbit(plane) - self.stator(plane)
        return np.hypot(d[:, 0], d[:, 1]) - self.model.scene.amb.air_gap

    def orbit_after(self, plane: str, t0: float, relative: bool = False) -> np.ndarray:
        """:meth:`orbit` at the samples t >= ``t0`` (``relative``: minus :meth:`sleeve`, the
        rotor in its sleeve's gap), computed once per result (the metrics and the study's
        observables read the same pieces), read-only."""
        def piece():                    # t is increasing: the samples t >= t0 are a suffix
            i = int(np.searchsorted(self.t, t0, "left"))
            o = self.orbit(plane)[i:]
            return o - self.sleeve(plane)[i:] if relative else o
        return self._memo(("orbit", plane, t0, relative), piece)

    def radius_after(self, plane: str, t0: float, relative: bool = False) -> np.ndarray:
        """The radius |(x, y)| of :meth:`orbit_after` (``np.hypot``), computed once per result."""
        def radius():
            o = self.orbit_after(plane, t0, relative)
            return np.hypot(o[:, 0], o[:, 1])
        return self._memo(("radius", plane, t0, relative), radius)

    def twin_planes(self) -> bool:
        """Both retainer planes' time series (rotor orbit, sleeve, the per-plane diagnostics,
        sleeve temperature) are the same bit for bit, as in a symmetric drop: every per-plane
        number is then the same too, and the metrics compute it once (``physics.metrics.per_plane``)."""
        if "twin" not in self._derived:
            a, b = PLANES
            n = N_AUX_PLANE
            self._derived["twin"] = (
                _same_bits(self.orbit(a), self.orbit(b)) and _same_bits(self.sleeve(a), self.sleeve(b))
                and _same_bits(self.aux[:, :n], self.aux[:, n:2 * n])
                and _same_bits(self.temperature_rise(a), self.temperature_rise(b)))
        return self._derived["twin"]

    def _memo(self, key, compute) -> np.ndarray:
        """``compute()`` once per result and ``key``, kept read-only (derived time series)."""
        if key not in self._derived:
            a = compute()
            a.flags.writeable = False
            self._derived[key] = a
        return self._derived[key]

    def orbit_velocity(self, plane: str) -> np.ndarray:
        return self._axis(ST_RB1 + self._plane(plane), offset=4)

    def _body(self, plane: str, j: int) -> np.ndarray:
        i = self.model.I[I_PLANES + self._plane(plane) * N_PLANE_IDX + j]
        return np.zeros((len(self.t), 2)) if i < 0 else self.Y[:, i:i + 2]

    def housing(self, plane: str) -> np.ndarray:
        """Housing (outer ring) position [m]; zeros when housings are fixed."""
        return self._body(plane, J_HX)

    def sleeve(self, plane: str) -> np.ndarray:
        """Sleeve (inner ring) centre [m]; equals the housing when the sleeve is rigidly mounted."""
        i = self.model.I[I_PLANES + self._plane(plane) * N_PLANE_IDX + J_SX]
        return self.housing(plane) if i < 0 else self.Y[:, i:i + 2]

    def _aux(self, plane: str, j: int) -> np.ndarray:
        return self.aux[:, self._plane(plane) * N_AUX_PLANE + j]

    def contact_force(self, plane: str) -> np.ndarray:
        """Radial rotor-sleeve contact force F_r [N]."""
        return self._aux(plane, A_FR)

    def friction_force(self, plane: str) -> np.ndarray:
        """Signed friction force F_mu [N] (on the sleeve along +t)."""
        return self._aux(plane, A_FMU)

    def penetration(self, plane: str) -> np.ndarray:
        """e_r - c [m]: negative while the rotor is free in the gap."""
        return self._aux(plane, A_DELTA)

    def bearing_load(self, plane: str) -> np.ndarray:
        """Radial load carried by the retainer bearing [N]."""
        return self._aux(plane, A_LOAD)

    def sleeve_speed(self, plane: str) -> np.ndarray:
        """Sleeve spin speed omega_s [rad/s] (rolling speed in the massless-sleeve limit)."""
        return self._aux(plane, A_WS)

    def drag_torque(self, plane: str) -> np.ndarray:
        return self._aux(plane, A_DRAG)

    def max_ball_load(self, plane: str) -> np.ndarray:
        """Load on the most heavily loaded ball [N] (Sopanen-Mikkola bearing; zero otherwise)."""
        return self._aux(plane, A_QMAX)

    def stator_force(self, plane: str) -> np.ndarray:
        """Rotor-stator normal force F_n at AMB plane ``AMB1``/``AMB2`` [N] (zero without
        ``effects.stator_contact``)."""
        return self.aux[:, A_STATOR + self._plane(plane, AMB_PLANES)]

    def friction_power(self, plane: str) -> np.ndarray:
        """Power dissipated by the rotor-sleeve contact friction, F_mu times the slip speed
        r Omega + v_t - R omega_s [W] (the heat generated at the retainer's inner surface). Under
        the paper's slip law (F_mu follows Omega - omega_s, not the slip speed) it can turn
        negative: in a whirl, and slightly while the sleeve rolls at omega_s = Omega."""
        return self._aux(plane, A_PFRIC)

    # -- sleeve heating (effects.thermal) ---------------------------------------------------
    @property
    def has_thermal(self) -> bool:
        return bool(self.model.I[I_THERM] >= 0)

    def temperature_rise(self, plane: str) -> np.ndarray:
        """Sleeve temperature above ambient theta [K] (zeros without effects.thermal)."""
        k = self._plane(plane)
        return self.Y[:, self.model.I[I_THERM] + k] if self.has_thermal else np.zeros(len(self.t))

    def friction_coefficient(self, plane: str) -> np.ndarray:
        """The rotor-sleeve friction coefficient mu at this plane (mu(theta) with
        effects.thermal, else the constant contact.friction)."""
        P = self.model.P
        if not self.has_thermal:
            return np.full(len(self.t), P[P_MU])
        return np.array([thermal.friction_coefficient(P[P_MU], th, P[P_TH_SLOPE], P[P_TH_RMIN],
                                                      P[P_TH_RMAX])
                         for th in self.temperature_rise(plane)])

    # -- energy audit ---------------------------------------------------------------------
    def energy(self) -> dict[str, np.ndarray]:
        """Mechanical energy, dissipated energy and external work [J] at each sample.

        Balance: E_mech(t) + E_dissipated(t) - W_external(t) = E_mech(0). With effects.thermal
        also the heat audit (physics/thermal.py): heat_stored (in the two sleeves, above their
        start) + heat_lost (to the housings and the rotor) = friction_work (the contact
        friction's share of E_dissipated).
        """
        m = self.model
        E = energies(self.Y, m.P, m.I)
        out = dict(mechanical=E, dissipated=self.Y[:, m.I[S_EDISS]], external=self.Y[:, m.I[S_WEXT]])
        if self.has_thermal:
            i = m.I[I_THERM]
            theta = self.Y[:, i] + self.Y[:, i + 1]
            out.update(heat_stored=m.P[P_TH_C] * (theta - theta[0]), heat_lost=self.Y[:, i + 2],
                       friction_work=self.Y[:, i + 3])
        return out

    def save_npz(self, path) -> None:
        """Time series with named columns (SI units)."""
        cols = {"t": self.t, "rotor_speed": self.rotor_speed}
        for p in PLANES:
            o, s, h = self.orbit(p), self.sleeve(p), self.housing(p)
            cols.update({f"{p}_x": o[:, 0], f"{p}_y": o[:, 1], f"{p}_sleeve_x": s[:, 0],
                         f"{p}_sleeve_y": s[:, 1], f"{p}_housing_x": h[:, 0],
                         f"{p}_housing_y": h[:, 1], f"{p}_contact_force": self.contact_force(p),
                         f"{p}_friction_force": self.friction_force(p),
                         f"{p}_sleeve_speed": self.sleeve_speed(p),
                         f"{p}_bearing_load": self.bearing_load(p),
                         f"{p}_friction_power": self.friction_power(p),
                         f"{p}_max_ball_load": self.max_ball_load(p)})
            if self.has_thermal:
                cols[f"{p}_temperature_rise"] = self.temperature_rise(p)
        for p in AMB_PLANES:
            cols[f"{p}_stator_force"] = self.stator_force(p)
        np.savez_compressed(path, states=self.Y, state_names=np.array(self.model.names), **cols)
