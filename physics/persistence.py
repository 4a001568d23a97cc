"""The end state of a run with the AMBs on: contact-free, persistent forward rub or backward
whirl (docs/physics.md "Persistent contact with the AMBs on").

Over the last ``window`` seconds of a run, per retainer plane, from the output samples:

* the contact fraction f_c: the share of samples with the rotor in its sleeve's gap closed
  (penetration δ > 0);
* the whirl ratio w = Δθ / ∫Ω dt: the turn of the rotor's orbit in its sleeve over the window
  (unwrapped) over the rotor's turn, > 0 forward, 1 synchronous;
* the backward revolutions of the drop metrics' whirl rule (:func:`physics.metrics.backward_turns`:
  samples beyond half the clearance, WHIRL_MIN_REVOLUTIONS make a whirl).

A plane is in **backward whirl** with at least WHIRL_MIN_REVOLUTIONS backward revolutions in
the window, or in contact most of the time (f_c ≥ RUB_CONTACT_FRACTION) with w ≤ −WHIRL_RATIO_MIN;
in **forward rub** with f_c ≥ RUB_CONTACT_FRACTION and w ≥ WHIRL_RATIO_MIN; **pressed** with
f_c ≥ RUB_CONTACT_FRACTION and |w| < WHIRL_RATIO_MIN (in contact on one side without whirling,
as under a held load); **contact-free** without a contact sample; **intermittent** otherwise
(bouncing, or a transient that has not settled: a longer run decides). The run's state is its
worse plane's (in the order of END_STATES). A run that left the model's validity (:func:`physics.metrics.left_validity`:
the AMB air gap, the contact law's bound) before its end is **undecided** unless it whirled
backward before.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from .metrics import WHIRL_MIN_REVOLUTIONS, backward_turns, first_bound, left_validity, whirl
from .model import PLANES

#: "contact most of the time": the contact fraction from which a plane rubs
RUB_CONTACT_FRACTION = 0.5
#: the whirl ratio |w| below which a rotor in contact does not whirl (it is pressed on one side)
WHIRL_RATIO_MIN = 0.1
#: the default window [s]: 10 revolutions and more at the speeds of the presets
WINDOW_S = 0.1
#: the fewest output samples a window must hold
MIN_SAMPLES = 20
#: the states, worst first
END_STATES = ("backward_whirl", "forward_rub", "pressed", "intermittent", "contact_free")
UNDECIDED = "undecided"


@dataclass(frozen=True)
class EndState:
    """A run's (or a plane's) end state and the numbers it rests on (SI units)."""
    label: str                    # one of END_STATES or UNDECIDED
    window_s: float               # the window over which it was judged [s]
    contact_fraction: float       # share of the window's samples in contact
    whirl_ratio: float            # orbit turn / rotor turn over the window
    backward_revolutions: float   # net backward orbit revolutions (the whirl rule's)
    mean_contact_force: float     # mean contact force over the window [N]
    mean_orbit_radius: float      # mean radius of the rotor in its sleeve [m]
    plane: str = ""               # the plane it comes from (the run's worse plane)

    def to_dict(self) -> dict:
        return asdict(self)


def classify(t: np.ndarray, orbit: np.ndarray, penetration: np.ndarray, force: np.ndarray,
             spin: np.ndarray, clearance: float, plane: str = "") -> EndState:
    """The end state of one plane from its window's samples: times ``t`` (N,), the rotor's
    orbit in its sleeve ``orbit`` (N, 2) [m], the ``penetration`` δ (N,) [m], the contact
    ``force`` (N,) [N] and the spin speed ``spin`` (N,) [rad/s]."""
    t = np.asarray(t, float)
    orbit = np.asarray(orbit, float)
    n = len(t)
    if n < MIN_SAMPLES or orbit.shape != (n, 2) or not (len(penetration) == len(force) == len(spin) == n):
        raise ValueError(f"the window needs at least {MIN_SAMPLES} samples of t (N,), orbit (N, 2),"
                         f" penetration, force and spin (N,) each; got t {t.shape},"
                         f" orbit {orbit.shape}, penetration {np.shape(penetration)},"
                         f" force {np.shape(force)}, spin {np.shape(spin)}")
    if not (clearance > 0.0 and math.isfinite(clearance)):
        raise ValueError(f"clearance = {clearance!r} m: allowed > 0")
    r = np.hypot(orbit[:, 0], orbit[:, 1])
    sense = float(np.sign(np.mean(spin)) or 1.0)
    back, _ = backward_turns(orbit, r, clearance, sense)
    revolutions = float(back.sum() / (2 * math.pi))
    turn = np.unwrap(np.arctan2(orbit[:, 1], orbit[:, 0]))
    rotor_turn = float(np.sum(0.5 * (spin[1:] + spin[:-1]) * np.diff(t)))
    ratio = float((turn[-1] - turn[0]) / rotor_turn) if rotor_turn != 0.0 else 0.0
    fraction = float(np.mean(np.asarray(penetration) > 0.0))
    if revolutions >= WHIRL_MIN_REVOLUTIONS or (fraction >= RUB_CONTACT_FRACTION
                                                and ratio <= -WHIRL_RATIO_MIN):
        label = "backward_whirl"
    elif fraction >= RUB_CONTACT_FRACTION:
        label = "forward_rub" if ratio >= WHIRL_RATIO_MIN else "pressed"
    elif fraction == 0.0:
        label = "contact_free"
    else:
        label = "intermittent"
    return EndState(label, float(t[-1] - t[0]), fraction, ratio, revolutions,
                    float(np.mean(force)), float(np.mean(r)), plane)


def end_state(result, window: float = WINDOW_S) -> EndState:
    """The end state of a run (:class:`physics.results.Result`) over its last ``window`` seconds:
    the worse of its two retainer planes (:func:`classify`), or UNDECIDED if the run left the
    model's validity before its end without whirling backward first."""
    t_end = float(result.t[-1])
    if not (isinstance(window, (int, float)) and 0.0 < window <= t_end):
        raise ValueError(f"window = {window!r} s: allowed (0, {t_end:g}] s (the run's length)")
    t0 = t_end - window
    i = int(np.searchsorted(result.t, t0, "left"))
    c = result.model.scene.contact.clearance
    states = [classify(result.t[i:], result.orbit_after(p, t0, relative=True),
                       result.penetration(p)[i:], result.contact_force(p)[i:],
                       result.rotor_speed[i:], c, p) for p in PLANES]
    worst = min(states, key=lambda s: END_STATES.index(s.label))
    left_at, _ = first_bound(left_validity(result))
    if left_at is None:
        return worst
    valid = result.until(left_at)               # the whirl rule within validity only
    whirled = any(whirl(valid, p, 0.0)["backward_whirl"] for p in PLANES)
    return EndState("backward_whirl" if whirled else UNDECIDED,
                    **{k: v for k, v in worst.to_dict().items() if k != "label"})
