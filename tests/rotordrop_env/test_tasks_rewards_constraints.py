"""Tasks, rewards and episode constraints as objects: the shorthand strings and the objects give
the same episodes, a constraint that does not end the episode is still monitored, and a task
declared with rotordrop_env.tasks runs without a new class (the how-to's task is in
tests/test_howtos.py)."""
import gymnasium as gym
import numpy as np
import pytest

import rotordrop_env  # noqa: F401  (registers the ids)
from rotordrop_env.constraints import CONSTRAINTS, resolve_constraints
from rotordrop_env.reward import KPI_WEIGHTS, KpiPotentialReward, TermReward, make_reward
from rotordrop_env.tasks import TASKS, Task

#: an AMB stator 100 µm from the centre, inside the 300 µm clearance: the falling rotor reaches
#: it a few milliseconds after the fault, long before it meets its retainer bearing
NEAR_STATOR = {"amb.air_gap": 1e-4}


def _episode(env_id, action, steps=None, **kwargs):
    env = gym.make(env_id, **kwargs)
    obs, info = env.reset(seed=1)
    rows = []
    for _ in range(steps or 10_000):
        obs, reward, terminated, truncated, info = env.step(action)
        rows.append((obs.copy(), reward, terminated, truncated, dict(info)))
        if terminated or truncated:
            break
    env.close()
    return rows


def test_the_shipped_tasks_are_declarations_and_their_classes_run_them():
    from rotordrop_env.env import DampingEnv, FullEnv, PassiveEnv, RelevitateEnv
    assert [t.env_id for t in TASKS.values()] == list(rotordrop_env.ENV_IDS)
    for cls, interfaces in ((PassiveEnv, ()), (DampingEnv, ("damper",)),
                            (RelevitateEnv, ("amb",)), (FullEnv, ("damper", "amb"))):
        assert cls.task.commands == interfaces and TASKS[cls.task.env_id] is cls.task
        assert rotordrop_env.ENV_IDS[cls.task.env_id] == f"rotordrop_env.env:{cls.__name__}"


def test_a_constraint_left_out_is_monitored_but_ends_nothing():
    """Near the stator every constraint set sees the same drop: the default ends the episode in
    the first step at the stator; without stator_contact (or with terminate_on_failure=False)
    the episode runs on, with the same cost in that step and the same latched KPI."""
    kw = dict(overrides=NEAR_STATOR, episode_time=0.02)
    ends = _episode("RotorDrop-Passive-v1", [0.0], **kw)
    free = _episode("RotorDrop-Passive-v1", [0.0], constraints=("bearing_overload",
                                                                  "contact_validity"), **kw)
    off = _episode("RotorDrop-Passive-v1", [0.0], terminate_on_failure=False, **kw)
    k = len(ends) - 1
    assert ends[k][2] and 0 < k < 19 and ends[k][4]["cost_stator_contact"] == 1.0
    assert not any(r[2] for r in free) and free[-1][3] and len(free) == 20
    for run in (free, off):
        for (o1, r1, _, _, i1), (o2, r2, _, _, i2) in zip(ends[:k], run[:k]):
            np.testing.assert_array_equal(o1, o2)
            assert r1 == r2 and i1["cost"] == i2["cost"] == 0.0
        assert run[k][4]["cost_stator_contact"] == 1.0 and run[-1][4]["kpi_stator_contact"]
        np.testing.assert_array_equal(run[k][0], ends[k][0])
    assert ends[k][4]["reward_failure"] < 0.0 == free[k][4]["reward_failure"]


def test_constraints_by_name_or_object_and_bad_ones_named():
    assert resolve_constraints(None, True) == tuple(CONSTRAINTS.values())
    assert resolve_constraints(["bearing_overload", CONSTRAINTS["stator_contact"]], True) == (
        CONSTRAINTS["bearing_overload"], CONSTRAINTS["stator_contact"])
    assert resolve_constraints(None, False) == ()
    with pytest.raises(ValueError, match="'stator_contact', 'bearing_overload', 'contact_validity'"):
        gym.make("RotorDrop-Passive-v1", constraints=("stator",))
    with pytest.raises(ValueError, match="given twice"):
        resolve_constraints(("stator_contact", "stator_contact"), True)
    with pytest.raises(ValueError, match="contradict"):
        gym.make("RotorDrop-Passive-v1", constraints=("stator_contact",), terminate_on_failure=False)


def test_a_reward_object_gives_the_same_rewards_as_its_shorthand():
    weights = dict(w_force=1.0, w_disp=0.2)
    by_name = _episode("RotorDrop-Damping-v1", [0.4, -0.2], steps=30, reward="kpi",
                       reward_kwargs=weights)
    by_object = _episode("RotorDrop-Damping-v1", [0.4, -0.2], steps=30,
                         reward=KpiPotentialReward(weights))
    default = _episode("RotorDrop-Damping-v1", [0.4, -0.2], steps=30)
    terms = _episode("RotorDrop-Damping-v1", [0.4, -0.2], steps=30, reward=TermReward())
    assert [r[1] for r in by_name] == [r[1] for r in by_object]
    assert [r[1] for r in default] == [r[1] for r in terms]
    assert [r[1] for r in by_name] != [r[1] for r in default]
    env = gym.make("RotorDrop-Damping-v1", reward=KpiPotentialReward(weights))
    assert env.unwrapped.reward == "kpi" and env.unwrapped.reward_function.weights == {
        **KPI_WEIGHTS, **weights}


def test_bad_rewards_are_named():
    with pytest.raises(ValueError, match="'default', 'kpi'"):
        make_reward("potential", None)
    with pytest.raises(ValueError, match="reward object"):
        make_reward(TermReward(), {"w_force": 1.0})
    with pytest.raises(ValueError, match="reward_kwargs.w_force"):
        KpiPotentialReward({"w_force": -1.0})


def test_a_task_is_checked_where_it_is_declared_and_where_it_is_made():
    with pytest.raises(ValueError, match="'damper', 'amb'"):
        Task("Spin", commands=("motor",))
    with pytest.raises(ValueError, match="order"):
        Task("Spin", commands=("amb", "damper"))
    with pytest.raises(ValueError, match="CamelCase"):
        Task("spin-up")
    with TASKS.temporary(Task("Spin", version=0, reward="shaped")):
        with pytest.raises(ValueError, match="reward = 'shaped' is not a reward"):
            gym.make("RotorDrop-Spin-v0")
    with pytest.raises(ValueError, match="already a task"):
        TASKS.register(TASKS["RotorDrop-Damping-v1"])
    from rotordrop_env.env import DampingEnv, RotorDropEnv
    assert RotorDropEnv().task == TASKS["RotorDrop-Passive-v1"]        # the base class: passive
    with pytest.raises(ValueError, match="must be a rotordrop_env.tasks.Task"):
        RotorDropEnv(task="Damping")
    with pytest.raises(TypeError, match="register"):
        TASKS["RotorDrop-Spin-v0"] = Task("Spin", version=0)
    with pytest.raises(ValueError, match="runs the Damping task"):
        DampingEnv(task=TASKS["RotorDrop-Full-v1"])


def test_a_task_with_the_damper_and_a_scene_key_of_its_own_runs_as_its_declaration_says():
    """A task that is no combination of class flags: the damper interface, the KPI reward, the
    stator contact forced on and only the bearing overload ending its episodes."""
    task = Task("DampedStator", version=0, commands=("damper",), reward="kpi",
                constraints=("bearing_overload",), scene={"effects.stator_contact": True},
                randomization={"contact.friction": (0.4, 0.5), "rotor.speed_rpm": None})
    with TASKS.temporary(task):
        env = gym.make(task.env_id, randomize=True, episode_time=0.005)
        u = env.unwrapped
        assert u.action_names == ["damping1", "damping2"] and u.reward == "kpi"
        assert u.base_scene.effects.stator_contact and u.base_scene.effects.semi_active_damper
        assert [c.name for c in u.constraints] == ["bearing_overload"]
        assert "rotor.speed_rpm" not in u.ranges and u.ranges["contact.friction"][1:] == (0.4, 0.5)
        env.reset(seed=0)
        assert 0.4 <= u.scenario["contact.friction"] <= 0.5
        assert env.step(np.zeros(2, np.float32))[1] <= 0.0
    assert task.env_id not in gym.registry
