"""Round-2 review of the studies: refused --set keys of study paper, the drop checks carried into
the sweeps, early limits on --members / --seed / --jobs, TOML base chains and small CLI fixes."""
from __future__ import annotations

import json
import os

import pytest

from physics import SceneError, load_scene, simulate
from agents.cli import main as cli_main
from physics.runs import UsageError
from physics.metrics import compute_metrics
from physics.runs.study.ensemble import perturbations
from physics.runs.study.paper import StudyInput
from physics.runs.study.parametric import MAX_RUNS, make_axes, plan_runs
from physics.runs.sweep import Run, run_sweep

CPUS = len(os.sched_getaffinity(0))


def _sweep(tmp_path, capsys, *args):
    out = tmp_path / "sw"
    assert cli_main(["study", "sweep", *args, "--quiet", "--no-plots", "--out", str(out)]) == 0
    return json.loads((out / "sweep.json").read_text()), out, capsys.readouterr().out


# ----------------------------------------------------- 1. study paper: keys it sets itself --
@pytest.mark.parametrize("key, value", [("contact.friction", "0.3"), ("support.damping", "20000"),
                                        ("support.stiffness", "5e6"), ("unbalance.angle_deg", "0"),
                                        ("amb.off_time", "0.2"), ("effects.friction", "kinematic"),
                                        ("effects.bearing_friction", "false")])
def test_study_paper_refuses_set_on_the_keys_it_varies(tmp_path, capsys, key, value):
    out = tmp_path / "st"
    assert cli_main(["study", "paper", "--quick", "--set", f"{key}={value}", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"rotordrop: error: study paper sets {key} itself") and "\n" not in err
    assert not out.exists()                                         # refused before anything ran


def test_study_paper_keeps_other_overrides_and_labels_the_held_values():
    from physics.runs.study.paper import STUDY_KEYS
    assert set(STUDY_KEYS) >= {"contact.friction", "support.damping", "support.stiffness",
                               "effects.friction", "unbalance.angle_deg", "amb.off_time"}
    StudyInput("paper", {"bearing.f0": 2.0})                        # allowed
    with pytest.raises(SceneError, match="contact.friction, support.damping itself"):
        StudyInput("paper", {"contact.friction": 0.3, "support.damping": 2e4})
    from physics.runs.study.report import _held, _soft_case
    a = {"held": {"contact.friction": 0.3, "support.stiffness": 5e7, "support.damping": 2e4}}
    assert _soft_case(a) == "K_s = 5e6, μ = 0.3"
    assert (_held(a, "support.stiffness"), _held(a, "support.damping")) == ("5e7", "20000")


# ---------------------------------------------------------- 2. drop checks in the sweeps --
def test_a_run_that_ends_before_the_fault_is_a_failed_drop_not_a_calm_one(tmp_path, capsys):
    r, out, text = _sweep(tmp_path, capsys, "--vary", "solver.t_end=0.05", "--members", "2",
                          "--jobs", "1")
    cell, = r["cells"]
    assert cell["failed"] == 2 and cell["whirl_probability"] is None     # not "0.00, no whirl"
    assert cell["warnings"]["no_fault"] == 2 and r["warnings"]["no_fault"] == 2
    assert cell["errors"][0].startswith("NoFault: no fault in the simulated time")
    assert "amb.off_time" in cell["errors"][0]
    assert not any(run["ok"] for run in r["runs"])
    assert "| 0.05 | - | - | - | 2 | 0 | no_fault 2 |" in text
    assert "2 drops without a fault (counted as failed)" in text
    from physics.runs.study.checks import WARNING_KINDS
    head, row = (out / "sweep.csv").read_text().splitlines()
    assert head.endswith(",".join(f"warnings_{k}" for k in WARNING_KINDS))
    assert row.endswith(",2" + ",0" * (len(WARNING_KINDS) - 1))


def test_sweep_cells_count_the_warnings_rotordrop_drop_prints(tmp_path, capsys):
    """Soft support and a coarse output rate: contact before the fault, stator contact and the
    coarse rate, as `rotordrop drop` says for the same scene. The penetration stays within the
    paper law's bound (553 µm, the load of a steel line contact at b = 0.3 r), but the rotor
    reaches the AMB air gap, which ends validity there (no stator in the preset): the drop counts
    apart, and the step-resolved peaks of the whole run (which the missed-peaks check needs) are
    not computable."""
    r, out, text = _sweep(tmp_path, capsys, "--vary", "support.stiffness=3e5", "--members", "1",
                          "--set", "solver.output_rate=500", "--set", "solver.t_end=0.15",
                          "--jobs", "1")
    cell, = r["cells"]
    # left validity at the air gap before any whirl: undecided, out of the whirl probability
    assert cell["failed"] == 0 and cell["whirl_probability"] is None and cell["whirl_undecided"] == 1
    assert cell["warnings"] == dict(no_fault=0, pre_fault_contact=1, stator_contact=1,
                                    coarse_output=1, missed_peaks=0, aliased_whirl=0,
                                    penetration=0, film_play=0, dry_whip=0)
    run, = r["runs"]
    drop = compute_metrics(simulate(load_scene("paper", run["overrides"])))
    assert run["metrics"]["warnings"] == drop["warnings"] and len(drop["warnings"]) == 4
    assert drop["air_gap_beyond_validity"] == ["AMB1", "AMB2"] and cell["beyond_validity"] == 1
    assert not drop["penetration_beyond_validity"]
    assert "pre_fault_contact 1, stator_contact 1, coarse_output 1 |" in text
    assert "drop checks: 1 drop in contact before the fault, 1 drop reaching the AMB stator" in text
    assert (out / "sweep.csv").read_text().splitlines()[1].endswith(",0,1,1,1,0,0,0,0,0")


def test_as_drop_and_warning_counts():
    from physics.runs.study.checks import as_drop, warning_counts
    runs = [Run.of("paper", {"solver.t_end": 0.05}), Run.of("paper", {"solver.t_end": 0.12}),
            Run.of("paper", {"contact.friction": 2.0})]
    calm, dropped, bad = (as_drop(o) for o in run_sweep(runs, jobs=1, progress=False))
    assert not calm.ok and calm.error.startswith("NoFault") and calm.metrics    # metrics kept
    assert dropped.ok and dropped.error is None
    assert not bad.ok and "SceneError" in bad.error                          # untouched
    assert warning_counts([calm, dropped, bad])["no_fault"] == 1


# ------------------------------------------------------------- 3-5. --members, --seed, --jobs --
def test_too_many_members_fail_before_any_member_is_drawn(monkeypatch):
    axes = make_axes("paper", {}, ["contact.friction=0.1,0.2"])

    def drawn(*args, **kwargs):
        raise AssertionError("members drawn before the drop count was checked")
    monkeypatch.setattr("physics.runs.study.parametric.perturbations", drawn)
    with pytest.raises(SceneError, match=f"would simulate 2000000 drops; at most {MAX_RUNS}"):
        plan_runs("paper", {}, axes, 10 ** 6, 0)


def test_seeds_and_jobs_below_their_range_are_one_line_errors(tmp_path, capsys):
    for flag, value, words in (("--seed", "-1", "--seed: must be an integer >= 0, got '-1'"),
                               ("--jobs", "0", "--jobs: must be an integer >= 1, got '0'"),
                               ("--jobs", "-1", "--jobs: must be an integer >= 1, got '-1'"),
                               ("--members", "0", "--members: must be an integer >= 1")):
        with pytest.raises(SystemExit) as exc:
            cli_main(["study", "sweep", "--vary", "contact.friction=0.3", flag, value,
                      "--out", str(tmp_path / "x")])
        assert exc.value.code == 2 and words in capsys.readouterr().err
    with pytest.raises(SystemExit):
        cli_main(["study", "paper", "--jobs", "0", "--out", str(tmp_path / "x")])
    assert "--jobs: must be an integer >= 1" in capsys.readouterr().err
    with pytest.raises(ValueError, match="seed must be an integer >= 0, got -1"):
        perturbations(2, 0.1, seed=-1)


def test_jobs_are_capped_at_the_cpus_and_the_drops():
    from physics.runs.sweep import plan_jobs
    assert plan_jobs(None, 100) == (CPUS, "")
    assert plan_jobs(1, 100) == (1, "")
    used, note = plan_jobs(100, 3)
    assert used == min(CPUS, 3) and note.startswith("--jobs 100 capped at")
    assert plan_jobs(2, 1)[0] == 1
    for bad in (0, -1, 1.5, True):
        with pytest.raises(UsageError, match="--jobs must be an integer >= 1"):
            plan_jobs(bad, 10)
    with pytest.raises(UsageError):
        run_sweep([Run.of("paper")], jobs=0, progress=False)


def test_the_sweep_records_and_prints_the_jobs_it_used(tmp_path, capsys):
    r, _, text = _sweep(tmp_path, capsys, "--vary", "contact.friction=0.3", "--members", "1",
                        "--set", "solver.t_end=0.12", "--jobs", "100")
    assert r["jobs"] == 1 and "note: --jobs 100 capped at 1 thread(s)" in text


# ---------------------------------------------------------------------- 6. TOML base chains --
def test_a_base_chain_that_names_itself_is_a_one_line_error(tmp_path):
    (tmp_path / "g.toml").write_text('base = "g.toml"\n')
    (tmp_path / "x1.toml").write_text('base = "x2.toml"\n')
    (tmp_path / "x2.toml").write_text('base = "x1.toml"\n')
    with pytest.raises(SceneError, match=r"cycle: .*g.toml -> .*g.toml$"):
        load_scene(tmp_path / "g.toml")
    with pytest.raises(SceneError, match=r"cycle: .*x1.toml -> .*x2.toml -> .*x1.toml$"):
        load_scene(str(tmp_path / "x1.toml"))


def test_a_relative_base_is_read_from_the_naming_files_directory(tmp_path, monkeypatch):
    d = tmp_path / "scenes"
    d.mkdir()
    (d / "a.toml").write_text('base = "paper"\n[contact]\nfriction = 0.4\n')
    (d / "b.toml").write_text('base = "a.toml"\n[support]\nstiffness = 5e8\n')
    (tmp_path / "a.toml").write_text('base = "paper"\n[contact]\nfriction = 0.1\n')   # a decoy
    monkeypatch.chdir(tmp_path)
    s = load_scene("scenes/b.toml")
    assert (s.contact.friction, s.support.stiffness, s.name) == (0.4, 5e8, "b")
    (d / "c.toml").write_text('base = "missing.toml"\n')
    with pytest.raises(SceneError, match=r"base 'missing.toml' of .*c.toml is neither a preset"):
        load_scene("scenes/c.toml")
    (d / "n.toml").write_text("base = 5\n")
    with pytest.raises(SceneError, match="base = 5 must be a string"):
        load_scene("scenes/n.toml")


# ------------------------------------------------------------------------------- 7. minor --
def test_params_columns_do_not_run_into_each_other(capsys):
    assert cli_main(["params"]) == 0
    line = next(l for l in capsys.readouterr().out.splitlines()
                if l.startswith("effects.retainer_bearing"))
    assert "rigid|linear|sopanen_mikkola  P " in line


def test_result_state_names_the_states():
    r = simulate(load_scene("paper", {"solver.t_end": 0.01}))
    with pytest.raises(ValueError, match=r"state must be one of x, y, .*Omega.*; got 'nope'"):
        r.state("nope")


def test_friction_heat_never_prints_minus_zero():
    from physics.cli import summary_table
    m = compute_metrics(simulate(load_scene("paper", {"solver.t_end": 0.12})))
    for v in m["planes"].values():
        v["friction_heat_J"] = -0.3
    table = summary_table(m)
    assert " -0" not in table and table.count("                  0\n") >= 1
