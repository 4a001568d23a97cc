"""The designed rows of the supervisor interface: ``inner-loop`` and ``whirl-brake-sup``."""
import numpy as np
import pytest

from agents.control.controllers import controller_env_kwargs
from agents.control.controllers import BASELINES, InnerLoop, WhirlBrake, WhirlBrakeSupervisor, command_for
from agents.control.plant import Plant, make_env
from agents.benchmarking.rollout import run_episodes

FULL = "RotorDrop-Full-v1"
KW = dict(command="supervisor", episode_time=0.15, terminate_on_failure=False,
          power_return_time=0.02, overrides={"contact.friction": 0.3})


def test_rows_are_baselines_in_the_supervisor_mode():
    for cls in (InnerLoop, WhirlBrakeSupervisor):
        assert BASELINES[cls.name] is cls and command_for(cls) == "supervisor"
        assert controller_env_kwargs(cls, FULL) == {"command": "supervisor", "control_dt": 1e-3}


def test_inner_loop_is_the_builtin_pid_with_c_max():
    """inner-loop in the supervisor mode runs the trajectory of the discrete mode's built-in
    controller with C_max, and re-levitates."""
    ep = run_episodes(FULL, InnerLoop, [0], KW)[0]
    env = make_env(FULL, **{**KW, "command": "discrete"})
    env.reset(seed=0)
    done, info = False, {}
    while not done:
        _, _, term, trunc, info = env.step(np.ones(3, dtype=np.float32))
        done = term or trunc
    assert ep.kpis["relevitated"]
    for k in ("peak_contact_force_N", "max_displacement_um", "relevitation_time_s",
              "peak_whirl_revolutions"):
        assert ep.kpis[k] == info["kpi_" + k]


def test_whirl_brake_sup_turns_whirl_brake_terms_into_offsets():
    """A rotor resting still at 0.8 c below the centre (outside r_on): whirl-brake's push
    k_t s J x̂ − k_r x̂ becomes the tangential offset k_t i_max/(k_p c) and the radial offset
    −k_r i_max/(k_p c) in both planes; zero velocity, so no cross-coupled term."""
    env = make_env(FULL, **KW)
    plant = Plant.from_env(env)
    obs, _ = env.reset(seed=0)
    obs = np.array(obs, dtype=np.float64)
    for name, value in (("x1", 0.0), ("y1", -0.8), ("x2", 0.0), ("y2", -0.8)):
        obs[plant.index(name)] = value                 # in units of the clearance (obs scale)
    for name in ("vx1", "vy1", "vx2", "vy2"):
        obs[plant.index(name)] = 0.0
    ctrl = WhirlBrakeSupervisor(plant)
    a, _ = ctrl.predict(obs)
    g = WhirlBrake.GAINS
    per = plant.current_limit / plant.pid[0] / plant.clearance
    cols = [plant.action_names.index(n)
            for n in ("offset_r1", "offset_t1", "offset_r2", "offset_t2")]
    np.testing.assert_allclose(a[cols], np.array([-g["kr"], g["kt"]] * 2) * per, rtol=1e-6)
    assert a[plant.action_names.index("levitate")] == 1.0
    assert a[plant.action_names.index("gain")] == 0.0
    np.testing.assert_array_equal(a[:2], [1.0, 1.0])


@pytest.mark.parametrize("cls", [InnerLoop, WhirlBrakeSupervisor])
def test_rows_relevitate_after_a_whirl_free_drop(cls):
    ep = run_episodes(FULL, cls, [0], KW)[0]
    assert ep.kpis["relevitated"] and not ep.kpis["backward_whirl"]


def test_inner_loop_lift_commands_constants_and_switches_on_at_the_power_return():
    """inner-loop-lift: C_max, levitate on, gain action 0.5 and radial offsets -0.5 clearance
    on both planes (no tangential offset) at every step, at its 5 ms control step; the built-in
    PID engages in the step the power returns (20 ms), not before; and the lift-assist
    re-levitates sooner than the plain inner loop on the same drop."""
    from agents.control.controllers import InnerLoopLift
    kw = {**KW, **controller_env_kwargs(InnerLoopLift, FULL)}
    assert kw["control_dt"] == 0.005 and BASELINES["inner-loop-lift"] is InnerLoopLift
    env = make_env(FULL, **kw)
    plant = Plant.from_env(env)
    ctrl = InnerLoopLift(plant)
    obs, _ = env.reset(seed=0)
    col = {n: plant.action_names.index(n) for n in plant.action_names}
    on_at = None
    for k in range(10):
        a, _ = ctrl.predict(obs)
        assert a[col["damping1"]] == a[col["damping2"]] == 1.0 and a[col["levitate"]] == 1.0
        assert a[col["gain"]] == 0.5
        assert a[col["offset_r1"]] == a[col["offset_r2"]] == -0.5
        assert a[col["offset_t1"]] == a[col["offset_t2"]] == 0.0
        obs, *_ = env.step(a)
        if on_at is None and plant.get(obs[None], "controller_on")[0] > 0.5:
            on_at = k * 0.005                       # the step that engaged it started here
    assert on_at == pytest.approx(KW["power_return_time"])
    lift, plain = (run_episodes(FULL, cls, [0], kw)[0].kpis for cls in (InnerLoopLift, InnerLoop))
    assert lift["relevitated"] and plain["relevitated"]
    assert lift["relevitation_time_s"] < plain["relevitation_time_s"] - 0.01


def test_inner_loop_constants_are_checked():
    plant = Plant.from_env(make_env(FULL, **KW))
    with pytest.raises(ValueError, match=r"^offset_r = -1.5 must be in \[-1, 1\] \(a supervisor action\)$"):
        InnerLoop(plant, offset_r=-1.5)
    with pytest.raises(ValueError, match=r"^gain = 2 must be in \[-1, 1\]"):
        InnerLoop(plant, gain=2)


def test_inner_loop_lift_is_a_full_task_baseline_of_both_suites():
    from agents.benchmarking.benchmark import _entries, robust_entries
    entries = {(e.task, e.name): e for e in _entries([])}
    assert entries[("full", "inner-loop-lift")].env_kwargs == {"command": "supervisor",
                                                                "control_dt": 0.005}
    assert ("damping", "inner-loop-lift") not in entries
    assert "inner-loop-lift" in {e.name for e in robust_entries([])[0]}
