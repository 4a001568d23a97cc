"""The paper study (issue 3, part 1): onset statistics, the process-pool sweep, and the quick
study end to end with physically sensible relations between its numbers."""
import json
import math
import re
import shlex

import numpy as np
import pytest

from physics import load_scene
from agents.cli import main as cli_main
from physics.runs.study.ensemble import JITTER_S, logistic_fit, onset, perturbations, probability_curve
from physics.runs.study.paper import DAMPING
from physics.runs.study.checks import WARNING_KINDS
from physics.runs.study.parametric import PLANE_KPIS
from physics.runs.sweep import Run, reproduce_command, run_sweep


# ----------------------------------------------------------------------- onset statistics --
def test_onset_of_a_sharp_threshold_is_interpolated_between_grid_points():
    mu = np.round(np.arange(0.10, 0.61, 0.05), 2)
    p = (mu >= 0.40).astype(float)
    o = onset(mu, p)
    assert o.threshold == pytest.approx(0.375)
    assert o.lowest_whirl == 0.40 and o.certain_from == 0.40 and o.crossings == 1


def test_interleaved_onset_names_no_threshold_but_the_certain_whirl():
    """Whirl at 0.2 more often than at 0.3: the probability falls, so no 50 % threshold is named
    (it would depend on where the grid falls); the lowest whirl and the certain whirl stand."""
    o = onset([0.1, 0.2, 0.3, 0.4, 0.5], [0.0, 0.75, 0.25, 1.0, 1.0])
    assert o.threshold is None and not o.monotone
    assert o.lowest_whirl == 0.2 and o.certain_from == 0.4 and o.crossings == 3
    rising = onset([0.1, 0.2, 0.3, 0.4, 0.5], [0.0, 0.25, 0.75, 1.0, 1.0])
    assert rising.monotone and rising.threshold == pytest.approx(0.2 + 0.1 * 0.25 / 0.5)


def test_no_whirl_anywhere_gives_no_threshold():
    o = onset([0.1, 0.2, 0.3], [0.0, 0.0, 0.0], [0.1, 0.2, 0.3], [False] * 3)
    assert o.threshold is None and o.lowest_whirl is None and o.certain_from is None
    assert o.logistic_mu50 is None


def test_logistic_fit_recovers_a_known_threshold_and_width():
    rng = np.random.default_rng(0)
    x = rng.uniform(0.1, 0.6, 4000)
    y = rng.uniform(size=x.size) < 1.0 / (1.0 + np.exp(-(x - 0.33) / 0.02))
    mu50, s = logistic_fit(x, y)
    assert mu50 == pytest.approx(0.33, abs=0.005)
    assert s == pytest.approx(0.02, rel=0.2)
    assert logistic_fit([0.1, 0.2, 0.3, 0.4], [0, 0, 1, 1]) == (pytest.approx(0.25), 0.0)
    assert logistic_fit([0.1, 0.2], [1, 1]) is None


def test_probability_curve_groups_runs_by_value():
    curve = probability_curve([0.2, 0.1, 0.2, 0.2], [True, False, False, True])
    assert [(c["value"], c["runs"], c["whirls"]) for c in curve] == [(0.1, 1, 0), (0.2, 3, 2)]
    assert curve[1]["probability"] == pytest.approx(2 / 3)


def test_ensemble_members_cover_the_circle_and_the_jitter_window():
    m = perturbations(16, 0.1, seed=3)
    angles = sorted(x["unbalance.angle_deg"] for x in m)
    assert [int(a // 22.5) for a in angles] == list(range(16))            # one per sector
    times = sorted(x["amb.off_time"] for x in m)
    slots = [int((t - (0.1 - JITTER_S)) / (2 * JITTER_S / 16)) for t in times]
    assert slots == list(range(16))                                        # one per time slot
    assert perturbations(16, 0.1, seed=3) == m                             # reproducible
    assert perturbations(16, 0.1, seed=4) != m
    for member in m:                                                       # ordinary overrides
        load_scene("paper", member)


# ------------------------------------------------------------------------------- sweeps --
def test_sweep_keeps_order_reports_failures_and_runs_are_reproducible(tmp_path):
    runs = [Run.of("paper", {"contact.friction": 0.1, "solver.t_end": 0.13}, k=0),
            Run.of("paper", {"contact.friction": 1.5}, k=1),                 # out of range
            Run.of("paper", {"solver.max_steps": 100, "solver.t_end": 0.2}, k=2),
            Run.of("paper", {"contact.friction": 0.5, "solver.t_end": 0.13}, k=3)]
    out = run_sweep(runs, jobs=2, progress=False)
    assert [o.run.label["k"] for o in out] == [0, 1, 2, 3]
    assert [o.ok for o in out] == [True, False, False, True]
    assert "SceneError" in out[1].error and "contact.friction" in out[1].error
    assert "IntegrationError" in out[2].error and "solver.max_steps" in out[2].error
    # two threads give exactly what one thread gives
    serial = run_sweep(runs[:1], jobs=1, progress=False)[0]
    assert serial.metrics["planes"] == out[0].metrics["planes"]
    # and the printed command reproduces the run
    argv = shlex.split(reproduce_command(runs[0]))
    assert argv[:2] == ["rotordrop", "drop"]
    assert cli_main(argv[1:] + ["--out", str(tmp_path), "--no-plots", "--quiet"]) == 0
    assert json.loads((tmp_path / "metrics.json").read_text())["planes"] == out[0].metrics["planes"]


# ------------------------------------------------------------------ quick study, end to end --
def test_quick_paper_study_end_to_end(tmp_path):
    """One quick study (run once: under xdist a module fixture would run once per worker)."""
    # the paper's model has no stator: its whirls reach the preset's 600 µm AMB air gap, which
    # ends their validity before most are decided; a wide gap keeps the paper's claims testable
    assert cli_main(["study", "paper", "--quick", "--set", "amb.air_gap=0.003", "--jobs", "2",
                     "--quiet", "--out", str(tmp_path)]) == 0
    a = json.loads((tmp_path / "study.json").read_text())
    _check_required_fields(a)
    _check_physics(a)
    _check_report(tmp_path, a)


def _check_required_fields(a):
    assert set(a["friction_threshold"]) == {"paper", "kinematic"}
    for key in ("whirl_probability", "support_stiffness", "support_damping", "claims"):
        assert a[key], key
    for r in a["whirl_probability"]:
        assert {"friction", "slip", "probability", "runs"} <= r.keys()
        assert r["slip"] in ("paper", "kinematic") and 0.0 <= r["probability"] <= 1.0
        assert r["runs"] + r["undecided"] == a["plan"]["members"] and r["failed"] == 0
    for r in a["support_stiffness"]:
        assert {"stiffness", "max_displacement_um", "peak_contact_force_N"} <= r.keys()
    assert {r["damping"] for r in a["support_damping"]} == set(DAMPING)
    for c in a["claims"]:
        assert {"claim", "ours", "reproduced"} <= c.keys() and isinstance(c["reproduced"], bool)
    assert a["runs"]["failed"] == 0 and not a["failures"]
    assert a["held"] == {"contact.friction": 0.25, "support.stiffness": 5e7, "support.damping": 5000.0}
    assert a["warnings"]["total"]["no_fault"] == 0 and set(a["warnings"]) >= {"total", "friction"}


def _check_physics(a):
    # no whirl at the lowest friction, certain whirl at the highest (paper §V-A), both slip laws
    for slip in ("paper", "kinematic"):
        for drag in (True, False):
            rows = sorted((r for r in a["whirl_probability"] if r["slip"] == slip
                           and r["bearing_friction"] == drag), key=lambda r: r["friction"])
            assert rows[0]["probability"] == 0.0 and rows[-1]["probability"] == 1.0
        th = a["friction_threshold"][slip]      # named only where the curve is monotone
        assert th is None or rows[0]["friction"] < th < rows[-1]["friction"]
        assert (th is None) == (not a["friction_onset"][f"{slip}, drag on"]["monotone"])
    # a stiffer support takes the impact with a larger force and a smaller excursion (§V-B)
    k = {r["stiffness"]: r for r in a["support_stiffness"]}
    assert k[5e6]["peak_contact_force_N"] < k[5e7]["peak_contact_force_N"] < k[5e8]["peak_contact_force_N"]
    assert k[5e6]["max_y_displacement_um"] > k[5e7]["max_y_displacement_um"]
    # the soft support's drop excursion is bounded by the undamped energy estimate (spec §7: 697 µm)
    assert 300.0 < k[5e6]["max_y_displacement_um"] < 1.1 * 697.0
    # every orbit leaves the static clearance circle (elastic support and bearing compression)
    c_um = load_scene(a["scene"]).contact.clearance * 1e6
    assert all(r["max_displacement_um"] > c_um for r in a["support_stiffness"])
    # more support damping: less rattling of the rotor in its sleeves (§V-B)
    d = {r["damping"]: r["ensemble"]["radial_speed_rms_mm_s"]["median"] for r in a["support_damping"]}
    assert d[max(DAMPING)] < d[min(DAMPING)]


def _check_report(out, a):
    text = (out / "report.md").read_text()
    figures = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    assert len(figures) >= 10
    for f in figures:
        assert (out / f).is_file() and (out / f).stat().st_size > 5000, f
    for c in a["claims"]:
        assert c["claim"] in text
    assert "## 2. Support stiffness (μ = 0.25, C_s = 5000 N s/m)" in text
    assert "## 3. Support damping (μ = 0.25, K_s = 5e7 N/m)" in text
    assert "\nDrop checks: " in text or "no drop flagged" in text
    assert a["reproduce"] and all(r["command"].startswith("rotordrop drop --scene")
                                  for r in a["reproduce"])
    assert all(r["command"] in text for r in a["reproduce"])
    assert math.isfinite(a["wall_time_s"])


def test_parametric_sweep_sees_the_whirl_and_its_forces(tmp_path, capsys):
    """At mu = 0.1 the rotor rests, at mu = 0.6 it whirls in every member with contact forces
    far above resting (spec §7: about twice, here more at the peak)."""
    out = tmp_path / "sw"
    # the whirl reaches the preset's 600 µm AMB air gap, which would end validity (no stator in
    # the model; its whirl then undecided): a wide gap keeps the whirl valid
    assert cli_main(["study", "sweep", "--vary", "contact.friction=0.1,0.6", "--members", "2",
                     "--set", "amb.air_gap=0.003",
                     "--jobs", "1", "--quiet", "--out", str(out)]) == 0
    r = json.loads((out / "sweep.json").read_text())
    rest, whirl = r["cells"]
    assert (rest["contact.friction"], whirl["contact.friction"]) == (0.1, 0.6)
    assert rest["whirl_probability"] == 0.0 and whirl["whirl_probability"] == 1.0
    assert whirl["peak_contact_force_N"]["min"] > 2.0 * rest["peak_contact_force_N"]["max"]
    assert whirl["whirl_revolutions"]["min"] >= 3.0 > rest["whirl_revolutions"]["max"]
    assert len(r["runs"]) == 4 and all(run["ok"] for run in r["runs"])
    # members differ by the ensemble keys only, and each run says how to repeat it
    angles = {run["overrides"]["unbalance.angle_deg"] for run in r["runs"]}
    assert len(angles) == 2
    assert all("--set contact.friction=" in run["command"] for run in r["runs"])
    assert len((out / "sweep.csv").read_text().splitlines()) == 3
    assert (out / "sweep.png").is_file()
    assert "| 0.6 | 1.00 |" in capsys.readouterr().out


def test_parametric_sweep_grid_values_and_errors():
    from physics.scene import SceneError
    from physics.runs.study.parametric import ensemble_keys, make_axes, parse_vary, plan_runs
    assert parse_vary("contact.friction=0.3:0.5:0.1") == ("contact.friction", ["0.3", "0.4", "0.5"])
    # ranges step in decimals: tiny values keep their scale, a range through zero hits 0 exactly
    assert make_axes("paper", {}, ["solver.min_step=1e-14:3e-14:1e-14"])[0].values == (1e-14, 2e-14, 3e-14)
    assert make_axes("paper", {}, ["positions.rb1=-0.1:0.1:0.1"])[0].values == (-0.1, 0.0, 0.1)
    assert make_axes("paper", {}, ["bearing.balls=8:12:2"])[0].values == (8, 10, 12)
    axes = make_axes("paper", {}, ["support.damping=2790,1e5", "effects.friction=paper,kinematic"])
    assert axes[0].values == (2790.0, 1e5) and axes[1].values == ("paper", "kinematic")
    assert len(plan_runs("paper", {}, axes, 3, 0)) == 2 * 2 * 3
    for bad, words in ((["contact.friction=0.2,1.5"], r"contact.friction = 1.5 .*\[0, 1\]"),
                       (["contact.nope=1"], "unknown parameter key"),
                       (["contact.friction=0.5:0.1:0.1"], "contact.friction: .*LO <= HI"),
                       (["contact.friction=0:1:inf"], "contact.friction: .*STEP > 0"),
                       (["contact.friction=0:1:1e-320"], "contact.friction: more than 1000 values"),
                       (["contact.friction=0:1:0.0001"], "contact.friction: more than 1000 values"),
                       (["contact.friction=,"], "contact.friction: no values"),
                       (["bearing.balls=8:9:0.5"], r"bearing.balls = '8.5' .*\[3, 100\]"),
                       (["contact.friction=0.2", "contact.friction=0.3"], "contact.friction is given twice"),
                       (["a.b=1", "c.d=2", "e.f=3", "g.h=4"], "1 to 3 keys")):
        with pytest.raises(SceneError, match=words):
            make_axes("paper", {}, bad)
    with pytest.raises(SceneError, match="both varied"):
        make_axes("paper", {"contact.friction": 0.2}, ["contact.friction=0.3"])
    # an ensemble key fixed by --set or --vary is neither perturbed nor reported as perturbed
    fixed = {"amb.off_time": 0.12}
    angle = make_axes("paper", fixed, ["unbalance.angle_deg=0,90"])
    assert ensemble_keys(fixed, angle) == [] and ensemble_keys(fixed, axes) == ["unbalance.angle_deg"]
    runs = plan_runs("paper", fixed, angle, 3, 0)
    assert [r.settings for r in runs] == [{"amb.off_time": 0.12, "unbalance.angle_deg": a}
                                          for a in (0.0, 90.0)]


def test_parametric_sweep_reports_failed_drops(tmp_path):
    """A step budget too small to finish: every drop fails, and the cells, the CSV and the plot
    say so."""
    out = tmp_path / "sw"
    assert cli_main(["study", "sweep", "--vary", "contact.friction=0.2", "--members", "2",
                     "--set", "solver.max_steps=100", "--jobs", "1", "--quiet",
                     "--out", str(out)]) == 0
    r = json.loads((out / "sweep.json").read_text())
    cell, = r["cells"]
    assert cell["failed"] == 2 and cell["whirl_probability"] is None
    assert cell["peak_contact_force_N"] is None
    assert "solver.max_steps" in cell["errors"][0]
    assert len(r["runs"]) == 2 and not any(run["ok"] for run in r["runs"])
    assert all("--set solver.max_steps=100" in run["command"] for run in r["runs"])
    assert (out / "sweep.csv").read_text().splitlines()[1] == ("0.2,2,2,0" + "," * (1 + 3 * len(PLANE_KPIS))
                                                           + ",0" * len(WARNING_KINDS))  # no metrics
    assert (out / "sweep.png").is_file()


def test_parametric_sweep_over_three_keys_maps_the_first_two_per_value_of_the_third(tmp_path):
    """The classic retainer design map: a soft support (K_s = 5e6) keeps the rotor out of
    whirl at mu = 0.45 where the paper's 5e7 whirls (paper §V-B trend)."""
    out = tmp_path / "sw3"
    assert cli_main(["study", "sweep", "--vary", "support.stiffness=5e6,5e7",
                     "--vary", "support.damping=5000", "--vary", "contact.friction=0.1,0.45",
                     "--set", "amb.air_gap=0.003",       # the whirl valid (see above)
                     "--members", "2", "--jobs", "1", "--quiet", "--out", str(out)]) == 0
    r = json.loads((out / "sweep.json").read_text())
    assert len(r["cells"]) == 4 and list(r["axes"]) == ["support.stiffness", "support.damping",
                                                        "contact.friction"]
    cell = {(c["support.stiffness"], c["contact.friction"]): c["whirl_probability"] for c in r["cells"]}
    assert cell[(5e6, 0.45)] == 0.0 and cell[(5e7, 0.45)] == 1.0
    assert cell[(5e6, 0.1)] == cell[(5e7, 0.1)] == 0.0
    assert (out / "sweep_1.png").is_file() and (out / "sweep_2.png").is_file()
    assert not (out / "sweep.png").exists()


def test_a_sweep_over_a_flexible_rotor_sees_its_softer_impact(tmp_path):
    """`study sweep --scene paper-flexible`: the same decisions as the rigid paper rotor (rest at
    mu = 0.1, whirl at mu = 0.6) and a softer first impact (the shaft's compliance in series
    with the contact: a lower peak contact force in the resting cell); each run names its scene."""
    args = ["study", "sweep", "--vary", "contact.friction=0.1,0.6", "--members", "2",
            "--set", "solver.t_end=0.3", "--set", "amb.air_gap=0.003",  # the whirl valid (above)
            "--jobs", "2", "--quiet", "--no-plots"]
    for scene in ("paper", "paper-flexible"):
        assert cli_main(args + ["--scene", scene, "--out", str(tmp_path / scene)]) == 0
    rigid, flex = (json.loads((tmp_path / s / "sweep.json").read_text())
                   for s in ("paper", "paper-flexible"))
    rest, whirl = flex["cells"]
    assert rest["whirl_probability"] == 0.0 and whirl["whirl_probability"] == 1.0
    assert all(run["ok"] and "--scene paper-flexible" in run["command"] for run in flex["runs"])
    soft, stiff = rest["peak_contact_force_N"]["max"], rigid["cells"][0]["peak_contact_force_N"]["min"]
    assert 0.8 * stiff < soft < 0.95 * stiff


def test_a_claim_whose_drops_all_left_validity_is_not_computable_not_a_crash():
    """Settling medians of drops that left validity before settling are None: the claim then
    says which quantity is missing (ValueError, reported as 'not computable'), and the same
    regime is still preferred where both ensembles have a value."""
    from physics.runs.study.claims import _same_regime

    def ensemble(p, whirl, no_whirl, overall):
        return {"whirl_probability": p, "force_settling_s": {"median": overall},
                "whirl": {"members": 1, "force_settling_s": {"median": whirl}},
                "no_whirl": {"members": 1, "force_settling_s": {"median": no_whirl}}}

    a, b, note = _same_regime(ensemble(0.5, 0.2, None, 0.3), ensemble(None, 0.4, None, 0.5),
                              "force_settling_s")
    assert (a, b) == (0.2, 0.4) and note.startswith("whirling drops")
    with pytest.raises(ValueError, match="no force_settling_s in both ensembles"):
        _same_regime(ensemble(None, None, None, None), ensemble(0.1, None, None, None),
                     "force_settling_s")
    empty = ensemble(0.0, None, None, None)
    empty["force_settling_s"] = {}                  # no drop measured at all: no statistics
    with pytest.raises(ValueError, match="no force_settling_s in both ensembles"):
        _same_regime(empty, ensemble(0.1, None, None, None), "force_settling_s")


def test_a_claim_that_cannot_be_computed_still_names_the_paper_statement_and_criterion():
    """An analysis without data (every section empty) gives 14 rows, none reproduced, each with
    the paper's statement, value and criterion, and 'ours' saying why it is not computable."""
    from physics.runs.study.claims import claims

    rows = claims({"friction_onset": {}, "friction_observables": {}, "support_stiffness": [],
                   "support_damping": []}, 300.0)
    assert len(rows) == 14 and not any(r["reproduced"] for r in rows)
    for r in rows:
        assert r["claim"][0] not in "(" and r["paper"] != "-" and r["criterion"] != "-"
        assert r["ours"].startswith("not computable from this run")
    assert rows[3]["paper"] == "orbit beyond the 300 µm circle"
    assert rows[0]["criterion"] == "|threshold − 0.39| ≤ 0.03"


def test_the_report_names_friction_values_whose_drops_all_left_validity_before_the_verdict():
    """A μ whose drops all reached a validity bound before their whirl verdict has no probability
    but is not dropped: the report counts the undecided drops and says from which μ none is
    decided."""
    from physics.runs.study.report import _undecided_note

    def row(mu, p, runs, undecided, slip="kinematic"):
        return dict(friction=mu, slip=slip, bearing_friction=True, probability=p, runs=runs,
                    whirls=0, failed=0, undecided=undecided)

    rows = [row(0.30, 0.0, 13, 3), row(0.37, 0.06, 16, 0), row(0.38, None, 0, 16),
            row(0.39, None, 0, 16), row(0.38, None, 0, 16, slip="paper")]
    note = _undecided_note(rows)
    assert "51 drops left validity" in note and "35 at μ = 0.30 … 0.39" in note
    assert "from μ = 0.38 on" in note and "(2 grid values)" in note
    assert "was decided" in _undecided_note([row(0.30, 0.0, 16, 0)])
