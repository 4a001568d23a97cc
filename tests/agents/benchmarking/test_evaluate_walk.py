"""The walk of an env id from ``rotordrop evaluate`` to ``gym.make``: every project function
entered from the command's handler until the first ``gym.make``, grouped into stays (consecutive
calls in one module). It comes back to a module it already left at most three times, for a
shipped policy, a policy file and a baseline."""
import sys

import pytest

from agents.cli import main
from agents.learning.policies import shipped_dir

PROJECT = ("agents", "rotordrop_env", "physics")


def walk(args: list[str]) -> list[str]:
    """The modules of the stays, in order, up to the first ``gym.make``."""
    calls, state = [], {"on": False, "done": False}

    def profile(frame, event, arg):
        if event != "call" or state["done"]:
            return
        module, name = frame.f_globals.get("__name__", ""), frame.f_code.co_name
        if name == "cmd_evaluate":
            state["on"] = True
        if not state["on"]:
            return
        if module == "gymnasium.envs.registration" and name == "make":
            state["done"] = True
            return
        if module.split(".")[0] not in PROJECT or not frame.f_code.co_flags & 1:    # functions
            return
        f = frame.f_back
        while f is not None and f.f_code.co_name != "cmd_evaluate":
            if f.f_code.co_name == "<module>":
                return                          # import time
            f = f.f_back
        calls.append(module)

    sys.setprofile(profile)
    try:
        assert main(args) == 0
    finally:
        sys.setprofile(None)
    assert state["done"], "gym.make was never called"
    return [m for i, m in enumerate(calls) if i == 0 or calls[i - 1] != m]


@pytest.mark.parametrize("policy", [["ppo-damping"], [str(shipped_dir() / "ppo-damping.zip")],
                                    ["max-damping", "--env", "RotorDrop-Damping-v1"]])
def test_evaluate_reaches_gym_make_returning_to_a_module_at_most_three_times(policy, tmp_path):
    stays = walk(["evaluate", "--policy", *policy, "--episodes", "1", "--no-plots",
                  "--out", str(tmp_path)])
    returns = [m for i, m in enumerate(stays) if m in stays[:i]]
    assert len(returns) <= 3, " -> ".join(stays)
