"""Where a controller runs: its *seat*, part of what a controller is.

An active-magnetic-bearing machine has two places a control law can live:

``controller``
    Inside the AMB controller, the digital loop that samples the position sensors and drives
    the coil amplifiers at 5-10 kHz: raw coil currents (``command="continuous"``) and the
    support dampers, a 0.1-0.2 ms control step, the sensing model's noise and delay (the
    sensor's own), and no transport latency (nothing travels between computers).
``supervisor``
    On a supervisory computer over the AMB controller's built-in PID (``command`` ``supervisor``
    or ``discrete``, or currents and dampers sent down a link): a 1-5 ms step, the same sensing,
    and the transport latency a transfer between the computers adds (the robust suite draws it
    per drop).

A :class:`Seat` maps to the env kwargs that put a law there (:meth:`Seat.env_kwargs`) and
checks that a row's env kwargs belong to it (:meth:`Seat.admits`). Controllers declare theirs
(``Controller.seat``; by default from the channels they command, :func:`seat_of`); a learned
policy sits where its training env kwargs put it (:func:`seat_for_kwargs`).
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Seat:
    """A place a control law runs (module doc): its allowed control steps [s], default step,
    the re-levitation commands it can issue (None: a law without AMB command, e.g. dampers
    only) and whether the transport latency of a scenario applies."""
    name: str
    about: str
    control_dt: tuple[float, float]
    default_dt: float
    commands: tuple[str | None, ...]
    transport_latency: bool

    def admits(self, env_kwargs: dict) -> bool:
        """Whether a row with ``env_kwargs`` (its ``control_dt``, default 1 ms, and
        ``command``) runs in this seat."""
        dt = float(env_kwargs.get("control_dt", 1e-3))
        lo, hi = self.control_dt
        return lo - 1e-12 <= dt <= hi + 1e-12 and env_kwargs.get("command") in self.commands

    def env_kwargs(self, control_dt: float | None = None) -> dict:
        """The env kwargs this seat fixes: the control step (``control_dt``, checked against the
        seat's range, else the default)."""
        dt = self.default_dt if control_dt is None else float(control_dt)
        lo, hi = self.control_dt
        if not lo - 1e-12 <= dt <= hi + 1e-12:
            raise ValueError(f"control_dt = {1e3 * dt:g} ms is outside the {self.name} seat's "
                             f"{1e3 * lo:g}-{1e3 * hi:g} ms")
        return {"control_dt": dt}


CONTROLLER = Seat("controller", "inside the AMB controller: raw currents and dampers, "
                                "0.1-0.2 ms step, the sensor's noise and delay, no transport "
                                "latency", (1e-4, 2e-4), 2e-4, (None, "continuous"), False)
SUPERVISOR = Seat("supervisor", "a supervisory computer over the built-in PID: 1-5 ms step, the "
                                "sensor's noise and delay plus the drawn transport latency",
                  (1e-3, 5e-3), 1e-3, (None, "continuous", "discrete", "supervisor"), True)
#: every seat by name
SEATS: dict[str, Seat] = {s.name: s for s in (CONTROLLER, SUPERVISOR)}


def check_seat(name: str) -> Seat:
    """The seat named ``name``; ValueError naming the seats otherwise."""
    if name not in SEATS:
        raise ValueError(f"seat = {name!r} must be one of {', '.join(SEATS)}")
    return SEATS[name]


def seat_of(cls) -> Seat:
    """A controller class's seat: its ``seat`` attribute, else ``supervisor`` when it commands
    the built-in PID (``levitate``, ``gain`` or ``offsets`` channels) and ``controller``
    otherwise (raw currents, dampers, or nothing)."""
    name = getattr(cls, "seat", None)
    if name is not None:
        return check_seat(name)
    pid = {"levitate", "gain", "offsets"} & set(getattr(cls, "needs", ()))
    return SUPERVISOR if pid else CONTROLLER


def seat_for_kwargs(env_kwargs: dict) -> Seat:
    """The seat of a row that runs with ``env_kwargs`` (a learned policy: its training kwargs);
    ValueError when no seat admits them (say a 0.5 ms step)."""
    for seat in SEATS.values():
        if seat.admits(env_kwargs):
            return seat
    raise ValueError(f"no seat runs control_dt = {1e3 * float(env_kwargs.get('control_dt', 1e-3)):g} "
                     f"ms with command {env_kwargs.get('command')!r}: "
                     + "; ".join(f"{s.name}: {1e3 * s.control_dt[0]:g}-{1e3 * s.control_dt[1]:g} ms"
                                 for s in SEATS.values()))
