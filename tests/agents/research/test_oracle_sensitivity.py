"""agents.research.oracle_sensitivity: the oracle's sequences replayed on imperceptibly changed
copies of their scenarios."""
import pytest

from agents.research.oracle import oracle, suite_scenarios
from agents.research.blind_oracle import blind_oracle
from agents.research.oracle_sensitivity import PERTURBATIONS, largest_gains, perturbed, searches, sensitivity
from agents.benchmarking.robust import SUITE_SEED


@pytest.fixture(scope="module")
def robust_report(tmp_path_factory):
    """A one-scenario robust oracle with inner-loop-lift's constants as a row and as the start."""
    return oracle(tmp_path_factory.mktemp("oracle"), scenarios=1, population=4, iterations=1,
                  progress=False, plots=False, suite="robust", constants=[(0.5, -0.5)],
                  start_from_constants=True)


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
    # the phase wraps: 359.5 deg + 1 deg is 0.5 deg, not out of the scene's range
    from dataclasses import replace
    late = replace(sc, overrides={**sc.overrides, "unbalance.angle_deg": 359.5})
    assert perturbed(late, phase, PERTURBATIONS["phase +1 deg"])[0].overrides["unbalance.angle_deg"] == 0.5
    assert perturbed(nominal, 359.5, PERTURBATIONS["phase +1 deg"])[1] == 0.5
    # a key the scenario does not override starts from the paper scene's value
    from agents.benchmarking.benchmark import Scenario
    from physics.scene import load_scene
    bare = perturbed(Scenario("bare", 0.4), 0.0, PERTURBATIONS["stiffness +0.1 %"])[0]
    assert bare.overrides == {"support.stiffness": load_scene("paper").support.stiffness * 1.001}


def test_top_k_are_the_drops_with_the_largest_oracle_gain():
    found = [dict(position=i, theta=[], J=1.0, J_designed=1.0 + g)
             for i, g in enumerate([0.1, 0.5, -0.2, 0.3])]
    assert [f["position"] for f in largest_gains(found, 2)] == [1, 3]
    assert largest_gains(found, None) == found                      # all, in suite order
    with pytest.raises(ValueError, match="needs the designed row"):
        largest_gains([dict(found[0], J_designed=None)], 1)


def test_unchanged_copy_reproduces_the_oracle_and_the_designed_row(robust_report):
    rep = robust_report
    out = sensitivity(rep, (0.5, -0.5), progress=False)
    assert out["scenarios"] == 1 and out["max_reproduction_error_J"] == 0.0
    rows = {r["perturbation"]: r for r in out["rows"]}
    score = {e["controller"]: e["score"] for e in rep["summary"]}
    assert rows["none"]["oracle"] == pytest.approx(score["oracle"], abs=1e-9)
    assert rows["none"]["designed"] == pytest.approx(score["constant g=0.5 r=-0.5"], abs=1e-6)
    # a friction change of 0.001 is a different drop: its scores are not the unchanged ones
    assert rows["friction +0.001"]["designed"] != rows["none"]["designed"]
    # per scenario: every copy's J and whirl, summing to the rows
    copies = out["per_scenario"][0]["copies"]
    assert copies["none"]["J_oracle"] == pytest.approx(rep["per_scenario"][0]["search"]["J"], abs=1e-12)
    assert rows["friction +0.001"]["designed_whirls"] == int(copies["friction +0.001"]["whirl_designed"])

    # the compact form kept in docs/img reads the same, and --top picks by the oracle's gain
    name = "constant g=0.5 r=-0.5"
    p = rep["per_scenario"][0]
    compact = dict(settings=rep["settings"], per_scenario=[dict(
        index=0, J={"oracle": p["search"]["J"], name: p["rows"][name]["J"]},
        oracle_theta=p["search"]["theta"])])
    assert searches(compact) == searches(rep)
    assert searches(rep)[0]["J_designed"] == p["rows"][name]["J"]
    top = sensitivity(compact, (0.5, -0.5), top=1, progress=False)
    assert top["rows"] == out["rows"] and top["top"] == 1
    with pytest.raises(ValueError, match="needs the designed row 'constant g=0.3 r=-0.5'"):
        sensitivity(compact, (0.3, -0.5), top=1, progress=False)


def test_blind_oracle_suits_three_friction_copies_and_never_ends_below_the_designed_law(robust_report):
    rep = robust_report
    out = blind_oracle(rep, top=1, delta=1e-3, population=4, iterations=1, progress=False)
    (p,) = out["per_scenario"]
    own, minus, plus = p["copies"]
    assert [c["friction_change"] for c in p["copies"]] == [0.0, -1e-3, 1e-3]
    # the exact oracle's sequence on its own drop reproduces its J; the copies are other drops
    assert own["J_oracle"] == pytest.approx(rep["per_scenario"][0]["search"]["J"], abs=1e-12)
    assert minus["J_passive"] != own["J_passive"] or minus["J_designed"] != own["J_designed"]
    # the search starts from the designed law and keeps the best mean over the three copies
    mean = lambda key: sum(c[key] for c in p["copies"]) / 3
    assert mean("J_blind") <= mean("J_designed") + 1e-12
    assert p["blind_rollouts"] == 1 + 1 * 4
    # points of the suite score: 100 / sum of the passive J over the report's scenarios
    scale = 100.0 / rep["per_scenario"][0]["rows"]["passive"]["J"]
    assert out["per_copy"]["+0"]["oracle_gain_points"] == pytest.approx(
        scale * (own["J_designed"] - own["J_oracle"]))
    with pytest.raises(ValueError, match="delta = 0.2 must be in"):
        blind_oracle(rep, top=1, delta=0.2, progress=False)
