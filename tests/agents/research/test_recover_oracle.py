"""The Recover oracle (agents.research.recover_oracle): its pool (each plan a designed law with
its constants, in its seat), its per-event best (recovered first, then the gentler), its
summary against the PID, and a tiny end-to-end run."""
import json

import numpy as np
import pytest

from agents.benchmarking.recover import ENV_ID, REFERENCE
from agents.control.controllers import SyncPhaseSearch, controller_env_kwargs
from agents.control.plant import plant_of
from agents.research import recover_oracle as ro


def test_the_pool_starts_with_the_pid_and_runs_each_plan_in_its_seat():
    sup, both = ro.plan_pool(["supervisor"]), ro.plan_pool(["supervisor", "controller"])
    assert sup[0].name == REFERENCE and both[:len(sup)] == sup
    assert len({p.name for p in both}) == len(both)              # names are unique
    assert {p.seat for p in sup} == {"supervisor"}
    assert {p.seat for p in both[len(sup):]} == {"controller"}
    held = next(p for p in sup if p.name == "held phase 90 A0.5")
    cls = held.controller()
    assert issubclass(cls, SyncPhaseSearch) and cls.name == "held phase 90 A0.5"
    assert cls.GAINS["phases"] == (90.0,) and cls.GAINS["amplitude"] == 0.5
    assert SyncPhaseSearch.GAINS["amplitude"] == 0.25             # the law itself is untouched
    assert controller_env_kwargs(cls, ENV_ID)["command"] == "supervisor"
    for seats in ([], ["pilot"], ["supervisor", "supervisor"]):
        with pytest.raises(ValueError, match="--seat"):
            ro.plan_pool(seats)


def _driver(law, plant):
    """drive(r, seconds): step ``law`` on an orbit held at r x clearance on both planes at
    10 000 rpm (continuing its episode); its last action."""
    obs = np.zeros((1, len(plant.obs_names)))
    obs[:, plant.index("rotor_speed")] = 10000 * np.pi / 30
    if "amb_power" in plant.obs_names:
        obs[:, plant.index("amb_power")] = 1.0

    def drive(r, seconds):
        for k in (1, 2):
            obs[:, plant.index(f"x{k}")] = r * plant.clearance
        for _ in range(int(round(seconds / plant.control_dt))):
            obs[:, plant.index("time")] = law.t[0] if law.n else 0.0
            a, _ = law.predict(obs / plant.obs_scale, episode_start=np.array([law.n == 0]))
        return a[0]
    return drive


def test_gain_on_contact_commands_its_gain_only_while_the_watch_holds_contact():
    plant = plant_of(ENV_ID, command="supervisor", episode_time=0.3)
    law = ro.Plan("g", "f", ro.GainOnContact, {"scale": -0.5}).controller()(plant)
    gain = plant.action_names.index("gain")
    drive = _driver(law, plant)
    assert drive(0.3, 0.02)[gain] == 0.0                          # free: the PID's own gains
    assert drive(0.95, 0.08)[gain] == pytest.approx(-0.5)         # persistent contact: held
    np.testing.assert_allclose(drive(0.95, 0.01)[-4:], 0.0)       # amplitude 0: no offset
    with pytest.raises(Exception, match="scale"):
        ro.Plan("g", "f", ro.GainOnContact, {"scale": 2.0}).controller()(plant)


def test_the_per_event_best_prefers_a_recovery_then_the_gentler_plan():
    cost = ro.event_cost(np.array([[False, True], [True, True]]),
                         np.array([[0.0, 9e4], [5e4, 1e3]]))
    assert cost[0, 0] == 1.0 and np.all(cost[1] < 0.5)
    assert list(np.argmin(cost, axis=0)) == [1, 1]
    pool = [ro.Plan(REFERENCE, "PID (reference)", ro.InnerLoop),
            ro.Plan("a", "fam", ro.InnerLoop, {"gain": 0.5}),
            ro.Plan("b", "fam", ro.InnerLoop, {"gain": -0.5})]
    rec = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]], bool)
    stuck = np.array([False, True, True, False])
    s = ro.summary(pool, rec, np.zeros((3, 4)), stuck)
    best = s["per-event best, all plans"]
    assert best["all events"]["recovered"]["value"] == 0.75
    assert best["all events"]["vs_reference"]["delta"] == 0.5
    assert best[ro.GROUPS[0]]["recovered"]["value"] == 1.0 and best[ro.GROUPS[0]]["events"] == 2
    assert s["per-event best: fam"]["all events"]["recovered"]["value"] == 0.5
    single = next(k for k in s if k.startswith("best single plan"))
    assert s[single]["all events"]["recovered"]["value"] == 0.25
    assert s[REFERENCE]["all events"]["vs_reference"]["delta"] == 0.0


def test_a_tiny_oracle_run_writes_its_report(tmp_path, monkeypatch):
    pool = [ro.Plan(REFERENCE, "PID (reference)", ro.InnerLoop),
            ro.Plan("held phase 180 A1", "offset of a fixed phase from detection",
                    SyncPhaseSearch, {"amplitude": 1.0, "phases": (180.0,)})]
    monkeypatch.setattr(ro, "plan_pool", lambda seats: pool)
    rec = ro.recover_oracle(tmp_path / "o", events=2, progress=False)
    assert rec["settings"]["seeds"] == [60_000, 60_001]
    stored = json.loads((tmp_path / "o" / "oracle_recover.json").read_text())
    assert stored["best_plan"] == rec["best_plan"] and len(stored["recovered"]) == 2
    s = stored["summary"]["per-event best, all plans"]["all events"]
    assert s["vs_reference"]["delta"] >= 0.0                      # the PID is in the pool
    lines = (tmp_path / "o" / "oracle_recover.csv").read_text().splitlines()
    assert len(lines) == 3 and (tmp_path / "o" / "oracle_recover.png").is_file()
    assert "per-event best, all plans" in ro.table(stored)
    with pytest.raises(ValueError, match="--events"):
        ro.recover_oracle(tmp_path / "x", events=0, progress=False)
    with pytest.raises(ValueError, match="--suite"):
        ro.recover_oracle(tmp_path / "x", suite="robust", progress=False)


def test_release_on_contact_switches_the_currents_off_then_lifts_again():
    plant = plant_of(ENV_ID, command="continuous", control_dt=2e-4, episode_time=0.3)
    plan = ro.Plan("r", "f", ro.ReleaseOnContact, {"off": 0.01})
    assert plan.seat == "controller"
    law = plan.controller()(plant)
    drive = _driver(law, plant)
    assert np.abs(drive(0.3, 0.01)).max() > 0                     # free: the own PID acts
    rev = 60.0 / 10000
    t_detect = -law.g["revolutions"] * np.log(1.0 - law.g["fraction"]) * rev
    drive(0.95, t_detect + 2e-3)                                  # persistent contact: released
    np.testing.assert_array_equal(drive(0.95, 4e-3), 0.0)
    t_off = law.t[0]
    after = drive(0.95, 0.01)                                     # off time over: lifting again
    assert np.abs(after).max() > 0
    assert t_off < law.on_t[0] < law.t[0]                         # its PID restarted, ramped
