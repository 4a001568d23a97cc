"""A benchmark suite of one's own: high-friction drops of the Full task, registered in a
registry of its own and used to score two designed laws, each in its seat.

    python docs/examples/howto_suite.py

(docs/howto/benchmark-suite.md walks through it; the test suite runs it.)
"""
from __future__ import annotations

import numpy as np

from agents.benchmarking.benchmark import Scenario, Validator, controller_entry, round_up
from agents.benchmarking.suites import SUITES, DrawnSuite
from agents.control.controllers import BASELINES

ENV_ID = "RotorDrop-Full-v1"
POWER_GRID = 0.005          # the power return is rounded up to this grid [s]


# --8<-- [start:draw]
def draw(seed: int, name: str) -> Scenario:
    """One drop drawn from ``seed``: friction 0.45-0.6 (the passive drop whirls there), any
    unbalance phase, the power back 30-70 ms after the fault (on the suite's grid)."""
    rng = np.random.default_rng(seed)
    friction = float(rng.uniform(0.45, 0.6))
    phase = float(rng.uniform(0.0, 360.0))
    power = round_up(float(rng.uniform(0.03, 0.07)), POWER_GRID)
    return Scenario(name, friction, {"unbalance.angle_deg": phase}, tasks=("full",),
                    env_kwargs={"power_return_time": power}, seed=seed)
# --8<-- [end:draw]


# --8<-- [start:suite]
HIGH_FRICTION = DrawnSuite(
    "high-friction", "drops of the Full task at friction 0.45-0.6", ("benchmark", "tune"),
    seed=70_000, size=3, quick_size=2,                  # the test drops: seeds 70 000-70 002
    validation_seed=71_000, validation_size=2,          # never shared with the test drops
    power_grid=POWER_GRID, env_id=ENV_ID, draw=draw)
# --8<-- [end:suite]


# --8<-- [start:score]
def main(laws=("inner-loop", "whirl-brake"), drops: int = 2) -> dict[str, float]:
    """Register the suite in a copy of the project's registry (the project's stays as it is),
    look it up by name and score ``laws`` on its first ``drops`` test drops."""
    registry = SUITES.copy()
    registry.register(HIGH_FRICTION)
    suite = registry.get("high-friction")
    scorer = Validator(ENV_ID, suite.scenarios(drops), (0.0,))     # passive is the reference
    scores = {}
    for name in laws:
        entry = controller_entry(BASELINES[name], ENV_ID)            # in its seat
        scores[name] = scorer.score(entry.make, entry.env_kwargs)[0]
        print(f"{name} ({entry.seat} seat): score {scores[name]:.2f} on {drops} drops")
    return scores
# --8<-- [end:score]


if __name__ == "__main__":
    main()
