"""Drop KPIs per retainer plane (displacement, contact force, first contact, backward whirl) and
the checks that say when they do not describe a clean drop (contact before the fault, stator
contact, no fault in the run, output samples too coarse), listed as ``warnings``.

A run is valid up to the first validity bound it passes (:func:`physics.validity.validity_bound`),
whichever it is: a contact law's penetration bound at a retainer plane, the stator contact's bound
at an AMB plane, or, without ``effects.stator_contact``, the rotor reaching the AMB air gap (the
stator it would hit is not modelled). From that time, ``left_validity_at_s``, the model does not
describe the motion, so every metric that depends on the motion after it is None: the per-plane
:data:`INVALID_KEYS` and :data:`STATOR_INVALID_KEYS` and the run-level :data:`RUN_INVALID_KEYS`
(final speeds, whirl, end state), their values over the samples before that time kept as
``<key>_before_invalid``; the energy audit covers the valid samples only."""
from __future__ import annotations

import functools
import math

import numpy as np

from .amb import weight_shares
from .ball_bearing import film_thickness, max_contact_pressure, static_max_ball_load
from .laws import contact_law, slip_law
from .dissipation import created_energy, dissipation_check
from .flexible_rotor import strain_energy
from .integrate import P_FR, P_LOAD, P_QMAX
from .model import F_FILM, F_RB, F_STATOR, P_FILM, PLANES, RB_SM
from .results import AMB_PLANES, Result
from .validity import validity_bound

WHIRL_MIN_REVOLUTIONS = 3.0     # net backward orbit revolutions that make a backward whirl
WHIRL_RADIUS_FRACTION = 0.5     # only orbit samples beyond this fraction of the clearance count
RPM = 30.0 / math.pi            # rad/s -> rpm
ISO76_C0_PRESSURE = 4.2e9       # Pa: ISO 76's nominal contact pressure at C_0 (ball bearings);
                                # the model's own level is rating_pressure()
ALIAS_ANGLE = 0.75 * math.pi    # orbit turn between two samples beyond which the whirl may alias
SAMPLES_PER_PERIOD = 10         # a sinusoid sampled n times a period shows >= cos(pi/n) of its
                                # peak: 95 % at n = 10 (see min_output_rate)
PEAK_TOLERANCE = 1.0 - math.cos(math.pi / SAMPLES_PER_PERIOD)   # the same 5 %, measured: a
                                # sampled peak this far below the step-resolved one is missed
STEP_PEAK_KEYS = {"peak_contact_force_N": P_FR, "peak_bearing_load_N": P_LOAD,
                  "max_ball_load_N": P_QMAX}      # metrics key -> physics.integrate peak column
# the force and displacement metrics that are None once a run left the validity of its laws
INVALID_KEYS = ("max_displacement_um", "max_y_displacement_um", "peak_contact_force_N",
                "peak_bearing_load_N", "static_safety_factor", "max_ball_load_N",
                "max_contact_pressure_MPa", "friction_heat_J", "max_penetration_um",
                # effects.thermal: heated by that friction
                "max_temperature_rise_K", "final_temperature_rise_K", "min_friction_coefficient",
                "max_friction_coefficient",
                # and every other number of the motion after the fault: speeds, whirl, film
                "final_sleeve_speed_rpm", "max_sleeve_speed_rpm", "friction_energy_created_J",
                "backward_whirl", "whirl_revolutions", "whirl_frequency_hz", "whirl_sampling_aliased",
                "max_film_thickness_um")
PRE_FAULT_KEYS = ("pre_fault_peak_contact_force_N",)    # invalid only if it left before the fault
STATOR_INVALID_KEYS = ("max_displacement_um", "stator_peak_force_N", "stator_contact_time_s",
                       "stator_penetration_um", "max_stator_displacement_um", "stator_contacts")
# the run-level ones; the end state (final_slip_ratio, sleeves_still_sliding) is None without a
# value before, and an event (first contact, reaching the air gap) keeps its time if it came first
RUN_INVALID_KEYS = ("final_rotor_speed_rpm", "backward_whirl")
BEFORE_INVALID = "_before_invalid"                 # suffix of their values up to that time
SLIDING_SLIP = 0.1              # |1 - omega_s R / (Omega r)| at the end above which a sleeve slides
SLIDING_WINDOW = 5e-3           # s: a plane counts as in contact at the end if it was in this window


def per_plane(result: Result, compute) -> dict:
    """{plane: compute(plane)} over the retainer planes (``compute`` returns a flat dict);
    computed once and copied when both planes' time series are the same bit for bit
    (:meth:`Result.twin_planes`, a symmetric drop), which gives the same numbers."""
    first = compute(PLANES[0])
    twin = result.twin_planes()
    return {p: first if k == 0 else dict(first) if twin else compute(p)
            for k, p in enumerate(PLANES)}


def first_crossing(t: np.ndarray, x: np.ndarray, level: float) -> float | None:
    """First time [s] the series ``x`` passes above ``level`` (x > level), interpolated linearly
    from the sample before it; None if it never does."""
    hit = np.flatnonzero(x > level)
    if hit.size == 0:
        return None
    k = hit[0]
    if k > 0 and x[k - 1] < level:
        return float(t[k - 1] + (t[k] - t[k - 1]) * (level - x[k - 1]) / (x[k] - x[k - 1]))
    return float(t[k])


def first_contact_time(result: Result) -> float | None:
    """Earliest time either plane's gap closes, interpolated between samples [s]."""
    times = [first_crossing(result.t, result.penetration(p), 0.0)
             for p in (PLANES[:1] if result.twin_planes() else PLANES)]
    return min((t for t in times if t is not None), default=None)


def backward_turns(e: np.ndarray, r: np.ndarray, clearance: float,
                   spin: float) -> tuple[np.ndarray, np.ndarray]:
    """The orbit ``e`` (N, 2) of the rotor in its sleeve turns between consecutive samples that
    both lie beyond WHIRL_RADIUS_FRACTION x ``clearance`` (``r``: its radius): (the turns [rad],
    > 0 against the sign of ``spin``, i.e. backward; the mask of the sample pairs that count)."""
    ang = np.arctan2(e[:, 1], e[:, 0])
    far = r > WHIRL_RADIUS_FRACTION * clearance
    both = far[1:] & far[:-1]
    dang = (np.diff(ang)[both] + np.pi) % (2 * np.pi) - np.pi
    return -spin * dang, both


def whirl(result: Result, plane: str, after: float) -> dict:
    """Backward-whirl detection from the orbit of the rotor relative to its sleeve.

    The orbit angle is accumulated over consecutive samples that both lie beyond half the
    clearance; turning against the spin direction is backward. A backward whirl needs at least
    WHIRL_MIN_REVOLUTIONS net backward revolutions; its frequency is the backward angular rate
    over the samples that counted. Also reports the mean orbit angular momentum sign.
    """
    i = int(np.searchsorted(result.t, after, "left"))       # the samples t >= after (a suffix)
    e = result.orbit_after(plane, after, relative=True)
    t = result.t[i:]
    c = result.model.scene.contact.clearance
    spin = (np.sign(result.rotor_speed[i:].mean()) or 1.0) if i < len(result.t) else 1.0
    r = result.radius_after(plane, after, relative=True)
    back, both = backward_turns(e, r, c, spin)
    revs = back.sum() / (2 * np.pi)
    dt = np.diff(t)[both]
    moving_back = back > 0
    t_back = dt[moving_back].sum()
    freq = back[moving_back].sum() / (2 * np.pi * t_back) if t_back > 0 else None
    aliased = bool(back.size and np.max(np.abs(back)) > ALIAS_ANGLE)
    is_whirl = bool(revs >= WHIRL_MIN_REVOLUTIONS)
    return dict(backward_whirl=is_whirl, whirl_revolutions=float(revs),
                whirl_frequency_hz=float(freq) if (is_whirl and freq is not None) else None,
                whirl_sampling_aliased=aliased)


def friction_heat(result: Result, plane: str, post: np.ndarray) -> np.ndarray:
    """Cumulative heat [J] generated at the rotor-sleeve contact over the samples ``post``
    (trapezoidal rule on ``Result.friction_power``); its last value is ``friction_heat_J``."""
    p, t = result.friction_power(plane)[post], result.t[post]
    return np.concatenate(([0.0], np.cumsum(0.5 * (p[1:] + p[:-1]) * np.diff(t))))[:len(t)]


def friction_energy_created(result: Result, plane: str, post: slice) -> float:
    """Energy [J] the rotor-sleeve friction created over the samples ``post``: the integral of its
    negative power. Zero for a law that dissipates; the paper's slip law creates energy whenever
    it pushes along the sliding (``friction_heat_J`` is then a net figure)."""
    return created_energy(result.t[post], result.friction_power(plane)[post])


@functools.lru_cache(maxsize=64)
def rating_pressure(bearing) -> float:
    """Worst ball-race Hertz pressure [Pa] at s_0 = 1: the bearing statically carrying its load
    rating C_0 (``bearing.static_load_rating``) with a ball under the load
    (:func:`physics.ball_bearing.static_max_ball_load`). 3 655 MPa for the shipped 6016 with
    C_0 = 40 kN, below ISO 76's nominal ``ISO76_C0_PRESSURE``: C_0 is a catalogue value, the
    pressure comes from the model's Hertz contacts."""
    return float(max_contact_pressure(bearing, static_max_ball_load(bearing,
                                                                    bearing.static_load_rating)))


def retainer_loading(result: Result, plane: str, post: np.ndarray) -> dict:
    """Retainer-bearing design numbers after the fault: the peak radial bearing load and the
    static safety factor s_0 = C_0 / P_0 (ISO 76, P_0 = the peak radial load; below about 1
    the races deform permanently), the friction heat generated at the rotor-sleeve contact
    (∫ F_mu v_slip dt, trapezoidal rule over the output samples; a net value, which the paper's
    slip law can make negative, see ``Result.friction_power``) and the highest sleeve speed.
    With the Sopanen-Mikkola bearing also the most heavily loaded ball's peak load and its
    largest Hertz contact pressure (either raceway; :func:`rating_pressure` is its level at
    s_0 = 1, where ISO 76 puts the permanent dent of 1e-4 ball diameters); None for the linear
    and rigid mounts, which have no balls."""
    t = result.t[post]
    load = result.bearing_load(plane)[post]
    peak = float(load.max()) if len(load) else 0.0
    ws = result.sleeve_speed(plane)[post]
    bearing = result.model.scene.bearing
    q = float(result.max_ball_load(plane)[post].max()) if len(t) else 0.0
    balls = result.model.I[F_RB] == RB_SM
    return dict(peak_bearing_load_N=peak,
                static_safety_factor=bearing.static_load_rating / peak if peak > 0.0 else None,
                max_ball_load_N=q if balls else None,
                max_contact_pressure_MPa=float(max_contact_pressure(bearing, q)) * 1e-6 if balls else None,
                friction_heat_J=float(friction_heat(result, plane, post)[-1]) if len(t) else 0.0,
                friction_energy_created_J=friction_energy_created(result, plane, post),
                max_sleeve_speed_rpm=float(np.abs(ws).max() * RPM) if len(ws) else 0.0)


def sleeve_heating(result: Result, plane: str) -> dict:
    """effects.thermal: the sleeve's largest and final temperature rise above ambient and the
    friction coefficient's range over the run (mu(theta), physics/thermal.py)."""
    theta, mu = result.temperature_rise(plane), result.friction_coefficient(plane)
    return dict(max_temperature_rise_K=float(theta.max()),
                final_temperature_rise_K=float(theta[-1]),
                min_friction_coefficient=float(mu.min()), max_friction_coefficient=float(mu.max()))


def pre_fault(result: Result) -> slice:
    """Samples while the AMBs still carry the rotor, t < t_fault: a prefix of the run (every
    sample when the run ends first). A slice indexes the samples a mask would, without a copy."""
    if result.t_fault is None:
        return slice(0, len(result.t))
    return slice(0, int(np.searchsorted(result.t, result.t_fault, "left")))


def after(result: Result, t0: float) -> slice:
    """The samples t >= ``t0``: a suffix of the run (t increases)."""
    return slice(int(np.searchsorted(result.t, t0, "left")), None)


def contact_period(scene, plane: str, load: float) -> float | None:
    """Period 2π √(m/k) [s] of the rotor's mass share m at a retainer plane (lever rule) on the
    contact stiffness linearised at ``load``, k = e K (F/K)^((e-1)/e) (paper eq. 14): the rotor
    bouncing on an immovable sleeve, the shortest period of an impact (the retainer bearing and
    the support in series only lengthen it). None without a period (no load with e > 1).
    With ``contact.law = "hertz_line"`` k is the line contact's tangent stiffness
    a / (ln(4ac/F) − 2), a = π L E* (:func:`physics.contact.line_deflection`), capped at a."""
    c = scene.contact
    m = abs(weight_shares(scene.rotor.mass, scene.positions.rb1, scene.positions.rb2)[
        PLANES.index(plane)])
    k = contact_law(c.law).tangent_stiffness(scene, load)      # the law's own
    return 2.0 * math.pi * math.sqrt(m / k) if k > 0.0 and m > 0.0 else None


def stator_period(scene) -> float:
    """Period 2π √(m/k) [s] of the rotor's mass share at an AMB plane on the stator stiffness
    (``stator.stiffness``): the stator impact, resolved like :func:`contact_period`."""
    m = abs(weight_shares(scene.rotor.mass, scene.positions.amb1, scene.positions.amb2)[0])
    return 2.0 * math.pi * math.sqrt(max(m, 1e-3) / scene.stator.stiffness)


def min_output_rate(result: Result, planes: dict) -> tuple[float, str]:
    """The lowest ``solver.output_rate`` [Hz] that resolves what the metrics read from the output
    samples, and what sets it: SAMPLES_PER_PERIOD samples per contact period (:func:`contact_period`
    linearised at the larger of the plane's static weight share and its sampled peak contact
    force) and per backward-whirl period where one was found (``planes``: the per-plane metrics).
    Source: a sinusoid sampled n times a period shows at least cos(π/n) of its peak, so n = 10
    keeps a sampled peak (contact force, displacement) within 5 % of the true one."""
    scene = result.model.scene
    g = scene.world.gravity if scene.effects.gravity else 0.0
    weights = weight_shares(scene.rotor.mass * g, scene.positions.rb1, scene.positions.rb2)
    best, source = 0.0, "nothing"
    for p, weight in zip(PLANES, weights):
        v = planes[p]                   # the peaks before and after the fault cover the run
        load = max(abs(weight), valid_or_before(v, "peak_contact_force_N"),
                   valid_or_before(v, "pre_fault_peak_contact_force_N"))
        periods = {"contact": contact_period(scene, p, load)}
        f_whirl = valid_or_before(v, "whirl_frequency_hz")
        periods["backward-whirl"] = 1.0 / f_whirl if f_whirl else None
        for what, period in periods.items():
            if period is not None and SAMPLES_PER_PERIOD / period > best:
                best = SAMPLES_PER_PERIOD / period
                source = f"{what} period at {p}, {period * 1e3:.3g} ms"
    touched = [p for p in AMB_PLANES if (result.stator_force(p) > 0.0).any()]
    if touched and SAMPLES_PER_PERIOD / stator_period(scene) > best:
        best = SAMPLES_PER_PERIOD / stator_period(scene)
        source = f"stator contact period at {touched[0]}, {stator_period(scene) * 1e3:.3g} ms"
    return best, source


def amb_plane_metrics(result: Result) -> dict:
    """Largest rotor displacement at each AMB plane over the run and whether it reaches the
    stator (|r| >= amb.air_gap, the environments' criterion). With ``effects.stator_contact`` also
    the stator contact's events (sampled contact episodes), peak normal force and time in
    contact over the output samples (None without the effect)."""
    gap = result.model.scene.amb.air_gap
    modelled = bool(result.model.I[F_STATOR])
    out = {}
    for p in AMB_PLANES:
        o = result.amb_orbit(p)
        r2 = float((o[:, 0] ** 2 + o[:, 1] ** 2).max()) if len(o) else 0.0
        out[p] = dict(max_displacement_um=math.sqrt(r2) * 1e6, stator_contact=r2 >= gap * gap)
        out[p].update(stator_contact_events(result, p) if modelled else
                      dict(stator_contacts=None, stator_peak_force_N=None, stator_contact_time_s=None))
        pen = result.stator_penetration(p)
        out[p]["stator_penetration_um"] = max(float(pen.max()) if len(pen) else 0.0, 0.0) * 1e6
        q = result.stator(p)                    # the stator's own motion on its mount
        out[p]["max_stator_displacement_um"] = float(np.hypot(q[:, 0], q[:, 1]).max() * 1e6) \
            if len(q) else 0.0
    return out


def stator_contact_events(result: Result, plane: str) -> dict:
    """Contact episodes (runs of samples with a stator force), peak force [N] and time in
    contact [s] (samples in contact times the sample spacing) at AMB plane ``plane``."""
    f = result.stator_force(plane)
    touching = f > 0.0
    starts = int(np.count_nonzero(touching[1:] & ~touching[:-1]) + (1 if len(f) and touching[0] else 0))
    dt = float(np.diff(result.t).mean()) if len(result.t) > 1 else 0.0
    return dict(stator_contacts=starts, stator_peak_force_N=float(f.max()) if len(f) else 0.0,
                stator_contact_time_s=float(np.count_nonzero(touching)) * dt)


def contact_validity(result: Result) -> dict:
    """Per retainer plane: the largest rotor-sleeve penetration over the run [µm] (checked
    against the law's bound by :func:`left_validity`) and, with the EHL film, the film at the
    highest sleeve speed [µm], checked against the bearing's radial internal play P_d / 2 (a
    thicker film preloads the balls at the centre, outside the film model's calibration)."""
    scene = result.model.scene
    film = bool(result.model.I[F_FILM])

    def plane(p: str) -> dict:
        pen = result.penetration(p)
        ws = np.abs(result.sleeve_speed(p))
        h = film_thickness(float(ws.max()), result.model.P[P_FILM])[0] if film and len(ws) else None
        return dict(max_penetration_um=max(float(pen.max()), 0.0) * 1e6 if len(pen) else 0.0,
                    max_film_thickness_um=h * 1e6 if h is not None else None)
    planes = per_plane(result, plane)
    play = scene.bearing.clearance / 2.0 * 1e6
    return dict(planes=planes, bearing_radial_play_um=play,
                film_exceeds_play=[p for p, v in planes.items()
                                   if v["max_film_thickness_um"] is not None
                                   and v["max_film_thickness_um"] > play])


def check_metrics(result: Result, m: dict) -> dict:
    """The checks of a drop (added to ``m`` by :func:`compute_metrics`): whether the fault lies in
    the run, contact before the fault, stator contact at the AMB planes and whether the output
    rate resolves the contact dynamics."""
    pre = pre_fault(result)
    out = dict(fault_simulated=result.t_fault is not None,
               contact_before_fault=any(bool((result.penetration(p)[pre] > 0.0).any())
                                        for p in PLANES))
    out["amb_planes"] = amb_plane_metrics(result)
    out["stator_contact_modelled"] = bool(result.model.I[F_STATOR])
    validity = contact_validity(result)
    for p, v in validity.pop("planes").items():
        m["planes"][p].update(v)
    out.update(validity)
    out.update(mark_validity(result, m["planes"], out["amb_planes"]))
    reached = [v["stator_contact"] for v in out["amb_planes"].values()]
    out["stator_contact"] = True if any(reached) else None if None in reached else False
    if out["left_validity_at_s"] is not None:     # the film check on the valid samples
        out["film_exceeds_play"] = [p for p, v in m["planes"].items()
                                    if (valid_or_before(v, "max_film_thickness_um") or 0.0)
                                    > out["bearing_radial_play_um"]]
    rate = result.model.scene.solver.output_rate
    t_inv = out["left_validity_at_s"]
    need, source = min_output_rate(result if t_inv is None else result.until(t_inv), m["planes"])
    out.update(output_rate_hz=rate, min_output_rate_hz=need, min_output_rate_source=source,
               output_rate_too_coarse=rate < need)
    # the step maxima cover the whole post-fault run: not computable once it left validity
    out["step_resolved_peaks"] = (step_resolved_peaks(result) if out["left_validity_at_s"] is None
                                  else None)
    out["sampled_peaks_missed"] = sampled_peaks_missed(m["planes"], out["step_resolved_peaks"])
    return out


def left_validity(result: Result) -> dict:
    """Per plane: the first time it passes its validity bound (``left_validity_at_s``,
    interpolated between samples; None if never) and the bound
    (:meth:`physics.validity.Bound.to_dict`): at the retainer planes the contact law's penetration
    bound, at the AMB planes the stator contact's bound with ``effects.stator_contact`` and the air
    gap without it (the rotor reaches a stator the model does not have)."""
    scene = result.model.scene
    rb = validity_bound(scene, "retainer")
    out = {p: dict(left_validity_at_s=first_crossing(result.t, result.penetration(p), rb.penetration),
                   **rb.to_dict()) for p in PLANES}
    if result.model.I[F_STATOR]:
        st = validity_bound(scene, "stator")
        for p in AMB_PLANES:
            pen = result.stator_penetration(p)
            out[p] = dict(left_validity_at_s=first_crossing(result.t, pen, st.penetration),
                          **st.to_dict())
    else:
        gap = validity_bound(scene, "air_gap")
        for p in AMB_PLANES:
            out[p] = dict(left_validity_at_s=first_crossing(result.t, amb_radius(result, p),
                                                            gap.penetration), **gap.to_dict())
    return out


def amb_radius(result: Result, plane: str) -> np.ndarray:
    """|r| [m] of the rotor axis at AMB plane ``plane`` over the run."""
    o = result.amb_orbit(plane)
    return np.hypot(o[:, 0], o[:, 1])


def first_bound(validity: dict) -> tuple[float | None, str | None]:
    """(time, plane) of the first validity bound a run passes, from :func:`left_validity`'s
    per-plane table; (None, None) for a run that stays valid. Ties go to the first plane listed
    (the retainer planes before the AMB planes)."""
    times = [(v["left_validity_at_s"], p) for p, v in validity.items()
             if v["left_validity_at_s"] is not None]
    return min(times, key=lambda tp: tp[0], default=(None, None))


def mark_validity(result: Result, planes: dict, amb_planes: dict) -> dict:
    """Adds :func:`left_validity` to the per-plane metrics ``planes`` and ``amb_planes`` (a plane's
    own time only where it is the first bound's, a later crossing being motion after it) and, when
    the run left validity at t_inv (the earliest plane), replaces their :data:`INVALID_KEYS` /
    :data:`STATOR_INVALID_KEYS` by None, keeping the values over the samples t < t_inv as
    ``<key>_before_invalid``. Returns the run-level keys: ``left_validity_at_s`` and the planes
    past their bound (``penetration_beyond_validity``, ``stator_beyond_validity``)."""
    validity = left_validity(result)
    t_inv, first = first_bound(validity)
    for v in validity.values():             # a plane passing its own bound later: not physical
        if v["left_validity_at_s"] is not None and v["left_validity_at_s"] > t_inv:
            v["left_validity_at_s"] = None
    for table in (planes, amb_planes):
        for p, v in table.items():
            v.update(validity.get(p, dict(left_validity_at_s=None)))
    if t_inv is not None:
        early = result.until(t_inv)
        keys = INVALID_KEYS + (PRE_FAULT_KEYS if result.t_fault is None or t_inv < result.t_fault
                               else ())
        table = _plane_table(early)
        for p, v in contact_validity(early)["planes"].items():
            table[p].update(v)
        _null(planes, table, keys)
        _null(amb_planes, amb_plane_metrics(early), STATOR_INVALID_KEYS)
        gap = result.model.scene.amb.air_gap
        for p, v in amb_planes.items():     # reaching the gap is an event: it stands if it came first
            reached = first_crossing(result.t, amb_radius(result, p), gap)
            if reached is None or reached > t_inv:
                v["stator_contact"], v["stator_contact" + BEFORE_INVALID] = None, False
    left = [p for p, v in validity.items() if v["left_validity_at_s"] is not None]
    stator = bool(result.model.I[F_STATOR])
    return dict(left_validity_at_s=t_inv, left_validity_plane=first,
                left_validity_criterion=validity[first]["validity_criterion"] if first else None,
                penetration_beyond_validity=[p for p in left if p in PLANES],
                stator_beyond_validity=[p for p in left if p in AMB_PLANES and stator],
                air_gap_beyond_validity=[p for p in left if p in AMB_PLANES and not stator])


def _null(table: dict, early: dict, keys: tuple[str, ...]) -> None:
    """table[p][key] -> None and table[p][key + BEFORE_INVALID] = early[p][key] (the same value
    over the samples before the run left validity), for every plane and key that has a value
    over the run or before it (a key None in both, e.g. the ball loads of a linear mount, stays
    None without a ``_before_invalid``)."""
    for p, v in table.items():
        for key in (k for k in keys if k in v):
            before = early[p].get(key)
            if v[key] is not None or before is not None:
                v[key + BEFORE_INVALID] = before
                v[key] = None


def null_after_validity(result: Result, out: dict) -> None:
    """The run-level metrics of ``out`` (:func:`compute_metrics`) that depend on the motion after
    ``out["left_validity_at_s"]``: :data:`RUN_INVALID_KEYS` -> None with their values at or
    before that time as ``<key>_before_invalid``; the end state (``final_slip_ratio``,
    ``sleeves_still_sliding``) -> None; a first contact after it -> None; the energy audit and
    the flexible rotor's strain energy over the samples before it."""
    t_inv = out["left_validity_at_s"]
    if t_inv is None:
        return
    early = result.until(t_inv)
    before = dict(final_rotor_speed_rpm=float(early.rotor_speed[-1] * RPM),
                  backward_whirl=any(valid_or_before(v, "backward_whirl")
                                     for v in out["planes"].values()))
    for key, value in before.items():
        out[key], out[key + BEFORE_INVALID] = None, value
    if out["first_contact_time_s"] is not None and out["first_contact_time_s"] >= t_inv:
        out["first_contact_time_s"] = out["first_contact_after_fault_s"] = None
    out["final_slip_ratio"] = out["sleeves_still_sliding"] = None
    out["dissipation"] = dissipation_check(early)
    if "max_strain_energy_J" in out["rotor"]:
        out["rotor"]["max_strain_energy_J" + BEFORE_INVALID] = \
            rotor_metrics(early)["max_strain_energy_J"]
        out["rotor"]["max_strain_energy_J"] = None


def valid_or_before(v: dict, key: str):
    """A per-plane metric, or its value before the run left validity where it is None."""
    return v[key] if v.get(key) is not None else v.get(key + BEFORE_INVALID)


def whirl_decision(m: dict) -> bool | None:
    """A drop's whirl decision (``metrics["backward_whirl"]``) within validity: True if it
    whirled, also before leaving validity (``backward_whirl_before_invalid``: the backward
    revolutions counted up to then already passed WHIRL_MIN_REVOLUTIONS), False if it stayed valid
    without a whirl, None if it left validity before whirling (undecided: what followed is not
    physical). Studies count the undecided drops apart."""
    if valid_or_before(m, "backward_whirl"):
        return True
    return False if m.get("left_validity_at_s") is None else None


def whirled(m: dict) -> bool:
    """The drop whirled within validity (:func:`whirl_decision` is True)."""
    return whirl_decision(m) is True


def step_resolved_peaks(result: Result) -> dict | None:
    """Per plane, the post-fault maxima the integrator saw at every accepted step
    (``Result.step_peaks``): independent of ``solver.output_rate``."""
    if result.step_peaks is None:
        return None
    return {p: {key: float(result.step_peaks[k, j]) for key, j in STEP_PEAK_KEYS.items()}
            for k, p in enumerate(PLANES)}


def sampled_peaks_missed(planes: dict, stepped: dict | None) -> list[dict]:
    """The sampled post-fault peaks that fall more than ``PEAK_TOLERANCE`` below the
    step-resolved ones (the output samples missed the peak of an impact)."""
    if stepped is None:
        return []
    return [dict(plane=p, key=key, sampled=planes[p][key], step_resolved=v)
            for p, peaks in stepped.items() for key, v in peaks.items()
            if planes[p][key] is not None and planes[p][key] < (1.0 - PEAK_TOLERANCE) * v]


def warnings_of(m: dict, scene) -> list[str]:
    """One line per failed check of :func:`check_metrics` and per aliased whirl plane."""
    out = []
    if not m["fault_simulated"] and not m["amb_on_events"]:
        out.append(f"no fault in the simulated time: the AMBs switch off at amb.off_time = "
                   f"{scene.amb.off_time:g} s, not before the end t_end = {m['t_end']:g} s; no drop "
                   "happened, the per-plane and retainer numbers are the levitated rotor's at the "
                   "last sample (raise --t-end / solver.t_end above amb.off_time)")
    if m["contact_before_fault"] and not m["amb_on_events"]:
        peaks = ", ".join(f"{p} {valid_or_before(v, 'pre_fault_peak_contact_force_N'):.0f} N"
                          for p, v in m["planes"].items())
        out.append(f"the rotor touches the retainer bearings before the fault, while levitated "
                   f"(peak contact force {peaks}); the post-fault metrics exclude it (check "
                   "contact.clearance, support.stiffness, unbalance)")
    if m["stator_contact"] and not m["stator_contact_modelled"]:
        disp = ", ".join(f"{p} at t = {v['left_validity_at_s']:.4f} s"
                         if v.get("left_validity_at_s") is not None else
                         f"{p} {valid_or_before(v, 'max_displacement_um'):.0f} µm"
                         for p, v in m["amb_planes"].items() if v["stator_contact"])
        out.append(f"the rotor reaches the AMB stator (amb.air_gap = {scene.amb.air_gap * 1e6:.0f} µm; "
                   f"{disp}): the model has no stator contact, the motion "
                   "beyond it is not physical (set effects.stator_contact = true)")
    if m["left_validity_at_s"] is not None:
        out.append(validity_warning(m, scene))
    if m["film_exceeds_play"]:
        film = _per_plane(m, m["film_exceeds_play"], "max_film_thickness_um", ".1f")
        out.append(f"the EHL film at the highest sleeve speed ({film}) exceeds the retainer "
                   f"bearing's radial internal play P_d/2 = {m['bearing_radial_play_um']:.1f} µm: "
                   "the film preloads the balls with the rotor centred, beyond what the film model"
                   " was made for (check bearing.clearance, bearing.viscosity)")
    if not m["dissipation"]["ok"]:
        d = m["dissipation"]
        out.append(f"{', '.join(d['negative'])} created {d['created_energy_J']:.3g} J (negative "
                   "dissipated power): "
                   + (getattr(slip_law(scene.effects.friction), "NEGATIVE_POWER", None) or
                      "an element does positive work on the motion; please report this scene"))
    if m["output_rate_too_coarse"]:
        out.append(f"solver.output_rate = {m['output_rate_hz']:g} Hz is below "
                   f"{m['min_output_rate_hz']:.0f} Hz ({SAMPLES_PER_PERIOD} samples per "
                   f"{m['min_output_rate_source']}): peaks, first contact and whirl come from the "
                   "output samples and are under-resolved; raise solver.output_rate")
    if m["sampled_peaks_missed"]:
        miss = ", ".join(f"{d['plane']} {d['key']} {d['sampled']:.0f} (steps: {d['step_resolved']:.0f})"
                         for d in m["sampled_peaks_missed"])
        out.append(f"the output samples miss impact peaks by more than {PEAK_TOLERANCE:.0%}: {miss} "
                   f"(step_resolved_peaks in metrics.json); raise solver.output_rate")
    if sliding_warning(m):
        out.append(sliding_warning(m))
    for p, v in m["planes"].items():
        if valid_or_before(v, "whirl_sampling_aliased"):
            out.append(f"{p}: the orbit turns more than {ALIAS_ANGLE / math.pi:g}π between output "
                       "samples (whirl_sampling_aliased): whirl detection and frequency are unreliable; "
                       "raise solver.output_rate")
    return out


def final_slip(result: Result) -> dict:
    """The slip ratio 1 - omega_s R / (Omega r) of each retainer plane at the last sample (sleeve
    surface speed over the rotor's, R the sleeve bore, r the journal radius): 0 when the sleeve
    rolls with the rotor, 1 when it stands. None for a plane out of contact over the last
    :data:`SLIDING_WINDOW` (re-levitated, or no drop) or a rotor at rest. ``final_slip_ratio``
    has every plane, ``sleeves_still_sliding`` those beyond :data:`SLIDING_SLIP`."""
    scene = result.model.scene
    r = scene.rotor.journal_radius
    bore = r + scene.contact.clearance
    rotor = float(result.rotor_speed[-1]) * r
    tail = result.t >= result.t[-1] - SLIDING_WINDOW
    slip = {}
    for p in PLANES:
        touching = result.t_fault is not None and bool((result.contact_force(p)[tail] > 0).any())
        slip[p] = (float(1.0 - result.sleeve_speed(p)[-1] * bore / rotor)
                   if touching and abs(rotor) > 1e-9 else None)
    return dict(final_slip_ratio=slip,
                sleeves_still_sliding={p: v for p, v in slip.items()
                                       if v is not None and abs(v) > SLIDING_SLIP})


def sliding_warning(m: dict) -> str | None:
    """The warning of a run that ends with a sleeve still sliding (:func:`final_slip`)."""
    sliding = m.get("sleeves_still_sliding")
    if not sliding:
        return None
    slips = ", ".join(f"{p} {v:.2f}" for p, v in sliding.items())
    return (f"the run ends with the sleeves still sliding (slip 1 - omega_s R / (Omega r) at t_end "
            f"= {m['t_end']:g} s: {slips}; rolling is 0): the final state is not a settled rolling "
            f"state, and whirl and final speeds describe the transient only (raise --t-end / "
            f"solver.t_end)")


def validity_warning(m: dict, scene) -> str:
    """The warning of a run that left validity (:func:`mark_validity`): the first bound passed,
    then every plane past its own."""
    where = {p: v for table in ("planes", "amb_planes") for p, v in m[table].items()
             if v.get("left_validity_at_s") is not None}
    when = ", ".join(f"{p} at t = {v['left_validity_at_s']:.4f} s" for p, v in where.items())
    bounds = "; ".join(sorted({f"{v['validity_bound_um']:.1f} µm ({v['validity_criterion']})"
                               for v in where.values()}))
    t = m["left_validity_at_s"]
    return (f"the run passes a validity bound first at {m['left_validity_plane']}, t = {t:.4f} s "
            f"({m['left_validity_criterion']}; every plane past its bound: {when}; bounds {bounds})"
            f": the model (contact.law = {scene.contact.law!r}"
            + (", stator contact: the rotor rolls on the stator, dry whip; read it as a destroyed "
               "stator, not a motion" if m["stator_beyond_validity"] else "")
            + ") does not describe the run from then on; every metric of the motion after "
            f"t = {t:.4f} s (forces, displacements, final speeds, whirl, end state) is n/a, their "
            f"values before it are the *{BEFORE_INVALID} keys")


def _per_plane(m: dict, planes: list[str], key: str, spec: str) -> str:
    """"RB1 179 µm, RB2 179 µm": a per-plane µm metric of ``planes`` for a warning."""
    return ", ".join(f"{p} {m['planes'][p][key]:{spec}} µm" for p in planes)


def compute_metrics(result: Result) -> dict:
    """The numbers written to metrics.json (SI, with µm and rpm at the edges)."""
    t_fault = result.t_fault if result.t_fault is not None else result.t[-1]
    t_fc = first_contact_time(result)
    out = dict(scene=result.model.scene.name, t_end=float(result.t[-1]), t_fault_s=result.t_fault,
               amb_on_events=result.model.scene.events(),
               first_contact_time_s=t_fc,
               first_contact_after_fault_s=(t_fc - t_fault) if t_fc is not None else None,
               final_rotor_speed_rpm=float(result.rotor_speed[-1] * RPM),
               wall_time_s=result.stats.wall_time_s, compile_time_s=result.stats.compile_time_s,
               rhs_evaluations=result.stats.rhs_evaluations, steps=result.stats.steps,
               rejected_steps=result.stats.rejected_steps, n_state=result.model.n_state, planes={})
    out["planes"] = _plane_table(result)
    out["backward_whirl"] = any(out["planes"][p]["backward_whirl"] for p in PLANES)
    balls = result.model.I[F_RB] == RB_SM
    out["rating_pressure_MPa"] = rating_pressure(result.model.scene.bearing) * 1e-6 if balls else None
    out.update(check_metrics(result, out))
    out["dissipation"] = dissipation_check(result)
    out["rotor"] = rotor_metrics(result)
    out.update(final_slip(result))
    null_after_validity(result, out)
    out["warnings"] = warnings_of(out, result.model.scene)
    return out


def rotor_metrics(result: Result) -> dict:
    """The rotor model: ``{"model": "rigid"}``, or for a flexible rotor its shaft, the retained
    elastic modes per bending plane (bending below the cut-off, static correction) with their
    frequencies, and the largest strain energy of the run."""
    scene, model = result.model.scene, result.model
    if not model.elastic_modes:
        return dict(model="rigid")
    from .flexible.shafts import drop_rotor
    fm = drop_rotor(scene)
    strain = strain_energy(model, result.Y)
    return dict(model="flexible", shaft=scene.flexible.shaft, elastic_modes=fm.n_modes,
                bending_modes=fm.n_bending, static_correction_modes=fm.n_correction,
                mode_cutoff_hz=scene.flexible.mode_cutoff_hz,
                frequencies_hz=[float(w / (2 * np.pi)) for w in fm.omega],
                damping_ratio=scene.flexible.damping_ratio,
                max_strain_energy_J=float(strain.max()))


def _plane_table(result: Result) -> dict:
    """{plane: :func:`plane_metrics`} of a run (its fault, or its end without one)."""
    t_fault = result.t_fault if result.t_fault is not None else result.t[-1]
    post, pre = after(result, t_fault), pre_fault(result)
    return per_plane(result, lambda p: plane_metrics(result, p, t_fault, post, pre))


def plane_metrics(result: Result, p: str, t_fault: float, post: slice, pre: slice) -> dict:
    """The per-plane numbers of :func:`compute_metrics` at retainer plane ``p`` (``post``, ``pre``:
    the samples after and before the fault at ``t_fault``)."""
    o = result.orbit_after(p, t_fault)
    force = result.contact_force(p)
    f, f_pre = force[post], force[pre]
    disp = result.radius_after(p, t_fault) if len(o) else np.zeros(1)
    entry = dict(max_displacement_um=float(disp.max() * 1e6),
                 max_y_displacement_um=float(np.abs(o[:, 1]).max() * 1e6) if len(o) else 0.0,
                 peak_contact_force_N=float(f.max()) if len(f) else 0.0,
                 pre_fault_peak_contact_force_N=float(f_pre.max()) if len(f_pre) else 0.0,
                 final_sleeve_speed_rpm=float(result.sleeve_speed(p)[-1] * RPM))
    entry.update(retainer_loading(result, p, post))
    if result.has_thermal:
        entry.update(sleeve_heating(result, p))
    entry.update(whirl(result, p, t_fault))
    return entry


def worst_plane(metrics: dict, key: str, before_invalid: bool = False) -> float | None:
    """The larger of the two retainer planes' values of a per-plane metric (``metrics["planes"]``
    of :func:`compute_metrics`, e.g. ``"peak_contact_force_N"``); None where the metric is None
    (e.g. the ball loads of a linear retainer mount). ``before_invalid``: past validity, the
    values before it (:func:`valid_or_before`), e.g. to compare solver settings on one drop."""
    values = [valid_or_before(v, key) if before_invalid else v[key]
              for v in metrics["planes"].values()]
    return None if any(v is None for v in values) else max(values)
