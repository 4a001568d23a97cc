"""The ``info`` of the environments, built from the kernel arrays of one environment or of a
batch (the single environment, the Gymnasium vector environment and the SB3 VecEnv all use
:func:`info_dict` on the numbers of :func:`rotordrop_env.kernels.info_values`).

The contract, which any RL library can rely on:

* the same keys at reset and at every step (for a given environment and its settings);
* every value a numpy scalar (single environment) or a numpy array with one entry per
  environment (batches): ``np.float64``, ``np.bool_`` or ``np.int64``, never a Python object;
* no NaN anywhere: a value that does not exist is the sentinel ``MISSING`` (-1.0), next to a
  boolean that says whether it exists (``kpi_relevitated`` for ``kpi_relevitation_time_s``),
  or a fixed property of the scene (``kpi_max_ball_load_N`` without Sopanen-Mikkola balls).

The ``kpi_*`` entries are the episode's KPIs so far: at the final step (terminated or
truncated, also by a ``TimeLimit``) they are the episode's KPIs.
"""
from __future__ import annotations

import numpy as np

from . import kernels as K
from .kernels import MISSING  # noqa: F401  (re-exported: the documented sentinel)

REWARD_TERMS = ("whirl", "contact", "displacement", "effort", "success", "failure")
#: the components of ``info["cost"]`` (Safety-Gymnasium convention: a cost >= 0 per step): 1 in
#: a step in which the rotor reaches the AMB stator, a contact force exceeds the retainer
#: bearing's static load rating, a penetration is past its contact law's validity bound
COST_TERMS = ("cost_stator_contact", "cost_bearing_overload", "cost_contact_validity")
#: the running KPIs the KPI reward's potential is built from (rotordrop_env.reward)
PEAK_KEYS = ("kpi_peak_whirl_revolutions", "kpi_peak_contact_force_N", "kpi_max_displacement_um")

#: the float entries, in the order of the kernel's V_* values
FLOAT_KEYS = ("contact_force_N", *("reward_" + t for t in REWARD_TERMS), "time_s", "cost",
              *COST_TERMS, "kpi_whirl_revolutions", "kpi_peak_whirl_revolutions",
              "kpi_peak_contact_force_N", "kpi_max_displacement_um", "kpi_relevitation_time_s",
              "kpi_control_effort", "kpi_max_ball_load_N", "kpi_max_contact_pressure_MPa",
              "kpi_time_within_validity_s", "kpi_friction_energy_J")
assert len(FLOAT_KEYS) == K.N_V_FLOAT
#: the bool entries and their V_* values ("relevitated": re-levitation environments only)
_BOOLS = (("backward_whirl", K.V_WHIRL), ("relevitated", K.V_RELEV),
          ("kpi_backward_whirl", K.V_WHIRL), ("kpi_relevitated", K.V_RELEV),
          ("kpi_stator_contact", K.V_STATOR), ("kpi_bearing_overload", K.V_OVERLOAD),
          ("beyond_validity", K.V_BEYOND), ("kpi_beyond_validity", K.V_BEYOND))
_BOOL_KEYS = {r: tuple(k for k, _ in _BOOLS if r or k != "relevitated") for r in (False, True)}
_BOOL_IDX = {r: np.array([i for k, i in _BOOLS if r or k != "relevitated"]) for r in (False, True)}
_NF = K.N_V_FLOAT
#: every key in its order: the floats, the bools, the latency, the episode time
_KEYS = {r: FLOAT_KEYS + _BOOL_KEYS[r] + ("obs_latency_steps", "kpi_episode_time_s")
         for r in (False, True)}
_BOOL_SLOTS = {r: tuple(int(i) for i in _BOOL_IDX[r]) for r in (False, True)}
_NP_BOOL = (np.False_, np.True_)            # numpy's two bool scalars (no allocation per step)
assert min(_BOOL_SLOTS[True]) >= _NF        # the bools follow the floats in V_*


def info_dict(v: np.ndarray, latency, relevitate: bool) -> dict:
    """The ``info`` from the numbers ``v`` of one environment (``(N_V,)``: numpy scalars) or of
    N (``(N, N_V)``: arrays of N, one fresh array each); ``latency``: the episode's observation
    latency (int, or int array of N)."""
    if v.ndim == 1:
        return _one(list(v[:_NF]), _tail(v.tolist(), latency, relevitate), v[K.V_TIME],
                    relevitate)
    bidx = _BOOL_IDX[relevitate]
    cols = v.T.copy()                        # fresh: nothing a caller holds is reused
    info = dict(zip(FLOAT_KEYS, cols[:_NF]))
    info.update(zip(_BOOL_KEYS[relevitate], cols[bidx] > 0.0))
    info["obs_latency_steps"] = np.array(latency, dtype=np.int64)
    info["kpi_episode_time_s"] = info["time_s"].copy()
    return info


def _tail(numbers: list, latency, relevitate: bool) -> list:
    """The entries after the floats but the episode time: the bools (numpy's two bool scalars,
    from the numbers as Python floats) and the latency (a numpy int)."""
    return [_NP_BOOL[numbers[i] > 0.0] for i in _BOOL_SLOTS[relevitate]] + [np.int64(latency)]


def _one(floats: list, tail: list, time, relevitate: bool) -> dict:
    """One environment's info, built in one go (it is made every step): its float entries
    ``floats`` (fresh numpy scalars), the :func:`_tail` entries, then its time (a numpy
    scalar of its own)."""
    floats += tail
    floats.append(time)
    return dict(zip(_KEYS[relevitate], floats))


class StepInfo:
    """The ``info`` of one environment, made at every step: :func:`info_dict`'s, built on a
    template holding the bools and the latency (which change a few times per episode at most),
    made again only when their numbers change, and copied with the step's numbers."""

    def __init__(self, relevitate: bool):
        self.relevitate = relevitate
        self._key: tuple | None = None
        self._template: dict = {}

    def __call__(self, v: np.ndarray, latency: int) -> dict:
        return self.made(list(v[:_NF]), v[_NF:].tobytes(), latency, v[K.V_TIME])

    def made(self, floats: list, rest: bytes, latency: int, time) -> dict:
        """The info of one environment's numbers (``(N_V,)``): its float entries ``floats``
        (fresh numpy scalars), the bytes ``rest`` of the entries after them, its latency and
        its time ``time`` (a numpy scalar of its own)."""
        key = (rest, latency)
        if key != self._key:
            self._key = key
            numbers = [0.0] * _NF + np.frombuffer(rest).tolist()
            self._template = _one([None] * _NF, _tail(numbers, latency, self.relevitate),
                                  None, self.relevitate)
        info = self._template.copy()             # keys in order, the bools and the latency
        info.update(zip(FLOAT_KEYS, floats))
        info["kpi_episode_time_s"] = time
        return info


def row_infos(v: np.ndarray, latency: np.ndarray, relevitate: bool,
              step_infos: list[StepInfo] | None = None) -> list[dict]:
    """Each environment's info (numpy scalars, as a single environment's) from the numbers
    ``v`` of N, ``(N, N_V)``: the SB3 VecEnv's list of infos (the numpy scalars made in one
    pass); ``step_infos``: each row's :class:`StepInfo` (the environments' own), else new ones."""
    n = v.shape[0]
    floats = list(v[:, :_NF].ravel())
    times = list(v[:, K.V_TIME])
    rest = np.ascontiguousarray(v[:, _NF:]).tobytes()
    size = len(rest) // n if n else 0
    lat = np.asarray(latency, dtype=np.int64).tolist()
    if step_infos is None:
        step_infos = [StepInfo(relevitate) for _ in range(n)]
    return [s.made(floats[e * _NF:(e + 1) * _NF], rest[e * size:(e + 1) * size], lat[e],
                   times[e]) for e, s in enumerate(step_infos)]


def kpi_keys(info: dict) -> dict:
    """The ``kpi_*`` entries of ``info``."""
    return {k: v for k, v in info.items() if k.startswith("kpi_")}
