"""Execution backends and the on-disk drop store (issue 14): every finished drop is kept, a
resumed batch runs only the missing drops and returns what an uninterrupted one returns, and
bad input (unknown backend, unreachable address, missing Ray, a store of another batch) is a
one-line error that changes nothing on disk. Ray itself is tested in tests/physics/runs/test_cluster.py."""
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from physics.runs.backend import Backend, BackendError, plan_threads, probe, run_drops
from physics.runs import UsageError
from agents.cli import main as cli_main
from physics.runs.store import DropStore
from physics.runs.sweep import Run

SHORT = {"solver.t_end": 0.14}                  # 40 ms after the fault: first impacts


def runs_of(frictions, **extra):
    return [Run.of("paper", {**SHORT, **extra, "contact.friction": mu}, friction=mu) for mu in frictions]


def without_timing(metrics: dict) -> dict:
    return {k: v for k, v in metrics.items() if k not in ("wall_time_s", "compile_time_s")}


def test_every_drop_is_on_disk_and_a_resumed_batch_runs_only_the_missing_ones(tmp_path):
    runs = runs_of([0.2, 0.3, 0.4])
    first, info = run_drops(runs, backend=Backend("local"), out=tmp_path, desc="t", progress=False)
    assert info.resumed == 0 and [o.ok for o in first] == [True] * 3
    done = tmp_path / "drops" / "done.jsonl"
    lines = done.read_text().splitlines()
    assert sorted(json.loads(l)["i"] for l in lines) == [0, 1, 2]
    # a driver killed while writing drop 1 (cut line) after drop 2; drop 0's record is marked
    # so that a re-run of drop 0 would show
    recs = {json.loads(l)["i"]: json.loads(l) for l in lines}
    recs[0]["metrics"]["steps"] = -1
    done.write_text(json.dumps(recs[0]) + "\n" + json.dumps(recs[2]) + "\n"
                    + json.dumps(recs[1])[:50])
    again, info = run_drops(runs, backend=Backend("local"), out=tmp_path, resume=True, desc="t",
                            progress=False)
    assert info.resumed == 2
    assert again[0].metrics["steps"] == -1                                  # kept, not re-run
    assert without_timing(again[1].metrics) == without_timing(first[1].metrics)    # re-run
    assert again[2].metrics == first[2].metrics                             # kept as stored
    assert all(line.startswith("{") and line.endswith("}")                  # cut line removed
               for line in done.read_text().splitlines())
    # the stored drops make the whole batch: nothing left to run, no session needed
    third, info = run_drops(runs, backend=Backend("ray", "127.0.0.9:6999"), out=tmp_path,
                            resume=True, desc="t", progress=False)
    assert info.resumed == 3 and third[1].metrics == again[1].metrics


def test_a_store_of_another_batch_is_refused_and_left_untouched(tmp_path):
    run_drops(runs_of([0.2]), out=tmp_path, desc="t", progress=False)
    done = tmp_path / "drops" / "done.jsonl"
    before = done.read_bytes(), (tmp_path / "drops" / "manifest.json").read_bytes()
    for other in (runs_of([0.25]), runs_of([0.2], **{"support.damping": 27900.0}), runs_of([0.2, 0.3])):
        with pytest.raises(UsageError, match="holds drops of another batch.*nothing was changed"):
            run_drops(other, out=tmp_path, resume=True, desc="t", progress=False)
    assert (done.read_bytes(), (tmp_path / "drops" / "manifest.json").read_bytes()) == before
    # a start that fails (unreachable cluster) does not clear the store either
    with pytest.raises(BackendError):
        run_drops(runs_of([0.3]), backend=Backend("ray", "127.0.0.9:6999"), out=tmp_path,
                  desc="t", progress=False)
    assert done.read_bytes() == before[0]


def test_the_node_that_ran_a_drop_is_on_disk_but_not_in_its_record(tmp_path):
    runs = runs_of([0.2, 0.3])
    store = DropStore.open(tmp_path, runs, None, "t")
    rec = dict(ok=True, metrics={"steps": 3}, extra={}, error=None)
    store.add(0, rec, node="127.0.0.3")
    store.add(1, rec)
    store.close()
    lines = [json.loads(l) for l in (tmp_path / "drops" / "done.jsonl").read_text().splitlines()]
    assert [l.get("node") for l in lines] == ["127.0.0.3", None]
    assert store.records() == [rec, rec]
    assert DropStore.open(tmp_path, runs, None, "t", resume=True).records() == [rec, rec]


def test_a_scene_file_that_changed_is_another_batch(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text('base = "paper"\n[contact]\nfriction = 0.2\n')
    runs = [Run.of(str(scene), SHORT)]
    store = DropStore.open(tmp_path, runs, None, "t")
    store.add(0, dict(ok=False, metrics={}, extra={}, error="x"))
    store.close()
    assert DropStore.open(tmp_path, runs, None, "t", resume=True).missing() == []
    scene.write_text('base = "paper"\n[contact]\nfriction = 0.3\n')
    with pytest.raises(UsageError, match="another batch"):
        DropStore.open(tmp_path, runs, None, "t", resume=True)


def test_bad_backend_input_is_a_one_line_error():
    with pytest.raises(UsageError, match="--backend must be one of local, ray, got 'dask'"):
        Backend("dask")
    with pytest.raises(UsageError, match="--address 10.0.0.1:6379 needs --backend ray"):
        Backend("local", "10.0.0.1:6379")
    with pytest.raises(UsageError, match="--jobs sets the threads of --backend local"):
        plan_threads(Backend("ray"), 2, 10)
    assert plan_threads(Backend("ray"), None, 10) == (None, "")
    with pytest.raises(BackendError, match="must be HOST:PORT"):
        probe("nowhere")
    with pytest.raises(BackendError, match="127.0.0.9:6999: no Ray cluster reachable there"):
        probe("127.0.0.9:6999")                  # at once, not after ray.init's minutes of retries


def test_backend_ray_without_ray_says_how_to_install_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)                  # import ray -> ImportError
    with pytest.raises(BackendError, match=r'needs Ray.*pip install -e "\.\[cluster\]"'):
        with Backend("ray").session():
            pass


def test_cli_errors_are_one_line_and_keep_the_finished_drops(tmp_path, capsys):
    args = ["study", "sweep", "--vary", "contact.friction=0.2,0.3", "--set", "solver.t_end=0.14",
            "--members", "1", "--quiet", "--no-plots", "--out", str(tmp_path)]
    assert cli_main(args) == 0
    done = (tmp_path / "drops" / "done.jsonl").read_bytes()
    capsys.readouterr()
    for extra, message in ((["--members", "2", "--resume"], "--resume"),
                           (["--backend", "ray", "--address", "127.0.0.9:6999"], "--address 127.0.0.9:6999"),
                           (["--address", "127.0.0.9:6999"], "needs --backend ray")):
        assert cli_main(args + extra) == 2
        err = capsys.readouterr().err
        assert err.startswith("rotordrop: error: ") and message in err and err.count("\n") == 1
        assert (tmp_path / "drops" / "done.jsonl").read_bytes() == done
    with pytest.raises(SystemExit):
        cli_main(args + ["--backend", "dask"])
    assert "invalid choice: 'dask'" in capsys.readouterr().err


def test_a_killed_driver_loses_no_finished_drop(tmp_path):
    """Kill `rotordrop study sweep` once drops are on disk; --resume completes the sweep with the
    same cells and per-drop metrics as an uninterrupted sweep."""
    args = ["study", "sweep", "--vary", "contact.friction=0.2:0.4:0.1", "--set", "solver.rtol=1e-7",
            "--members", "4", "--jobs", "1", "--quiet", "--no-plots"]     # ~0.1 s per drop: time to kill
    killed = tmp_path / "killed"
    env = dict(os.environ, PYTHONPATH=os.getcwd() + os.pathsep + os.environ.get("PYTHONPATH", ""))
    proc = subprocess.Popen([sys.executable, "-c", "import sys; from agents.cli import main; "
                             "sys.exit(main(sys.argv[1:]))", *args, "--out", str(killed)], env=env)
    done = killed / "drops" / "done.jsonl"
    deadline = time.monotonic() + 120
    while proc.poll() is None and time.monotonic() < deadline:
        if done.exists() and done.read_text().count("\n") >= 2:
            proc.send_signal(signal.SIGKILL)
            break
        time.sleep(0.01)
    proc.wait(timeout=30)
    kept = done.read_text().count("\n")
    assert 2 <= kept < 12, "the sweep was not interrupted mid-way"
    assert cli_main(args + ["--out", str(killed), "--resume"]) == 0
    assert cli_main(args + ["--out", str(tmp_path / "whole")]) == 0
    a, b = (json.loads((d / "sweep.json").read_text()) for d in (killed, tmp_path / "whole"))
    assert a["cells"] == b["cells"]
    assert [without_timing(r["metrics"]) for r in a["runs"]] == [without_timing(r["metrics"]) for r in b["runs"]]


def test_train_seeds_are_checked_before_anything_runs(tmp_path, capsys):
    from agents.training.seeds import parse_seeds
    assert parse_seeds("0,1, 2") == [0, 1, 2]
    for bad in ("", "a,b", "0,0", "-1"):
        with pytest.raises(ValueError, match="--seeds expects distinct integers >= 0"):
            parse_seeds(bad)
    base = ["train", "--env", "RotorDrop-Damping-v1", "--algo", "ppo", "--out", str(tmp_path / "t")]
    for extra, message in ((["--seeds", "1,1"], "--seeds expects"),
                           (["--seeds", "0,1", "--resume", str(tmp_path)], "--resume continues one run"),
                           (["--seeds", "0,1", "--backend", "ray", "--address", "127.0.0.9:6999"],
                            "no Ray cluster reachable"),
                           (["--seeds", "0,1", "--config", str(tmp_path / "none.yaml")], "does not exist")):
        assert cli_main(base + extra) == 2
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1, err
    assert not (tmp_path / "t").exists()
