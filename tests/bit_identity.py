"""Trajectories whose sha256 must not change when the model's code is reorganised (the layout,
the effect modules): short drops of each preset and of scenes that switch on every effect, and one
short episode per environment id and command mode with a fixed seed and fixed actions.

``python3 tests/bit_identity.py`` prints the hashes as JSON (``tests/data/bit_identity.json``
holds the ones recorded before the reorganisation; ``tests/test_layout.py`` asserts them). The
hashes hold for one machine, numba and LLVM build: on another, re-derive them from the parent
commit the same way before trusting a failure.
"""
from __future__ import annotations

import hashlib
import json
import sys

import numpy as np

#: name -> (preset, overrides, t_end)
DROPS = {
    "paper": ("paper", {}, 0.15),
    "spec": ("spec", {}, 0.15),
    "asymmetric": ("asymmetric", {}, 0.15),
    "everything": ("paper", {"effects.amb": "actuator", "effects.thermal": True,
                             "effects.stator_contact": True, "effects.semi_active_damper": True,
                             "sensor.delay": 1e-4}, 0.1),
    "no_mount_hertz": ("paper", {"effects.stator_contact": True, "effects.stator_mount": False,
                                 "contact.law": "hertz_line"}, 0.1),
    "massless_sleeve": ("paper", {"effects.sleeve_inertia": False, "effects.friction": "paper"},
                        0.1),
    "linear_rigid": ("spec", {"effects.retainer_bearing": "linear", "effects.housing": False}, 0.1),
    "rigid": ("paper", {"effects.retainer_bearing": "rigid", "effects.gyroscopic": False}, 0.1),
}

#: name -> (env id, kwargs, action)
EPISODES = {
    "passive": ("RotorDrop-Passive-v1", {}, [0.0]),
    "damping": ("RotorDrop-Damping-v1", {}, [0.3, -0.6]),
    "relevitate_discrete": ("RotorDrop-Relevitate-v1", {"command": "discrete"}, 1),
    "relevitate_continuous": ("RotorDrop-Relevitate-v1", {"command": "continuous"},
                              [0.2, 0.5, -0.1, 0.4]),
    "relevitate_supervisor": ("RotorDrop-Relevitate-v1", {"command": "supervisor"},
                              [1.0, 0.5, 0.3, -0.2, 0.1, 0.4]),
    "full_discrete": ("RotorDrop-Full-v1", {"command": "discrete", "full_state": True},
                      [0.2, -0.3, 1.0]),
    # the sensors sampling at the control rate: noise held per control step, as these hashes
    # were recorded (a sample rate above it splits the step at the sample instants)
    "full_supervisor": ("RotorDrop-Full-v1", {"command": "supervisor", "sensor_noise": 1e-6,
                                              "sensor_sample_rate": 1e3},
                        [0.2, -0.3, 1.0, -0.5, 0.3, -0.2, 0.1, 0.4]),
}


def sha(a) -> str:
    return hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()


def drop_hashes(name: str) -> list[str]:
    """sha256 of Y, the diagnostics and the energies of one short drop."""
    from physics.scene import load_scene
    from physics.simulate import simulate
    preset, overrides, t_end = DROPS[name]
    r = simulate(load_scene(preset, overrides), t_end=t_end)
    e = r.energy()
    return [sha(r.Y), sha(rigid_diagnostics(r.aux)), sha(np.array([e[k] for k in sorted(e)]))]


def rigid_diagnostics(aux: np.ndarray) -> np.ndarray:
    """The diagnostics the hashes were recorded with: every column but the flexible rotor's
    (appended later; a rigid rotor's are zero, which is asserted here)."""
    from physics.model import LAYOUT
    first = LAYOUT.aux["rotor.station_force"]
    last = LAYOUT.aux["rotor.damping_power"] + 1
    assert not np.any(aux[:, first:last]), "a rigid rotor's flexible diagnostics must be zero"
    return np.delete(aux, np.s_[first:last], axis=1)


def episode_hashes(name: str) -> list[str]:
    """sha256 of the observations, states, rewards and info numbers of one short episode."""
    import gymnasium as gym
    import rotordrop_env  # noqa: F401  (registers the ids)
    env_id, kwargs, action = EPISODES[name]
    env = gym.make(env_id, episode_time=0.08, **kwargs)
    obs, _ = env.reset(seed=5)
    a = action if isinstance(action, int) else np.asarray(action, np.float32)
    rows, states, rewards, infos = [obs], [], [], []
    for _ in range(200):
        obs, r, term, trunc, info = env.step(a)
        rows.append(obs)
        states.append(env.unwrapped._b.y.copy())
        rewards.append(r)
        infos.append([float(v) for k, v in sorted(info.items())
                      if isinstance(v, (int, float, bool, np.floating, np.integer))])
        if term or trunc:
            break
    env.close()
    return [sha(np.array(rows)), sha(np.array(states)), sha(np.array(rewards, np.float64)),
            sha(np.array(infos, np.float64))]


def all_hashes() -> dict:
    return {"drops": {n: drop_hashes(n) for n in DROPS},
            "episodes": {n: episode_hashes(n) for n in EPISODES}}


if __name__ == "__main__":
    json.dump(all_hashes(), sys.stdout, indent=1, sort_keys=True)
    print()
