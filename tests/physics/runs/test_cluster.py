"""A two-node Ray cluster on this machine (issue 14): head on 127.0.0.2, worker on 127.0.0.3, token
authentication on. A sweep runs across both nodes, the worker is killed mid-sweep, and the sweep
completes with the same cells and per-drop metrics as the local backend.

Marked ``cluster`` (needs the cluster extra; ``pytest -m cluster``). All traffic stays on
loopback addresses (Ray rewrites 127.0.0.1 into the machine's network address, so the nodes
get other loopback addresses). Every Ray process the test starts is ended by its process id.
"""
import json
import os
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from agents.cli import main as cli_main

pytestmark = pytest.mark.cluster

HEAD, WORKER = "127.0.0.2", "127.0.0.3"
ROOT = Path(__file__).resolve().parents[3]
# the done-when command
SWEEP = ["study", "sweep", "--vary", "contact.friction=0.3:0.5:0.1",
         "--vary", "support.damping=2790,27900", "--quiet", "--no-plots"]
TIMEOUT_S = 600


def free_port(host: str) -> int:
    with socket.socket() as s:
        s.bind((host, 0))
        return s.getsockname()[1]


def ray_processes(tag: str, node: str = "") -> list:
    """The processes of the cluster whose command line holds its temporary directory ``tag`` (and
    ``node``'s address), with their children (Ray's workers rename themselves ``ray::...``)."""
    import psutil
    found = {}
    for p in psutil.process_iter(["cmdline"]):
        cmd = " ".join(p.info["cmdline"] or ())
        if tag in cmd and node in cmd:
            try:
                for q in [p] + p.children(recursive=True):
                    found[q.pid] = q
            except psutil.Error:
                pass
    return list(found.values())


def end(procs) -> None:
    import psutil
    procs = list(procs)
    for p in procs:
        try:
            p.send_signal(signal.SIGKILL)
        except psutil.Error:
            pass
    psutil.wait_procs(procs, timeout=10)


@pytest.fixture
def cluster():
    """(address, env of a driver holding the token, temporary directory of the cluster)."""
    import ray  # noqa: F401  (the cluster extra must be installed: fail here if it is not;
    import psutil  # noqa: F401  it brings psutil, found once ray is imported)
    tmp = tempfile.mkdtemp(prefix="rd-ray-", dir="/tmp")     # short: Unix socket paths
    env = dict(os.environ, RAY_AUTH_MODE="token", RAY_AUTH_TOKEN=secrets.token_hex(16),
               RAY_USAGE_STATS_ENABLED="0", MPLBACKEND="Agg",
               PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    env.pop("RAY_ADDRESS", None)
    port = free_port(HEAD)
    ray_bin = [sys.executable, "-m", "ray.scripts.scripts"]
    common = ["--num-cpus", "1", "--disable-usage-stats"]
    try:
        subprocess.run(ray_bin + ["start", "--head", "--node-ip-address", HEAD, "--port", str(port),
                                  "--include-dashboard", "false", "--temp-dir", tmp,
                                  "--ray-client-server-port", str(free_port(HEAD))] + common,
                       env=env, check=True, capture_output=True, timeout=120)
        subprocess.run(ray_bin + ["start", "--address", f"{HEAD}:{port}", "--node-ip-address", WORKER]
                       + common, env=env, check=True, capture_output=True, timeout=120)
        yield f"{HEAD}:{port}", env, tmp
    finally:
        end(ray_processes(tmp))
        shutil.rmtree(tmp, ignore_errors=True)


def without_timing(metrics: dict) -> dict:
    return {k: v for k, v in metrics.items() if k not in ("wall_time_s", "compile_time_s")}


def test_a_sweep_across_two_nodes_survives_a_killed_worker(cluster, tmp_path):
    address, env, tmp = cluster
    # token authentication is on: a driver without the token is refused, in one line
    no_token = {k: v for k, v in env.items() if k not in ("RAY_AUTH_TOKEN", "RAY_AUTH_MODE")}
    bad = subprocess.run([sys.executable, "-m", "agents.cli"] + SWEEP + [
        "--backend", "ray", "--address", address, "--out", str(tmp_path / "refused")],
        env=no_token, capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert bad.returncode == 2 and not (tmp_path / "refused" / "sweep.json").exists()
    assert bad.stderr.startswith("rotordrop: error: ") and bad.stderr.count("\n") == 1, bad.stderr
    assert "RAY_AUTH_TOKEN" in bad.stderr

    out = tmp_path / "ray"
    driver = subprocess.Popen([sys.executable, "-c", "import sys; from agents.cli import main; "
                               "sys.exit(main(sys.argv[1:]))"] + SWEEP + [
        "--backend", "ray", "--address", address, "--out", str(out)],
        env=env, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    done = out / "drops" / "done.jsonl"
    deadline = time.monotonic() + TIMEOUT_S
    killed = []
    while driver.poll() is None and time.monotonic() < deadline:
        # kill the worker once it has finished a chunk and a third of the 48 drops are done (a
        # worker slow to start may finish nothing before the head has done a third)
        lines = done.read_text().splitlines() if done.exists() else []
        if len(lines) >= 16 and any(f'"node":"{WORKER}"' in line for line in lines):
            killed = ray_processes(tmp, f"node_ip_address={WORKER}")     # the worker's raylet
            end(killed)
            break
        time.sleep(0.2)
    try:
        stdout, stderr = driver.communicate(timeout=max(1.0, deadline - time.monotonic()))
    finally:
        driver.kill()
    assert killed, "the worker node was not killed mid-sweep"
    assert driver.returncode == 0, stderr[-2000:]

    ray_report = json.loads((out / "sweep.json").read_text())
    per_node = ray_report["backend"]["tasks_per_node"]
    print(f"killed {len(killed)} processes of the worker node; {ray_report['backend']}")
    assert per_node.get(WORKER, 0) >= 1 and per_node.get(HEAD, 0) >= 1, per_node
    assert sum(per_node.values()) >= ray_report["backend"]["tasks"]
    assert "ray:" in stdout

    assert cli_main(SWEEP + ["--backend", "local", "--out", str(tmp_path / "local")]) == 0
    local_report = json.loads((tmp_path / "local" / "sweep.json").read_text())
    assert len(ray_report["runs"]) == 48
    assert ray_report["cells"] == local_report["cells"]
    assert [without_timing(r["metrics"]) for r in ray_report["runs"]] == \
        [without_timing(r["metrics"]) for r in local_report["runs"]]
    assert [r["overrides"] for r in ray_report["runs"]] == [r["overrides"] for r in local_report["runs"]]


def test_one_node_ray_gives_the_local_numbers_of_the_paper_study_drops(tmp_path):
    """A Ray started for the run (no --address) and the local backend: identical outcomes,
    including the study's extra observables."""
    pytest.importorskip("ray")
    from physics.runs.backend import Backend, run_drops
    from physics.runs.study.observables import drop_observables
    from physics.runs.sweep import Run
    runs = [Run.of("paper", {"solver.t_end": 0.2, "contact.friction": mu}, friction=mu)
            for mu in (0.2, 0.3, 0.45, 3.0)]                               # the last one fails
    local, _ = run_drops(runs, drop_observables, Backend("local"), progress=False)
    remote, info = run_drops(runs, drop_observables, Backend("ray"), out=tmp_path, progress=False)
    assert info.backend["tasks"] >= 1 and info.backend["bytes_per_task"]["max"] < 10_000
    assert [o.ok for o in remote] == [True, True, True, False]
    assert remote[3].error == local[3].error and "contact.friction" in remote[3].error
    for a, b in zip(local, remote):
        assert without_timing(a.metrics) == without_timing(b.metrics) and a.extra == b.extra


def test_a_flexible_rotor_study_on_ray_gives_the_local_numbers(tmp_path, monkeypatch):
    """`study sweep --scene paper-flexible --backend ray` (a Ray started for the run): the
    elastic modes travel as the scene's name, the workers rebuild the reduced rotor, and the
    cells and per-drop metrics are the local backend's."""
    pytest.importorskip("ray")
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    # a wide AMB air gap keeps the whirling drops valid (the stator is not modelled: validity
    # would end where the whirl orbit reaches the 600 µm gap, and their forces be null)
    args = ["study", "sweep", "--scene", "paper-flexible", "--vary", "contact.friction=0.1,0.6",
            "--members", "2", "--set", "solver.t_end=0.15", "--set", "amb.air_gap=0.003",
            "--quiet", "--no-plots"]
    assert cli_main(args + ["--out", str(tmp_path / "local")]) == 0
    assert cli_main(args + ["--out", str(tmp_path / "ray"), "--backend", "ray"]) == 0
    a, b = (json.loads((tmp_path / d / "sweep.json").read_text()) for d in ("local", "ray"))
    assert b["backend"]["backend"] == "ray" and b["backend"]["tasks"] >= 1
    assert a["cells"] == b["cells"] and len(b["runs"]) == 4
    assert [without_timing(r["metrics"]) for r in a["runs"]] == \
        [without_timing(r["metrics"]) for r in b["runs"]]
    rest, whirl = b["cells"]                        # the high friction drives the rotor round
    assert whirl["peak_contact_force_N"]["min"] > 2.0 * rest["peak_contact_force_N"]["max"]


TINY = ("RotorDrop-Damping-v1:\n  n_steps: 64\n  batch_size: 64\n  n_epochs: 1\n  eval_freq: 0\n"
        "  checkpoint_freq: 0\n  env_kwargs:\n    episode_time: 0.02\n")


def test_seeds_trained_as_ray_tasks_equal_the_local_ones(tmp_path):
    """`train --seeds 0,1 --backend ray`: one task per seed, the same networks as local."""
    pytest.importorskip("ray")
    import torch
    from stable_baselines3 import PPO
    (tmp_path / "tiny.yaml").write_text(TINY)
    args = ["train", "--env", "RotorDrop-Damping-v1", "--algo", "ppo", "--timesteps", "128",
            "--n-envs", "1", "--config", str(tmp_path / "tiny.yaml"), "--seeds", "0,1", "--quiet"]
    assert cli_main(args + ["--out", str(tmp_path / "local")]) == 0
    assert cli_main(args + ["--out", str(tmp_path / "ray"), "--backend", "ray"]) == 0

    def weights(where, seed):
        return PPO.load(tmp_path / where / f"seed_{seed}" / "model.zip").policy.state_dict()
    for seed in (0, 1):
        a, b = weights("local", seed), weights("ray", seed)
        assert all(torch.equal(a[k], b[k]) for k in a)
    a, b = weights("local", 0), weights("local", 1)
    assert not all(torch.equal(a[k], b[k]) for k in a)               # the seeds differ


def test_ray_tune_finds_the_gains_of_the_local_search(tmp_path):
    """`tune --backend ray`: Ray Tune runs the candidates as trials; same history, same gains."""
    pytest.importorskip("ray")
    args = ["tune", "--policy", "whirl-brake", "--env", "RotorDrop-Relevitate-v1", "--gain",
            "kp=0.5:1.5", "--iterations", "2", "--population", "3", "--elite", "1", "--quiet",
            "--no-plots"]
    assert cli_main(args + ["--out", str(tmp_path / "local")]) == 0
    assert cli_main(args + ["--out", str(tmp_path / "ray"), "--backend", "ray"]) == 0
    a, b = (json.loads((tmp_path / d / "tune.json").read_text()) for d in ("local", "ray"))
    assert b["backend"] == "ray" and (tmp_path / "ray" / "ray_tune").is_dir()
    assert a["history"] == b["history"] and len(a["history"]) == 3
    assert a["gains"] == b["gains"] and a["validation_score"] == b["validation_score"]
    # the research gain search runs on Ray Tune the same way
    args = ["research", "tune-whirl-brake", "--iterations", "1", "--population", "2", "--elite", "1"]
    assert cli_main(args + ["--out", str(tmp_path / "wb-local")]) == 0
    assert cli_main(args + ["--out", str(tmp_path / "wb-ray"), "--backend", "ray"]) == 0
    a, b = (json.loads((tmp_path / d / "tune.json").read_text()) for d in ("wb-local", "wb-ray"))
    assert a["history"] == b["history"] and a["gains"] == b["gains"] and a["cost"] == b["cost"]


def test_benchmark_on_ray_gives_the_local_leaderboard(tmp_path):
    """`benchmark --backend ray`: threshold frictions and controllers as tasks (learned policies
    travel as their paths), the same rows and leaderboard."""
    pytest.importorskip("ray")
    args = ["benchmark", "--quick", "--scenarios", "1", "--episodes", "1", "--quiet", "--no-plots"]
    assert cli_main(args + ["--out", str(tmp_path / "local")]) == 0
    assert cli_main(args + ["--out", str(tmp_path / "ray"), "--backend", "ray"]) == 0
    a, b = (json.loads((tmp_path / d / "benchmark.json").read_text()) for d in ("local", "ray"))
    assert b["backend"]["backend"] == "ray" and b["backend"]["tasks"] > len(a["threshold_sweep"]["grid"])
    assert any(r["controller"].startswith("ppo-") for r in b["rows"])        # learned policies ran
    assert a["threshold_sweep"] == b["threshold_sweep"]
    assert a["rows"] == b["rows"] and a["leaderboard"] == b["leaderboard"]
