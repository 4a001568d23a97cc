"""``rotordrop dataset`` (Minari data sets) and ``rotordrop bc`` (behaviour cloning): the
stored episodes equal a replay of the same controller on the same seeds, the seeds and
scenarios are recorded, bad input is one line naming the parameter, and a cloned policy
fits its teacher and runs in the benchmark."""

import numpy as np
import pytest

minari = pytest.importorskip("minari")

from agents.cli import main
from agents.training.dataset import info_arrays, info_columns, write_dataset
from agents.benchmarking.rollout import merge_env_kwargs
from agents.learning.policies import actor_for
from agents.control.plant import Plant, make_env

FULL = "RotorDrop-Full-v1"
DAMPING = "RotorDrop-Damping-v1"


def _replay(policy, env_id, user_kwargs, seeds, randomize=True):
    """The episodes as evaluate would run them, written out here step by step (not through
    agents.training.dataset): [(observations, actions, rewards, terminated, truncated, infos)]."""
    make_actor, env_id, base, _, _ = actor_for(policy, env_id)
    env = make_env(env_id, **merge_env_kwargs(base, user_kwargs, randomize))
    plant = Plant.from_env(env)
    out = []
    for s in seeds:
        actor = make_actor(plant)
        obs, info = env.reset(seed=s)
        info = {**info, "scenario": dict(env.unwrapped.scenario)}    # the episode's machine
        o, a, r, te, tr, infos = [obs], [], [], [], [], [info]
        first = True
        while True:
            act, _ = actor.predict(obs[None, :], episode_start=np.array([first]), deterministic=True)
            first = False
            obs, rew, term, trunc, info = env.step(act[0])
            o.append(obs)
            a.append(np.asarray(act[0], dtype=env.action_space.dtype))
            r.append(rew)
            te.append(term)
            tr.append(trunc)
            infos.append(info)
            if term or trunc:
                break
        out.append((np.array(o), np.array(a), np.array(r), np.array(te), np.array(tr), infos))
    env.close()
    return out


def _check_round_trip(ds, expected, seeds):
    assert ds.total_episodes == len(seeds)
    assert ds.total_steps == sum(len(e[2]) for e in expected)
    metas = list(ds.storage.get_episode_metadata(range(ds.total_episodes)))
    assert [m["seed"] for m in metas] == seeds
    assert ds.storage.metadata["rotordrop"]["seeds"] == seeds
    for ep, meta, (obs, act, rew, term, trunc, infos) in zip(ds.iterate_episodes(), metas, expected):
        np.testing.assert_array_equal(ep.observations, obs)
        np.testing.assert_array_equal(ep.actions, act)
        np.testing.assert_array_equal(ep.rewards, rew)
        np.testing.assert_array_equal(ep.terminations, term)
        np.testing.assert_array_equal(ep.truncations, trunc)
        # infos: the reset row, then one per step, every key on every row (the KPIs so far)
        for key in ("time_s", "contact_force_N", "kpi_peak_contact_force_N"):
            np.testing.assert_array_equal(ep.infos[key], [i[key] for i in infos])
        assert meta["kpis"]["peak_contact_force_N"] == infos[-1]["kpi_peak_contact_force_N"]
        assert meta["scenario"] == pytest.approx(infos[0]["scenario"])
        assert meta["return"] == pytest.approx(float(np.sum(rew)))


def test_whirl_brake_on_full_round_trips_through_minari(tmp_path, monkeypatch):
    monkeypatch.setattr("agents.training.dataset.CHUNK", 2)          # written in two parts: 2 + 1
    seeds = [5, 6, 7]
    kw = {"episode_time": 0.06}
    r = write_dataset("whirl-brake", FULL, 3, tmp_path / "root", seed=5, env_kwargs=kw,
                      progress=False)
    assert r["dataset_id"] == "rotordrop/full/whirl-brake-v0"
    assert (tmp_path / "root" / r["dataset_id"] / "data").is_dir()
    monkeypatch.setenv("MINARI_DATASETS_PATH", str(tmp_path / "root"))
    ds = minari.load_dataset(r["dataset_id"])
    _check_round_trip(ds, _replay("whirl-brake", FULL, kw, seeds), seeds)
    # every episode drew its own scenario (randomize is on by default)
    frictions = [m["scenario"]["contact.friction"]
                 for m in ds.storage.get_episode_metadata(range(3))]
    assert len(set(frictions)) == 3
    # Minari rebuilds the environment with the kwargs the episodes ran with
    env = ds.recover_environment()
    assert env.spec.id == FULL and env.spec.kwargs["episode_time"] == 0.06
    assert env.spec.kwargs["command"] == "continuous"
    env.close()


def test_damping_controller_round_trips_with_fixed_scene(tmp_path):
    kw = {"episode_time": 0.05, "overrides": {"contact.friction": 0.45}}
    assert main(["dataset", "--policy", "whirl-switch", "--env", DAMPING, "--episodes", "2",
                 "--seed", "3", "--out", str(tmp_path), "--name", "damping/switch-v1", "--quiet",
                 "--env-kwarg", "episode_time=0.05", "--env-kwarg", "randomize=False",
                 "--env-kwarg", "overrides={'contact.friction': 0.45}"]) == 0
    from agents.training.dataset import load
    ds = load("damping/switch-v1", tmp_path)
    assert ds.storage.metadata["rotordrop"]["policy_name"] == "whirl-switch"
    _check_round_trip(ds, _replay("whirl-switch", DAMPING, kw, [3, 4], randomize=False), [3, 4])
    assert all(m["scenario"]["contact.friction"] == 0.45
               for m in ds.storage.get_episode_metadata(range(2)))
    # the data set's directory loads too, and an existing id is not overwritten silently
    assert load(tmp_path / "damping/switch-v1").total_episodes == 2
    assert main(["dataset", "--policy", "whirl-switch", "--env", DAMPING, "--episodes", "1",
                 "--out", str(tmp_path), "--name", "damping/switch-v1", "--quiet"]) == 2


def test_info_columns_keep_scalars_of_every_step_and_the_last_steps_kpis():
    reset = {"scenario": {"contact.friction": 0.3}, "time_s": 0.0}
    steps = [{"f": 1.0, "w": False, "n": 3, "only_first": 1.0, "nested": {"a": 1}},
             {"f": 2.0, "w": True, "n": 4, "nested": {"a": 2}, "kpi_x": np.float64(7.0),
              "kpi_t": None, "kpi_b": True}]
    cols = info_columns(reset, steps)
    assert cols == {"f": "float", "w": "bool", "n": "float", "kpi_x": "float", "kpi_t": "float",
                    "kpi_b": "float"}
    arr = info_arrays(cols, [reset, *steps])
    np.testing.assert_array_equal(arr["w"], [False, False, True])
    assert arr["w"].dtype == bool
    np.testing.assert_array_equal(arr["f"], [np.nan, 1.0, 2.0])
    np.testing.assert_array_equal(arr["kpi_x"], [np.nan, np.nan, 7.0])
    np.testing.assert_array_equal(arr["kpi_b"], [np.nan, np.nan, 1.0])
    assert np.isnan(arr["kpi_t"]).all()


@pytest.mark.parametrize("args, names", [
    (["--policy", "no-such-policy", "--env", FULL, "--episodes", "2"],
     ["--policy", "whirl-brake", "inner-loop-lift", "max-damping"]),
    (["--policy", "whirl-brake", "--env", "RotorDrop-Nope-v1", "--episodes", "2"],
     ["--env", FULL, DAMPING]),
    (["--policy", "whirl-brake", "--env", FULL, "--episodes", "0"], ["--episodes", ">= 1"]),
    (["--policy", "whirl-brake", "--env", FULL, "--episodes", "1", "--env-kwarg", "oops"],
     ["--env-kwarg", "KEY=VALUE"]),
])
def test_bad_input_is_one_line_naming_the_parameter(tmp_path, capsys, args, names):
    assert main(["dataset", *args, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("rotordrop dataset: error:")
    for n in names:
        assert n in err[0]
    assert not any(tmp_path.rglob("metadata.json"))


def test_bc_clones_the_teacher_and_runs_in_the_benchmark(tmp_path):
    from agents.benchmarking.benchmark import Entry, scenario_suite, suite_rows, extras
    from agents.training.dataset import load
    from agents.training.imitation import dataset_arrays, train_bc
    root = tmp_path / "root"
    r = write_dataset("whirl-brake", FULL, 6, root, env_kwargs={"episode_time": 0.06},
                      progress=False)
    rep = train_bc(r["dataset_id"], tmp_path / "bc", root=root, epochs=150, batch_size=64,
                   progress=False)
    assert rep["episodes"] == {"train": 5, "validation": 1}
    # the symmetric drop under a symmetric teacher: the two bearing planes never differ
    assert ["x1", "x2"] in rep["duplicate_observations"]
    assert ["vy1", "vy2"] in rep["duplicate_observations"]
    # the cloned policy as the benchmark loads it: its actions against the teacher's on the
    # training observations
    policies, _ = extras([str(tmp_path / "bc" / "model.zip")])
    pol = policies[0]
    assert pol.name == "bc-whirl-brake@bc" and pol.env_id == FULL
    ds = load(r["dataset_id"], root)
    train = [i for i, m in enumerate(ds.storage.get_episode_metadata(range(6)))
             if m["seed"] not in rep["validation_seeds"]]
    obs, act = dataset_arrays(ds, train)
    pred, _ = pol.predict(obs, deterministic=True)
    mse = np.mean(np.sum((pred - act) ** 2, axis=1))
    variance = np.sum(act.var(axis=0))
    assert mse < 0.2 * variance
    assert rep["train"]["mse"] == pytest.approx(mse, rel=1e-5)
    # an untrained network of the same shape is far off (the fit is the training's doing)
    rep0 = train_bc(r["dataset_id"], tmp_path / "bc0", root=root, epochs=1, lr=1e-9,
                    progress=False)
    assert rep0["train"]["mse_over_variance"] > 0.5
    # the benchmark machinery runs it on one scenario
    entry = Entry(pol.name, "full", pol.bound, dict(pol.env_kwargs))
    rows = suite_rows(entry, scenario_suite(0.3, quick=True)[:1], (0.0,))
    assert len(rows) == 1 and rows[0]["controller"] == "bc-whirl-brake@bc"
    assert np.isfinite(rows[0]["peak_contact_force_N"])


def test_bc_refuses_discrete_actions(tmp_path):
    from agents.training.imitation import train_bc
    r = write_dataset("builtin-relevitate", "RotorDrop-Relevitate-v1", 1, tmp_path,
                      env_kwargs={"episode_time": 0.06}, progress=False)
    with pytest.raises(ValueError, match="Box"):
        train_bc(r["dataset_id"], tmp_path / "bc", root=tmp_path, progress=False)


BLOCK_MINARI = """
import importlib.abc, sys
class NoMinari(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] == "minari":
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
sys.meta_path.insert(0, NoMinari())
from agents.cli import main
sys.exit(main(sys.argv[1:]))
"""


def test_dataset_without_minari_names_the_offline_extra(tmp_path):
    import subprocess
    import sys
    from pathlib import Path
    proc = subprocess.run([sys.executable, "-c", BLOCK_MINARI, "dataset", "--policy", "max-damping",
                           "--env", DAMPING, "--episodes", "1", "--out", str(tmp_path)],
                          cwd=Path(__file__).resolve().parents[3], capture_output=True, text=True)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "offline extra" in proc.stderr, proc.stderr


def test_duplicate_columns_names_pairs_equal_in_every_sample():
    from agents.training.imitation import duplicate_columns
    x = np.array([[1.0, 1.0, 5.0, 0.0, 2.0], [2.0, 2.0, 5.0, 0.0, 2.0], [3.0, 3.0, 5.0, 0.0, 3.0]])
    assert duplicate_columns(x, ["a", "b", "c", "d", "e"]) == [("a", "b")]   # constants do not count
    x[1, 1] += 1e-6
    assert duplicate_columns(x, ["a", "b", "c", "d", "e"]) == []


FAILING = """
from agents.control.controllers import Controller
import numpy as np

class Flaky(Controller):
    name = "flaky"
    needs = ("damping",)
    built = 0

    def __init__(self, plant):
        super().__init__(plant)
        type(self).built += 1

    def commands(self, obs):
        if type(self).built > 3:        # check_actor's, then episodes 0 and 1 are fine
            raise RuntimeError("broken in the third episode")
        return {"damping": np.ones((len(obs), 2))}
"""


def test_a_failure_midway_leaves_no_data_set(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr("agents.training.dataset.CHUNK", 1)          # episodes 0 and 1 are on disk then
    (tmp_path / "flaky.py").write_text(FAILING)
    spec = f"{tmp_path / 'flaky.py'}:Flaky"
    assert main(["dataset", "--policy", spec, "--env", DAMPING, "--episodes", "4", "--quiet",
                 "--env-kwarg", "episode_time=0.02", "--out", str(tmp_path / "root")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "flaky" in err[0] and "third episode" in err[0]
    assert not (tmp_path / "root" / "rotordrop" / "damping" / "flaky-v0").exists()


def test_a_shipped_policy_round_trips_on_its_own_environment(tmp_path):
    r = write_dataset("ppo-damping", None, 2, tmp_path, seed=11,
                      env_kwargs={"episode_time": 0.03}, progress=False)
    assert r["env_id"] == DAMPING and r["dataset_id"] == "rotordrop/damping/ppo-damping-v0"
    from agents.training.dataset import load, replay
    ds = load(r["dataset_id"], tmp_path)
    for i in range(2):
        again = replay(ds, i)
        ep = ds[i]
        assert again.seed == 11 + i
        np.testing.assert_array_equal(ep.observations, again.observations)
        np.testing.assert_array_equal(ep.actions, again.actions)
        np.testing.assert_array_equal(ep.rewards, again.rewards)


def test_bc_command_line(tmp_path, capsys):
    root = tmp_path / "root"
    write_dataset("whirl-switch", DAMPING, 2, root, env_kwargs={"episode_time": 0.03},
                  progress=False)
    assert main(["bc", "--dataset", "rotordrop/damping/whirl-switch-v0", "--root", str(root),
                 "--out", str(tmp_path / "bc"), "--epochs", "2", "--quiet"]) == 0
    assert "MSE / action variance" in capsys.readouterr().out
    from agents.learning.policies import LearnedPolicy
    pol = LearnedPolicy.load(tmp_path / "bc")                 # the directory loads too
    assert pol.name == "bc-whirl-switch" and pol.env_id == DAMPING and pol.self_contained
    for argv, name in ((["--dataset", "rotordrop/damping/nothing-v0", "--root", str(root)],
                        "--dataset"),
                       (["--dataset", "rotordrop/damping/whirl-switch-v0", "--root", str(root),
                         "--epochs", "0"], "--epochs"),
                       (["--dataset", "rotordrop/damping/whirl-switch-v0", "--root", str(root),
                         "--hidden", "64,x"], "--hidden")):
        assert main(["bc", *argv, "--out", str(tmp_path / "bc2")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("rotordrop bc: error:") and name in err[0]
    # a mistyped root is reported, not created
    assert main(["bc", "--dataset", "rotordrop/damping/whirl-switch-v0", "--root",
                 str(tmp_path / "nowhere"), "--out", str(tmp_path / "bc3")]) == 2
    assert "--dataset" in capsys.readouterr().err
    assert not (tmp_path / "nowhere").exists() and not (tmp_path / "bc3").exists()
