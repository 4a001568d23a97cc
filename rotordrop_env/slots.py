"""The named slots of the environments' flat kernel arrays (:class:`physics.layout.Slots`
tables; numba compiles the module-level ints in as constants):

* ``C``  float64 configuration of the episode (``C_*``), set at construction and reset,
* ``M``  float64 running monitor (``M_*``),
* ``out`` float64 per-step results (``O_*``),
* the ``info`` numbers (``V_*``, named by :mod:`rotordrop_env.info`).

The step kernels (:mod:`rotordrop_env.kernels`), the episode constraints
(:mod:`rotordrop_env.constraints`) and the Python side index them by these names.
"""
from __future__ import annotations

from physics.layout import Slots

# ------------------------------------------------------------------------ configuration C --
#: the episode's configuration C (C_*: control step, fault / end / power-return times, damper
#: and re-levitation modes, solver settings, reward weights, scales and validity bounds)
CONFIG = Slots("configuration")
(C_DT, C_T_FAULT, C_T_END, C_T_POWER, C_DAMP, C_LEV,
 C_RTOL, C_HMAX, C_HMIN, C_FIXED, C_MAXSTEPS,
 C_W_WHIRL, C_W_CONTACT, C_W_DISP, C_W_EFFORT, C_W_SUCCESS, C_W_FAILURE,
 C_F_REF, C_GAP, C_LOAD_RATING, C_HOLD, C_FULL, C_CS_MIN, C_CS_MAX, C_ILIM,
 C_RELEV_RADIUS, C_WHIRL_RADIUS, C_WHIRL_REVS, C_SUP_OFFSET, C_SUP_OCTAVES, C_P_COEF,
 C_PEN_BOUND, C_STATOR_BOUND) = CONFIG.add_each(
    "dt", "t_fault", "t_end", "t_power", "damping_mode", "relevitation_mode",
    "rtol", "max_step", "min_step", "fixed", "max_steps",
    "w_whirl", "w_contact", "w_displacement", "w_effort", "w_success", "w_failure",
    "force_ref", "gap", "load_rating", "hold", "full_state", "damping_min",
    "damping_max", "current_limit", "relevitation_radius", "whirl_radius", "whirl_revs",
    "supervisor_offset", "supervisor_octaves", "pressure_coef", "penetration_bound",
    "stator_bound")
#: C[C_ENDS + j] > 0: constraint j of :data:`rotordrop_env.constraints.CONSTRAINTS` ends the
#: episode when it is violated (it is monitored, and its cost reported, either way)
C_ENDS = CONFIG.add("ends", 3)
#: C[C_UNLATCHED] > 0: the success region's verdict is the present one (a task with
#: ``latched=False``: lost again on contact), else latched at the first success
C_UNLATCHED = CONFIG.add("unlatched")
N_C = CONFIG.freeze().size
#: C[C_P_COEF]: Hertz contact pressure [Pa] = C_P_COEF x cbrt(ball load [N]), < 0 without
#: Sopanen-Mikkola balls (read by the info builder, not by the kernels)
LEV_NONE, LEV_DISCRETE, LEV_CONTINUOUS, LEV_SUPERVISOR = 0, 1, 2, 3
#: C[C_DAMP]: no damper commands, or the damper action's map (env kwarg ``damping_action``)
DAMP_NONE, DAMP_LINEAR, DAMP_FROM_MAX = 0.0, 1.0, 2.0
#: supervisor: below this fraction of the clearance the observed orbit rate is zero
SUP_MIN_RADIUS = 0.05

# ------------------------------------------------------------------------------ monitor M --
MONITOR = Slots("monitor")
(M_T, M_H, M_REV1, M_REV2, M_WHIRL, M_PEAK_F, M_MAX_DISP, M_OK_START, M_RELEV,
 M_RELEV_T, M_EFFORT, M_CTRL_ON, M_POWER, M_REV_PEAK, M_PEAK_Q, M_STATOR, M_OVERLOAD,
 M_BEYOND, M_LEFT_T, M_PHI, M_FRICTION) = MONITOR.add_each(
    "t", "h", "revolutions1", "revolutions2", "whirl", "peak_force", "max_displacement",
    "ok_start", "relevitated", "relevitation_time", "effort", "controller_on", "power",
    "peak_revolutions", "peak_ball_load", "stator", "overload", "beyond", "left_time", "phi",
    "friction_energy")
N_M = MONITOR.freeze().size
#: M[M_PHI]: the KPI reward's potential after the last step (rotordrop_env.reward; 0 at reset)

# ------------------------------------------------------------------------------ outputs --
OUTPUTS = Slots("output")
(O_REWARD, O_R_WHIRL, O_R_CONTACT, O_R_DISP, O_R_EFFORT, O_R_SUCCESS, O_R_FAILURE, O_FORCE,
 O_TERM, O_TRUNC, O_STATUS, O_ERR, O_STATOR, O_OVERLOAD, O_RELEV, O_BEYOND) = OUTPUTS.add_each(
    "reward", "r_whirl", "r_contact", "r_displacement", "r_effort", "r_success", "r_failure",
    "force", "terminated", "truncated", "status", "error", "stator", "overload", "relevitated",
    "beyond")
N_O = OUTPUTS.freeze().size
#: out[O_RELEV]: 1 in the step in which re-levitation is achieved
ERR_NONE, ERR_NAN, ERR_RANGE = 0, 1, 2
# ------------------------------------------------------------------ info values (V_*) --
#: the numbers of ``info`` (rotordrop_env.info names them): floats first, then flags (> 0: True)
INFO = Slots("info value")
(V_FORCE, V_R_WHIRL, V_R_CONTACT, V_R_DISP, V_R_EFFORT, V_R_SUCCESS, V_R_FAILURE, V_TIME,
 V_COST, V_COST_STATOR, V_COST_OVERLOAD, V_COST_VALIDITY, V_WHIRL_REVS, V_PEAK_REVS, V_PEAK_F,
 V_MAX_DISP_UM, V_RELEV_T, V_EFFORT, V_BALL_Q, V_PRESSURE_MPA, V_TIME_VALID,
 V_FRICTION) = INFO.add_each(
    "force", "r_whirl", "r_contact", "r_displacement", "r_effort", "r_success", "r_failure",
    "time", "cost", "cost_stator", "cost_overload", "cost_validity", "whirl_revolutions",
    "peak_revolutions", "peak_force", "max_displacement_um", "relevitation_time", "effort",
    "ball_load", "pressure_mpa", "time_valid", "friction_energy")
N_V_FLOAT = INFO.size
V_WHIRL, V_RELEV, V_STATOR, V_OVERLOAD, V_BEYOND = INFO.add_each(
    "whirl", "relevitated", "stator", "overload", "beyond")
N_V = INFO.freeze().size
#: the value of an info entry that does not exist (no re-levitation, no ball model)
MISSING = -1.0
