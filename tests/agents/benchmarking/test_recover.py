"""The recovery laws (their contact watch, phase search and motion compensation on constructed
observations), the Recover suites (seeds apart) and the recovery benchmark's statistics."""
import json

import numpy as np
import pytest

from agents.benchmarking.recover import (DESIGNED, ENV_ID, paired_bootstrap, rate,
                                         recover_benchmark, recover_markdown)
from agents.benchmarking.suites import SUITES, RecoverSuite, SuiteRegistry
from agents.control.controllers import (BASELINES, PidRelevitate, SyncCurrentSearch,
                                        SyncMotionCompensation, SyncPhaseSearch,
                                        controller_env_kwargs, make_controller)
from agents.control.plant import plant_of
from agents.control.seats import seat_of


@pytest.fixture(scope="module")
def plant():
    return plant_of(ENV_ID, command="supervisor", episode_time=0.3)


def _obs(plant, r, angle=0.0, n=1):
    """n observations with the rotor at r x clearance (angle from +x) at both AMB planes,
    spinning at 10 000 rpm, time 0."""
    obs = np.zeros((n, len(plant.obs_names)))
    for k in (1, 2):
        obs[:, plant.index(f"x{k}")] = r * np.cos(angle) * plant.clearance
        obs[:, plant.index(f"y{k}")] = r * np.sin(angle) * plant.clearance
    obs[:, plant.index("rotor_speed")] = 10000 * np.pi / 30
    return obs / plant.obs_scale


def _drive(law, plant, r, seconds):
    """Step the law on a constant orbit radius r for ``seconds`` (continuing its episode); its
    last offsets."""
    obs = _obs(plant, r)
    for _ in range(int(round(seconds / plant.control_dt))):
        obs[:, plant.index("time")] = (law.t[0] if law.n else 0.0) / plant.obs_scale[
            plant.index("time")]
        action, _ = law.predict(obs, episode_start=np.array([law.n == 0]))
    return action[0, -4:]


def test_phase_search_waits_for_persistent_contact_cycles_phases_and_releases(plant):
    law = SyncPhaseSearch(plant)
    g = law.g
    rev = 60.0 / 10000
    assert np.all(_drive(law, plant, 0.5, 0.05) == 0.0)        # inside r_contact: nothing
    law = SyncPhaseSearch(plant)
    # in contact: detected when the watch's level, 1 - exp(-t / (revolutions rev)), passes
    # its fraction
    t_detect = -g["revolutions"] * np.log(1.0 - g["fraction"]) * rev
    assert np.all(_drive(law, plant, 0.95, t_detect - 0.2 * rev) == 0.0)
    off = _drive(law, plant, 0.95, 0.4 * rev)
    a = g["amplitude"]
    np.testing.assert_allclose(off, [-a, 0.0, -a, 0.0], atol=1e-6)    # φ = 180°: inward
    off = _drive(law, plant, 0.95, g["dwell"] * rev)          # dwell over: the next phase
    phi = np.radians(g["phases"][1])
    np.testing.assert_allclose(off, np.tile([a * np.cos(phi), a * np.sin(phi)], 2), atol=1e-6)
    # contact gone for the release time: the offset is removed
    assert np.all(_drive(law, plant, 0.3, (g["release"] + 1) * rev) == 0.0)


def test_motion_compensation_pulls_in_proportion_to_the_orbit(plant):
    law = SyncMotionCompensation(plant)
    off = _drive(law, plant, 0.9, 10 * 60.0 / 10000)
    np.testing.assert_allclose(off, [-law.g["gain"] * 0.9, 0.0] * 2, atol=1e-6)


def test_current_search_adds_a_turned_synchronous_current_on_contact():
    plant = plant_of(ENV_ID, command="continuous", control_dt=2e-4, episode_time=0.3)
    law = SyncCurrentSearch(plant)
    calm = SyncCurrentSearch(plant)
    rev = 60.0 / 10000
    base = _drive(calm, plant, 0.95, 0.1 * rev)[None]          # before any detection
    t = (-law.g["revolutions"] * np.log(1.0 - law.g["fraction"]) + 0.5) * rev
    cur = _drive(law, plant, 0.95, t)                          # detected: φ = 180°
    assert law.search.active[0] and law.search.k[0] == 0
    pid = PidRelevitate(plant)
    pid_cur = _drive(pid, plant, 0.95, t)
    # the PID part is pid-relevitate's; the extra current is −A x̂ on both planes (x̂ = +x)
    np.testing.assert_allclose(cur - pid_cur, [-law.g["amplitude"], 0.0] * 2, atol=1e-6)
    assert base.shape == (1, 4)


def test_the_recovery_laws_run_in_the_recover_task_only():
    plant = plant_of("RotorDrop-Full-v1", command="supervisor", episode_time=0.01)
    for cls in (SyncPhaseSearch, SyncMotionCompensation):
        assert not cls.supports(plant)
        with pytest.raises(ValueError, match="in RotorDrop-Recover-v1"):
            make_controller(cls, plant)


def test_every_designed_row_runs_in_its_seat():
    for name in DESIGNED:
        cls = BASELINES[name]
        kw = controller_env_kwargs(cls, ENV_ID)
        assert seat_of(cls).admits(kw), name
    assert controller_env_kwargs(BASELINES["sync-phase-search"], ENV_ID)["command"] == "supervisor"
    assert controller_env_kwargs(BASELINES["whirl-brake"], ENV_ID)["control_dt"] == 2e-4


def test_the_recover_suites_keep_test_and_validation_seeds_apart():
    seeds = []
    for name in ("recover", "recover-robust"):
        s = SUITES.get(name)
        assert s.env_id == ENV_ID and not set(s.test_seeds()) & set(s.validation_seeds())
        seeds += [set(s.test_seeds()), set(s.validation_seeds())]
    assert sum(len(x) for x in seeds) == len(set().union(*seeds))      # all four apart
    with pytest.raises(ValueError, match="overlap"):
        SuiteRegistry([RecoverSuite("bad", "overlapping", seed=10, size=5, validation_seed=12,
                                    validation_size=5)])


def test_rates_and_paired_bootstrap():
    r = rate(np.array([1, 1, 0, 0], float))
    assert r["value"] == 0.5 and r["se"] == pytest.approx(0.25)
    lo, hi = r["wilson95"]
    assert 0.0 < lo < 0.5 < hi < 1.0
    assert rate(np.ones(10))["wilson95"][1] == pytest.approx(1.0)
    rng = np.random.default_rng(0)
    x = rng.normal(size=50)
    same = paired_bootstrap(x, x, rng)
    assert same["delta"] == 0.0 and same["se"] == 0.0
    shifted = paired_bootstrap(x + 1.0, x, rng)
    assert shifted["delta"] == pytest.approx(1.0) and shifted["se"] == pytest.approx(0.0, abs=1e-12)


def test_the_benchmark_writes_its_report_and_table(tmp_path):
    suite = RecoverSuite("tiny", "three events", seed=60_000, size=3, quick_size=3,
                         validation_seed=61_000, validation_size=2, env_id=ENV_ID,
                         env_kwargs={"episode_time": 0.1})
    report = recover_benchmark(tmp_path, suite, policies=["sync-motion-comp"], progress=False)
    assert [r["controller"] for r in report["board"]].count("inner-loop") == 1   # the reference
    stored = json.loads((tmp_path / "benchmark.json").read_text())
    assert stored["seeds"] == [60_000, 60_002] and len(stored["events"]["inner-loop"]) == 3
    assert stored["calm"] == [True] * 3          # the paper machine levitates without its event
    ref = next(r for r in report["board"] if r["controller"] == "inner-loop")
    assert ref["vs_reference"]["recovered"] == {"delta": 0.0, "se": 0.0, "ci95": [0.0, 0.0]}
    for ev in stored["events"]["inner-loop"]:
        assert ev["recovered"] + ev["ended"] + ev["persistent"] == 1
    assert "`sync-motion-comp` | supervisor" in recover_markdown(report)


def test_results_store_a_recovery_leaderboard_and_generate_its_block(tmp_path):
    """`rotordrop results --recover FILE` stores the report in docs/data and tasks.md's
    recover block becomes its standing sentence and table, generated from the data."""
    from agents.benchmarking import results
    suite = RecoverSuite("recover", "two events", seed=60_000, size=2, quick_size=2,
                         validation_seed=61_000, validation_size=2, env_id=ENV_ID,
                         env_kwargs={"episode_time": 0.06})
    recover_benchmark(tmp_path / "run", suite, policies=["sync-phase-search"], progress=False)
    root = tmp_path / "root"
    (root / "docs" / "data").mkdir(parents=True)
    (root / "docs" / "tasks.md").write_text("# Tasks\n\n<!-- recover:recover:start -->\n"
                                            "<!-- recover:recover:end -->\n")
    stored = results.store(tmp_path / "run" / "benchmark.json",
                           root / "docs" / "data" / results.RECOVER_BOARDS["recover"])
    report = json.loads(stored.read_text())
    text = results.recover_blocks((root / "docs" / "tasks.md").read_text(), root)
    assert "test events 60000-60001 (2 events" in text
    assert results.recover_standing(report) in text and recover_markdown(report) in text
    ref = next(r for r in report["board"] if r["controller"] == "inner-loop")
    assert f"recovers {100 * ref['recovered']['value']:.1f} ± " in text


def test_a_learned_row_runs_through_its_interface_and_a_zero_residual_is_the_pid(tmp_path):
    """`--policy RUN` rows: a fresh residual policy on inner-loop with its action mean zeroed
    (zero_start) is the built-in PID, so on the same events it has the PID's outcomes exactly;
    its training distribution (randomize, episode_time) gives way to the suite's."""
    import gymnasium as gym
    from stable_baselines3 import PPO

    from agents.learning.exploration import zero_action_mean
    from agents.sb3_policy import export_self_contained
    env = gym.make(ENV_ID, command="supervisor")
    model = PPO("MlpPolicy", env, seed=0, device="cpu", n_steps=64, batch_size=64)
    zero_action_mean(model.policy)
    path = export_self_contained(model, None, tmp_path / "zero.zip", env_id=ENV_ID,
                                 env_kwargs={"command": "supervisor", "randomize": True,
                                             "episode_time": 0.5},
                                 residual="inner-loop", residual_scale=1.0)
    suite = RecoverSuite("tiny", "two events", seed=60_000, size=2, quick_size=2,
                         validation_seed=61_000, validation_size=2, env_id=ENV_ID,
                         env_kwargs={"episode_time": 0.06})
    report = recover_benchmark(tmp_path / "run", suite, policies=[str(path)],
                               names=["zero-residual"], progress=False)
    rows = report["events"]
    assert list(rows) == ["inner-loop", "zero-residual"]
    assert rows["zero-residual"] == rows["inner-loop"]
    assert rows["inner-loop"][0]["peak_contact_force_N"] > 0       # the event makes contact
    mine = next(r for r in report["board"] if r["controller"] == "zero-residual")
    assert mine["learned"] and mine["seat"] == "supervisor"
    assert mine["vs_reference"]["recovered"]["delta"] == 0.0
    with pytest.raises(ValueError, match="ppo-damping"):
        recover_benchmark(tmp_path / "bad", suite, policies=["ppo-damping"], progress=False)
