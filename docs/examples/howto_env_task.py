"""A new environment task, declared and registered: ``RotorDrop-Catch-v0``.

The AMB power comes back at the instant of the fault (``power_return_time=0``), so the agent
can switch the built-in levitation controller on before the rotor has fallen: it catches the
rotor in the air, or lets it drop onto its retainer bearings. The task is one declaration
(:class:`rotordrop_env.tasks.Task`); its episode ends only when the rotor reaches the AMB
stator, and its reward is the KPI reward.

    python docs/examples/howto_env_task.py

runs one episode with the controller switched on at the first step and one with it left off,
and prints their KPIs (the how-to: docs/howto/env-task.md).
"""
from __future__ import annotations

import gymnasium as gym

from rotordrop_env.tasks import TASKS, Task

# --8<-- [start:task]
CATCH = Task(
    "Catch", version=0,
    commands=("amb",),                    # the agent commands the AMBs (command="discrete")
    power_return_time=0.0,                # ... whose power returns at the fault
    reward="kpi",                         # the KPI reward of rotordrop_env.reward
    constraints=("stator_contact",),      # only reaching the AMB stator ends an episode
    randomization={"contact.friction": (0.3, 0.6)},   # randomize=True draws a higher friction
    summary="catch the falling rotor with the AMBs, whose power returns at the fault")
# --8<-- [end:task]


# --8<-- [start:episode]
def run_episode(levitate: int, seed: int = 0, episode_time: float = 0.06) -> dict:
    """One episode of ``RotorDrop-Catch-v0`` with the constant action ``levitate`` (1: switch
    the built-in controller on at the first step; 0: leave the AMBs off): its return and KPIs."""
    env = gym.make(CATCH.env_id, episode_time=episode_time)
    obs, info = env.reset(seed=seed)
    episode_return, done = 0.0, False
    while not done:
        obs, reward, terminated, truncated, info = env.step(levitate)
        episode_return += reward
        done = terminated or truncated
    env.close()
    return {"return": episode_return, **{k: v for k, v in info.items() if k.startswith("kpi_")}}


def main() -> dict:
    with TASKS.temporary(CATCH):          # registered for this block only (TASKS.register: for good)
        caught, dropped = run_episode(levitate=1), run_episode(levitate=0)
    for name, kpis in (("switched on", caught), ("left off", dropped)):
        print(f"{name:12s} return {kpis['return']:7.3f}, re-levitated {kpis['kpi_relevitated']}, "
              f"peak contact force {kpis['kpi_peak_contact_force_N']:7.1f} N, "
              f"max displacement {kpis['kpi_max_displacement_um']:6.1f} µm")
    return {"caught": caught, "dropped": dropped}
# --8<-- [end:episode]


if __name__ == "__main__":
    main()
