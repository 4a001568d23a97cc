"""The how-tos' worked examples (docs/examples/howto_*.py) run as the pages show them: each page
includes its code from the example file, so these tests are what keeps the pages true."""
import importlib.util
import math
import re
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "docs" / "examples"


def _example(name: str):
    spec = importlib.util.spec_from_file_location(f"docs_example_{name}", EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("page, example", [("controller", "howto_controller"),
                                           ("env-task", "howto_env_task")])
def test_each_howto_page_includes_its_example_file(page, example):
    """The page's code is the example's (pymdownx.snippets), not a copy that can drift."""
    text = (ROOT / "docs" / "howto" / f"{page}.md").read_text()
    included = re.findall(r'--8<-- "docs/examples/([\w.]+):(\w+)"', text)
    assert included and all(f == f"{example}.py" for f, _ in included)
    source = (EXAMPLES / f"{example}.py").read_text()
    for _, section in included:
        assert f"# --8<-- [start:{section}]" in source and f"# --8<-- [end:{section}]" in source


def test_controller_howto_latches_the_dampers_and_they_follow_their_first_order_lag():
    """LatchDamping, loaded as ``rotordrop evaluate --policy file.py:Class`` loads it and run as
    a temporary baseline: it holds the start damping until the rotor nears the retainer, then
    commands C_max, and the damper state follows C_max - (C_max - C_0) exp(-t / tau)."""
    from agents.control.controllers import BASELINES, load_controller
    from physics.scene import load_scene
    cls = load_controller(f"{EXAMPLES / 'howto_controller.py'}:LatchDamping")
    assert cls.name == "latch-damping" and cls.needs == ("damping",)
    run = _example("howto_controller").run_episode(episode_time=0.06)
    assert "latch-damping" not in BASELINES                 # registered for the episode only
    scene = load_scene("paper")
    c0, c_max = scene.support.damping, scene.support.damping_max
    tau, dt, t_latch = scene.support.damper_time_constant, run["control_dt"], run["latched_at"]
    assert run["damping_range"][1] == c_max and 0.0 < t_latch < 0.03   # latched in the drop
    d = run["damping1"]
    k_latch = int(round(t_latch / dt))
    assert np.allclose(d[:k_latch], c0, rtol=1e-6)          # held until the latch
    for k in range(k_latch, len(d)):
        t = (k + 1) * dt - t_latch                          # d[k] is the state after step k
        assert d[k] == pytest.approx(c_max - (c_max - c0) * math.exp(-t / tau), rel=1e-5)
    assert d[-1] > c_max - (c_max - c0) * math.exp(-4.0)


def test_env_task_howto_declares_a_new_task_that_catches_the_rotor_and_leaves_no_trace():
    """RotorDrop-Catch-v0: with the AMB power back at the fault, switching the built-in PID on
    at the first step keeps the rotor off its retainer (no contact force, a few µm, re-levitated
    by the KPI reward's measure); left off, the rotor drops through the clearance onto the
    retainer. Registered for the example only: no id, task or entry point is left behind."""
    import gymnasium as gym

    import rotordrop_env
    from physics.scene import load_scene
    from rotordrop_env.tasks import TASKS
    example = _example("howto_env_task")
    out = example.main()
    caught, dropped = out["caught"], out["dropped"]
    clearance = load_scene("paper").contact.clearance
    assert caught["kpi_relevitated"] and caught["kpi_peak_contact_force_N"] == 0.0
    assert caught["kpi_max_displacement_um"] < 0.05 * clearance * 1e6
    assert not dropped["kpi_relevitated"] and dropped["kpi_peak_contact_force_N"] > 1e3
    assert dropped["kpi_max_displacement_um"] > clearance * 1e6
    assert caught["return"] > 0.0 > dropped["return"]
    env_id = example.CATCH.env_id
    assert env_id not in gym.registry and env_id not in TASKS and env_id not in rotordrop_env.ENV_IDS


@pytest.mark.filterwarnings("ignore::UserWarning")          # torch's threads (the SB3 VecEnv)
def test_a_declared_task_runs_the_same_numbers_single_and_batched():
    """The how-to's step 'check it': one short episode of the new task by gym.make equals the
    same seed in its Gymnasium vector environment and in the SB3 VecEnv, bit for bit."""
    import gymnasium as gym

    from rotordrop_env import make_batched
    from rotordrop_env.tasks import TASKS
    task = _example("howto_env_task").CATCH
    kwargs = dict(episode_time=0.01, randomize=True)
    with TASKS.temporary(task):
        env = gym.make(task.env_id, **kwargs)
        obs, _ = env.reset(seed=3)
        single = [obs]
        for _ in range(5):
            single.append(env.step(1)[0])
        vec = gym.make_vec(task.env_id, num_envs=2, vectorization_mode="vector_entry_point",
                           **kwargs)
        obs, _ = vec.reset(seed=3)
        batched = [obs[0]] + [vec.step(np.array([1, 0]))[0][0] for _ in range(5)]
        sb3 = make_batched(task.env_id, n_envs=2, seed=3, **kwargs)
        sb3_rows = [sb3.reset()[0]] + [sb3.step(np.array([1, 0]))[0][0] for _ in range(5)]
        assert env.unwrapped.scenario["contact.friction"] >= 0.3      # the task's draw
    np.testing.assert_array_equal(np.array(single), np.array(batched))
    np.testing.assert_array_equal(np.array(single), np.array(sb3_rows))
