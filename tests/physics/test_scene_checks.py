"""Inputs that used to run and give garbage (or a traceback) now stop with a one-line error:
solver tolerances looser than the accuracy study supports, retainer-bearing geometry that cannot
be built, accuracy studies whose reference cannot run or whose fault lies outside the compared
span, and study drops drawn in a figure that fail."""
import math

import pytest

from physics import SceneError, load_scene, simulate
from physics.runs.accuracy import AccuracyPlan, plan_runs
from agents.cli import main as cli_main
from physics.metrics import compute_metrics, worst_plane
from physics.scene import Scene, param_meta


# ------------------------------------------------------------------------- solver.rtol --
@pytest.mark.parametrize("rtol", [2e-3, 5e-3, 1e-2, 0.1])
def test_tolerances_that_give_wrong_bearing_loads_are_refused(rtol):
    with pytest.raises(SceneError, match=r"solver.rtol.*\[1e-12, 0.001\]"):
        load_scene("paper", {"solver.rtol": rtol})


def test_the_loosest_allowed_tolerance_keeps_the_bearing_load_within_a_few_percent():
    """At rtol 1e-2 the bearing load was 10x off (34 kN against 3.3 kN), at 5e-3 16 % off; the
    loosest allowed tolerance stays within 2 % of a tight run on the paper drop."""
    rtol_max = param_meta("solver.rtol")["hi"]
    assert rtol_max == 1e-3 and Scene().solver.rtol <= rtol_max
    m = {r: compute_metrics(simulate(load_scene("paper", {"solver.rtol": r}), t_end=0.3))
         for r in (rtol_max, 1e-6)}
    for key in ("peak_bearing_load_N", "max_ball_load_N", "peak_contact_force_N"):
        ref = worst_plane(m[1e-6], key)
        assert abs(worst_plane(m[rtol_max], key) - ref) <= 0.02 * ref, key


def test_nothing_in_the_repository_uses_a_looser_tolerance():
    plans = (AccuracyPlan.make(True), AccuracyPlan.make(False))
    for plan in plans:                          # every setting of both accuracy grids is valid
        for r in plan.rtols + (plan.reference_rtol,):
            load_scene("paper", {"solver.rtol": r})


# ------------------------------------------------------------------ bearing geometry --
def test_balls_that_do_not_fit_on_the_pitch_circle_are_refused():
    # 10 balls of 50 mm on a 110 mm pitch circle: neighbours overlap (limit d_m sin(pi/z) = 34 mm)
    with pytest.raises(SceneError) as exc:
        load_scene("paper", {"bearing.ball_diameter": 0.05})
    msg = str(exc.value)
    assert "bearing.ball_diameter" in msg and "bearing.balls" in msg and "bearing.pitch_diameter" in msg
    assert "33.99 mm" in msg
    with pytest.raises(SceneError, match="bearing.balls = 30"):
        load_scene("paper", {"bearing.balls": 30})
    load_scene("paper", {"bearing.balls": 18})              # 18 x 19.05 mm still fit (19.10 mm)


def test_a_journal_larger_than_the_inner_raceway_is_refused():
    with pytest.raises(SceneError) as exc:
        load_scene("paper", {"rotor.journal_radius": 0.5})
    msg = str(exc.value)
    assert "rotor.journal_radius" in msg and "contact.clearance" in msg
    assert "bearing.pitch_diameter" in msg and "45.48 mm" in msg
    with pytest.raises(SceneError, match="contact.clearance"):          # R = r + c counts
        load_scene("paper", {"rotor.journal_radius": 0.045, "contact.clearance": 0.001})
    # a larger bearing makes room for it
    s = load_scene("paper", {"rotor.journal_radius": 0.1, "bearing.pitch_diameter": 0.25})
    assert s.rotor.journal_radius + s.contact.clearance < (0.25 - s.bearing.ball_diameter) / 2


def test_presets_and_the_6016_default_satisfy_the_geometry():
    for name in ("paper", "spec"):
        s = load_scene(name)
        b = s.bearing
        assert b.ball_diameter < b.pitch_diameter * math.sin(math.pi / b.balls)
        assert s.rotor.journal_radius + s.contact.clearance < (b.pitch_diameter - b.ball_diameter) / 2


def test_the_cli_refuses_bad_geometry_with_one_line(tmp_path, capsys):
    for bad in ("bearing.ball_diameter=0.05", "rotor.journal_radius=0.5"):
        assert cli_main(["drop", "--set", bad, "--out", str(tmp_path), "--quiet"]) == 2
        err = capsys.readouterr().err
        assert err.startswith("rotordrop: error:") and err.count("\n") == 1
        assert not (tmp_path / "metrics.json").exists()


# ------------------------------------------------------------------------ accuracy --
def test_accuracy_with_a_failing_reference_is_a_clear_error(tmp_path, capsys):
    """The reference at rtol 1e-10 runs out of a 2000-step budget: one line naming the setting
    and the failed drop, no traceback, no output files."""
    out = tmp_path / "acc"
    assert cli_main(["accuracy", "--quick", "--quiet", "--jobs", "1", "--set",
                     "solver.max_steps=2000", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("rotordrop: error: the reference runs (adaptive rtol 1e-10)")
    assert "solver.max_steps" in err and "rotordrop drop --scene paper" in err
    assert err.count("\n") == 1 and not out.exists()


@pytest.mark.parametrize("quick, off, limit", [(True, 0.5, "0.2395"), (True, 0.25, "0.2395"),
                                               (False, 0.99, "0.9395")])
def test_accuracy_refuses_a_fault_outside_the_compared_span(quick, off, limit):
    with pytest.raises(SceneError) as exc:
        plan_runs(AccuracyPlan.make(quick), "paper", {"amb.off_time": off})
    assert "amb.off_time" in str(exc.value) and f"<= {limit} s" in str(exc.value)
    plan_runs(AccuracyPlan.make(quick), "paper", {"amb.off_time": float(limit)})   # the limit runs


# --------------------------------------------------------------------------- study --
def test_a_failing_figure_drop_of_the_study_names_the_drop(tmp_path, capsys):
    """The stiff support study's nominal drop runs out of a 14 000-step budget: the error says
    which drop and how to re-run it alone."""
    assert cli_main(["study", "paper", "--quick", "--quiet", "--jobs", "1", "--set",
                     "solver.max_steps=14000", "--out", str(tmp_path / "st")]) == 2
    err = capsys.readouterr().err
    assert "support.stiffness = 5e+08" in err and "step budget solver.max_steps = 14000" in err
    assert "re-run it alone: rotordrop drop --scene paper --set solver.max_steps=14000 --set " \
           "support.stiffness=" in err
    assert err.count("\n") == 1
