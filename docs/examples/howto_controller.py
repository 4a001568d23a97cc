"""A controller of one's own: ``LatchDamping`` holds the support dampers at their start value
until the rotor first comes within 10 % of the retainer bearing, then commands C_max for the
rest of the episode (the how-to: docs/howto/controller.md).

    rotordrop evaluate --policy docs/examples/howto_controller.py:LatchDamping \\
                       --env RotorDrop-Damping-v1 --episodes 20 --out out/latch
    python docs/examples/howto_controller.py          # one episode, the damper's response
"""
from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from agents.control.controllers import BASELINES, Controller, make_baseline
from agents.control.plant import make_env, plant_of


# --8<-- [start:controller]
class LatchDamping(Controller):
    """C_max from the first time the rotor comes within 10 % of the retainer bearing on."""
    name = "latch-damping"
    needs = ("damping",)              # channels: damping, currents, levitate, gain, offsets
    GAINS = {"trigger": 0.9}          # optional: what `rotordrop tune` starts from

    def __init__(self, plant, trigger=0.9):
        super().__init__(plant)
        self.trigger = trigger        # constants in __init__

    def reset(self, n, which=None):   # per-episode state in reset
        super().reset(n, which)       # resets self.t and self.hold
        if which is None:
            self.latched = np.zeros(n, dtype=bool)
        else:
            self.latched[which] = False

    def commands(self, obs):          # obs: (n, n_obs) raw observations
        p = self.plant
        r = np.hypot(p.get(obs, "x1"), p.get(obs, "y1"))
        self.latched |= r > self.trigger * p.clearance
        return {"damping": np.where(self.latched[:, None], 1.0, self.hold)}
# --8<-- [end:controller]


# --8<-- [start:baseline]
@contextmanager
def as_baseline(cls: type[Controller]):
    """``cls`` as a built-in baseline (``make_baseline(cls.name, plant)``, ``--policy NAME``)
    inside the ``with`` block only; shipping it means adding it to ``BASELINES`` for good."""
    if cls.name in BASELINES:
        raise ValueError(f"{cls.name!r} is a baseline already")
    BASELINES[cls.name] = cls
    try:
        yield cls
    finally:
        del BASELINES[cls.name]
# --8<-- [end:baseline]


# --8<-- [start:episode]
def run_episode(env_id: str = "RotorDrop-Damping-v1", seed: int = 0, **env_kwargs) -> dict:
    """One episode of the baseline ``latch-damping`` in ``env_id``: the time it latched [s]
    (None: never) and the damper state C_s of housing 1 [N s/m] at every step."""
    with as_baseline(LatchDamping):
        ctrl = make_baseline("latch-damping", plant_of(env_id, **env_kwargs))
    env = make_env(env_id, **env_kwargs)
    obs, info = env.reset(seed=seed)
    latched_at, damping, done = None, [], False
    while not done:
        action, _ = ctrl.predict(obs)
        if latched_at is None and ctrl.latched[0]:
            latched_at = float(ctrl.plant.get(obs[None], "time")[0])
        obs, reward, terminated, truncated, info = env.step(action)
        damping.append(ctrl.plant.get(obs[None], "damping1")[0])
        done = terminated or truncated
    env.close()
    return {"latched_at": latched_at, "damping1": np.array(damping),
            "damping_range": ctrl.plant.damping_range, "control_dt": ctrl.plant.control_dt}
# --8<-- [end:episode]


if __name__ == "__main__":
    run = run_episode(episode_time=0.1)
    print(f"latched at {run['latched_at']:.3f} s; damper C_s: start {run['damping1'][0]:.0f}, "
          f"end {run['damping1'][-1]:.0f} N s/m (C_max {run['damping_range'][1]:.0f})")
