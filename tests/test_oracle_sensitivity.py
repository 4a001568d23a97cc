"""agents.research.oracle_sensitivity: the oracle's sequences replayed on imperceptibly changed
copies of their scenarios."""
import pytest

from agents.oracle import oracle, suite_scenarios
from agents.research.oracle_sensitivity import PERTURBATIONS, perturbed, sensitivity
from agents.robust import SUITE_SEED


def test_copies_change_one_scene_value_by_the_stated_amount():
    sc, phase, _ = suite_scenarios("robust", 1, SUITE_SEED)[0]
    for name, (key, delta, relative) in [(n, c) for n, c in PERTURBATIONS.items() if c]:
        new, new_phase = perturbed(sc, phase, (key, delta, relative))
        assert new_phase == phase                   # the robust suite's phase is a scene value
        before = sc.scene_overrides(phase)[key]
        after = new.scene_overrides(new_phase)[key]
        assert after == pytest.approx(before * (1 + delta) if relative else before + delta), name
        others = {k: v for k, v in new.scene_overrides(new_phase).items() if k != key}
        assert others == {k: v for k, v in sc.scene_overrides(phase).items() if k != key}
    nominal, ph, _ = suite_scenarios("full", 1, 10_000)[0]
    assert perturbed(nominal, ph, PERTURBATIONS["phase +1 deg"])[1] == ph + 1.0
    # a key the scenario does not override starts from the paper scene's value
    from agents.benchmark import Scenario
    from physics.scene import load_scene
    bare = perturbed(Scenario("bare", 0.4), 0.0, PERTURBATIONS["stiffness +0.1 %"])[0]
    assert bare.overrides == {"support.stiffness": load_scene("paper").support.stiffness * 1.001}


def test_unchanged_copy_reproduces_the_oracle_and_the_designed_row(tmp_path):
    rep = oracle(tmp_path, scenarios=1, population=4, iterations=1, progress=False, plots=False,
                 suite="robust", constants=[(0.5, -0.5)], start_from_constants=True)
    out = sensitivity(rep, (0.5, -0.5), progress=False)
    assert out["scenarios"] == 1 and out["max_reproduction_error_J"] == 0.0
    rows = {r["perturbation"]: r for r in out["rows"]}
    score = {e["controller"]: e["score"] for e in rep["summary"]}
    assert rows["none"]["oracle"] == pytest.approx(score["oracle"], abs=1e-9)
    assert rows["none"]["designed"] == pytest.approx(score["constant g=0.5 r=-0.5"], abs=1e-6)
    # a friction change of 0.001 is a different drop: its scores are not the unchanged ones
    assert rows["friction +0.001"]["designed"] != rows["none"]["designed"]
