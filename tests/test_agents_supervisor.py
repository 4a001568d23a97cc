"""The designed rows of the supervisor interface: ``inner-loop`` and ``whirl-brake-sup``."""
import numpy as np
import pytest

from agents.benchmark import controller_env_kwargs
from agents.controllers import BASELINES, InnerLoop, WhirlBrake, WhirlBrakeSupervisor, command_for
from agents.plant import Plant, make_env
from agents.rollout import run_episodes

FULL = "RotorDrop-Full-v0"
KW = dict(command="supervisor", episode_time=0.15, terminate_on_failure=False,
          power_return_time=0.02, overrides={"contact.friction": 0.3})


def test_rows_are_baselines_in_the_supervisor_mode():
    for cls in (InnerLoop, WhirlBrakeSupervisor):
        assert BASELINES[cls.name] is cls and command_for(cls) == "supervisor"
        assert controller_env_kwargs(cls, FULL) == {"command": "supervisor"}


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
