"""The docs: generated results tables match the committed data, the user pages carry no work
history, and the README's links resolve. (The site itself is built by `mkdocs build --strict`
in .ci/run.)"""
import json
import re
from pathlib import Path

import pytest

from agents.benchmarking import results

ROOT = Path(__file__).resolve().parents[1]
USER_PAGES = [ROOT / "README.md"] + [p for p in (ROOT / "docs").rglob("*.md")
                                     if "experiments" not in p.relative_to(ROOT / "docs").parts]


def test_results_page_and_readme_leaderboard_match_the_committed_data():
    for path, text in results.generated(ROOT).items():
        assert path.read_text() == text, f"{path.name} is stale: run `python -m agents.benchmarking.results`"
    assert results.main(["--check"]) == 0


def test_results_command_stores_benchmark_output_and_regenerates(tmp_path):
    root = tmp_path / "repo"
    (root / "docs" / "img").mkdir(parents=True)
    (root / "README.md").write_text(f"# x\n\n{results.START}\nold\n{results.END}\n")
    bench = json.loads((ROOT / "docs/data/leaderboard-nominal.json").read_text())
    bench["rows"] = [{"controller": "passive"}]            # benchmark.json as written: rows dropped
    src = tmp_path / "benchmark.json"
    src.write_text(json.dumps(bench))
    assert results.main(["--root", str(root), "--nominal", str(src)]) == 0
    stored = json.loads((root / "docs/data/leaderboard-nominal.json").read_text())
    assert "rows" not in stored and stored["leaderboard"] == bench["leaderboard"]
    readme = (root / "README.md").read_text()
    top = next(e["controller"] for e in bench["leaderboard"] if e["task"] == "full")
    assert "\nold\n" not in readme and f"| 1 | `{top}` |" in readme
    assert "## Nominal suite" in (root / "docs/results.md").read_text()
    assert results.main(["--root", str(root), "--check"]) == 0
    oracle = tmp_path / "oracle.json"
    oracle.write_text((ROOT / "docs/data/oracle-robust.json").read_text())
    assert results.main(["--root", str(root), "--oracle-robust", str(oracle)]) == 0
    page = (root / "docs/results.md").read_text()
    assert "## Oracle (searched open-loop plans)" in page and "| `oracle` |" in page
    (root / "docs/results.md").write_text("edited by hand\n")
    assert results.main(["--root", str(root), "--check"]) == 1


def test_results_command_builds_the_hard_algorithm_table(tmp_path, capsys):
    """--hard-run (a run's kpis.json and run directory) and --hard-ref add rows to
    docs/data/hard-table.json; an evaluation whose sensing is not the variant's is refused."""
    root = tmp_path / "repo"
    (root / "docs" / "img").mkdir(parents=True)
    (root / "README.md").write_text(f"# x\n\n{results.START}\nold\n{results.END}\n")
    ref = ROOT / "docs/data/hard-whirl-brake.json"
    kpis = json.loads(ref.read_text())
    for seed in (0, 1):
        run = tmp_path / f"tqc-{seed}"
        run.mkdir()
        (run / "training.json").write_text(json.dumps(dict(
            algo="tqc", seed=seed, timesteps=40000 + seed, wall_time_s=300.2, steps_per_s=133.3,
            time_limit_s=300.0, command="rotordrop train ...", learning_curve=[
                dict(timesteps=40000, wall_time_s=290.0, mean_relevitated=0.5)])))
        kpis["policy"] = f"tqc-relevitate@tqc-{seed}/best"
        (run / "kpis.json").write_text(json.dumps(kpis))
        assert results.main(["--root", str(root), "--hard-run", "nominal", str(run / "kpis.json"),
                             str(run)]) == 0
    assert results.main(["--root", str(root), "--hard-ref", "nominal", str(ref)]) == 0
    table = json.loads((root / "docs/data/hard-table.json").read_text())
    assert [(r["algo"], r["seed"], r["model"]) for r in table["runs"]] == [("tqc", 0, "best"),
                                                                            ("tqc", 1, "best")]
    assert len(table["runs"][0]["relevitated"]) == 200 and table["references"][0]["sensing"] == {}
    page = (root / "docs/results.md").read_text()
    assert "### Algorithm table" in page and "wall-clock limit of 300 s" in page
    assert "| `tqc` | learned | **1.00 ± 0.00** | 1.00 ± 0.00, 1.00 ± 0.00 (200, 200 / 200) |" in page
    assert "| `whirl-brake` | designed | **1.00** |" in page and "40 k, 40 k |" in page
    assert results.main(["--root", str(root), "--hard-ref", "noisy", str(ref)]) == 2
    assert "is not the noisy variant's" in capsys.readouterr().err
    assert results.main(["--root", str(root), "--check"]) == 0


def test_user_pages_name_no_issue_numbers_or_time_boxes():
    bad = re.compile(r"\bissue\s*#?\d+|(?<![\w&])#\d+\b|time[- ]box", re.I)
    hits = [f"{p.relative_to(ROOT)}:{i}: {line.strip()}" for p in USER_PAGES
            for i, line in enumerate(p.read_text().splitlines(), 1) if bad.search(line)]
    assert not hits, "\n".join(hits)


def test_agents_guide_stays_a_guide():
    assert len((ROOT / "docs/agents.md").read_text().splitlines()) <= 800


def test_readme_links_resolve():
    readme = (ROOT / "README.md").read_text()
    for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", readme):
        if "://" not in target:
            assert (ROOT / target).exists(), target


def test_generated_physics_tables_match_their_data():
    """Tables that docs/examples scripts generate are pasted between markers: the page holds
    exactly what the script wrote (re-run the script and paste again when the physics changes)."""
    page = (ROOT / "docs/physics.md").read_text()
    start = "<!-- generated by docs/examples/dry_whirl_onset.py: do not edit -->\n"
    block = page[page.index(start) + len(start):page.index("<!-- end generated -->")]
    assert block == (ROOT / "docs/img/dry-whirl-onset-table.txt").read_text()
    rows = json.loads((ROOT / "docs/img/dry-whirl-onset.json").read_text())
    assert all(r["stator_penetration_um"] <= r["validity_bound_um"] + 1e-9 for r in rows)


def _example(name: str):
    import importlib.util
    spec = importlib.util.spec_from_file_location(name, ROOT / "docs/examples" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_flexible_study_tables_match_their_data():
    """docs/physics.md "When flexibility matters" holds exactly the tables
    docs/examples/flexible_study.py renders from docs/data/flexible-study.json (re-run the script:
    it rewrites the block), and the data is the study the script describes."""
    study = _example("flexible_study")
    page = (ROOT / "docs/physics.md").read_text()
    assert page.count(study.START) == 1
    i = page.index(study.START) + len(study.START)
    data = json.loads((ROOT / "docs/data/flexible-study.json").read_text())
    assert page[i:page.index(study.END, i)] == study.tables(data)
    assert data["frictions"] == list(study.FRICTIONS) and data["mu_grid"] == list(study.MU_GRID)
    flexible = [r["stiffness"] for r in data["rotors"][1:]]
    assert sorted(s["target_ratio"] for s in flexible if s["target_ratio"]) == list(study.RATIOS)
    for s in flexible:
        if s["target_ratio"]:
            assert abs(s["ratio"] / s["target_ratio"] - 1) < study.RATIO_TOL
    assert (ROOT / "docs/img/flexible-study.png").stat().st_size > 10_000
    assert (ROOT / "docs/data/flexible-study.csv").read_text().count("\n") == 1 + sum(
        len(r["grid"]) for r in data["rotors"])
    # whirl fractions over the grid x the drop's perturbations, never a bisected threshold; an
    # onset only where the fraction is monotone in mu, as the data say
    assert data["members"] == study.members() and len(data["members"]) == study.MEMBERS
    for r in data["rotors"]:
        assert sorted((g["friction"], g["member"]) for g in r["grid"]) == sorted(
            (mu, k) for mu in study.MU_GRID for k in range(study.MEMBERS))
        assert study.summarise(r) == r
        p = [f["fraction"] for f in r["whirl_fraction"] if f["fraction"] is not None]
        assert r["onset"]["monotone"] == all(b >= a for a, b in zip(p, p[1:]))
    assert "bisect" not in page[i:page.index(study.END, i)]

def test_flexible_study_whirl_statistics():
    """The flexible study's whirl fraction: Wilson's 95 % interval (0/10 -> [0, 0.278], 5/10 ->
    [0.237, 0.763], the textbook values), undecided drops left out of n, and an onset band only
    for a fraction that never falls along the grid."""
    study = _example("flexible_study")
    assert study.wilson(0, 10) == pytest.approx((0.0, 0.2775), abs=1e-4)
    assert study.wilson(5, 10) == pytest.approx((0.2366, 0.7634), abs=1e-4)
    grid = study.MU_GRID

    def drops(whirls):                   # per grid mu: decisions True / False / None
        return [dict(friction=mu, backward_whirl=w is True,
                     left_validity_at_s=0.2 if w is None else None)
                for mu, ws in zip(grid, whirls) for w in ws]
    rising = [[False, False]] * 5 + [[True, False], [True, None]] + [[True, True]] * 9
    f = study.whirl_fraction(drops(rising))
    assert f[6]["decided"] == 1 and f[6]["undecided"] == 1 and f[6]["fraction"] == 1.0
    assert study.onset_band(f) == dict(monotone=True, undecided_from=None, no_whirl_up_to=grid[4],
                                       all_whirl_from=grid[6])
    dip = [[False, False]] * 3 + [[True, True], [False, False]] + [[True, True]] * 11
    assert study.onset_band(study.whirl_fraction(drops(dip))) == dict(
        monotone=False, undecided_from=None, no_whirl_up_to=None, all_whirl_from=None)
    lost = [[False, False]] * 7 + [[None, None]] * 9     # the rotor reaches the air gap undecided
    assert study.onset_band(study.whirl_fraction(drops(lost))) == dict(
        monotone=True, undecided_from=grid[7], no_whirl_up_to=None, all_whirl_from=None)


def test_the_flexible_cost_table_is_the_benchmarks_output():
    """docs/scaling.md pastes the table benchmarks/bench_flexible.py wrote next to its data."""
    page = (ROOT / "docs/scaling.md").read_text()
    start = "<!-- generated by benchmarks/bench_flexible.py: do not edit -->\n"
    block = page[page.index(start) + len(start):page.index("<!-- end generated -->", page.index(start))]
    assert block == (ROOT / "docs/data/bench-flexible-table.txt").read_text()
    data = json.loads((ROOT / "docs/data/bench-flexible.json").read_text())
    for name, row in data["cases"].items():
        assert row["steps"] >= row["stability_min_steps"], name      # the bound holds
        assert f"| {name} | {row['elastic_modes']} |" in block


def _bench_env_block(data_file: str):
    """benchmarks/bench_env.py as a module, the JSON ``data_file`` of docs/data and the block
    docs/environments.md pastes between the markers naming its rendering."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("bench_env", ROOT / "benchmarks/bench_env.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    data = json.loads((ROOT / "docs/data" / data_file).read_text())
    page = (ROOT / "docs/environments.md").read_text()
    start = (f"<!-- generated by benchmarks/bench_env.py --render docs/data/{data_file}: "
             "do not edit -->\n")
    block = page[page.index(start) + len(start):page.index("<!-- end generated -->", page.index(start))]
    return bench, data, block


def test_the_controller_seat_speed_table_is_the_benchmarks_rendering():
    """docs/environments.md pastes the table bench_env.py renders from its controller-seat run
    (docs/data/bench-env-seat.json): rates and ratios to Pendulum-v1 at 0.1 and 0.2 ms with
    random currents, plus the comparison runs (a looser tolerance, a designed law's actions)."""
    bench, data, block = _bench_env_block("bench-env-seat.json")
    assert block == bench.seat_table(data) == bench.render(data)
    plain = [r for r in data["seat"] if r.get("actions", "random") == "random"
             and not r["env_kwargs"].get("overrides")]
    assert sorted(r["control_dt_s"] for r in plain) == [1e-4, 2e-4]
    for r in data["seat"]:                   # every case of the seat, with its ratio
        assert set(r["ratio_to_pendulum"]) == set(r["rates"]) - {bench.PENDULUM}
        assert r["env_kwargs"]["command"] == "continuous" and r["env_id"] == bench.SEAT_ENV


def test_the_1ms_speed_tables_are_the_benchmarks_rendering():
    """docs/environments.md pastes the tables bench_env.py renders from its 1 ms run
    (docs/data/bench-env.json), and what its prose concludes holds in that data: the backward
    whirl asks for several times the right-hand sides of the calm drop at the same cost each,
    the physics is most of a step so that batching per core stays under the Amdahl bound and,
    at the default tolerance, short of 1.5 x; the vector env steps as fast as the SB3 batch; a
    looser tolerance needs fewer right-hand sides and steps faster."""
    bench, data, block = _bench_env_block("bench-env.json")
    assert block == bench.step_table(data) == bench.render(data)
    default, loose = data["runs"]
    assert default["overrides"] == {} and float(loose["overrides"]["solver.rtol"]) == 1e-4
    sb3, vec = (f"{kind} N={data['n_envs']}, 1 thread, per core" for kind in ("SB3 batch", "vector env"))
    for r in data["runs"]:
        assert set(r["ratio_to_pendulum"]) == set(r["rates"]) - {bench.PENDULUM}
        assert set(r["ratio_to_single"]) == {n for n in r["rates"] if " N=" in n}
        calm, whirl = (r["splits"][f"Damping, {scene}"] for scene in bench.SCENES)
        assert whirl["integrator per step"]["rhs"] > 2 * calm["integrator per step"]["rhs"]
        assert 0.8 < whirl["integrator per step"]["rhs_ns"] / calm["integrator per step"]["rhs_ns"] < 1.25
        assert whirl["per-step us"]["wrapped"] > 2 * calm["per-step us"]["wrapped"]
        for split in r["splits"].values():
            c = split["per-step us"]
            assert 0.5 < c["physics"] / c["wrapped"] < 1
        b = r["batching bound per core (Amdahl)"]
        assert 1 < b["kernel"] < b["physics"] and r["ratio_to_single"][sb3] < b["physics"]
        assert abs(r["ratio_to_single"][vec] / r["ratio_to_single"][sb3] - 1) < 0.15
    assert default["batching bound per core (Amdahl)"]["physics"] < 1.5
    for case in default["splits"]:
        assert (loose["splits"][case]["integrator per step"]["rhs"]
                < default["splits"][case]["integrator per step"]["rhs"])
    for case in [n for n in default["rates"] if "gym.make" in n] + [sb3]:
        assert loose["ratio_to_pendulum"][case] > default["ratio_to_pendulum"][case]


@pytest.mark.parametrize("name", ["paper", "machine"])
def test_the_mode_tables_are_the_accuracy_runs_output(name):
    """docs/accuracy.md pastes the --modes table `rotordrop accuracy` wrote into docs/data."""
    page = (ROOT / "docs/accuracy.md").read_text()
    start = (f"<!-- generated by rotordrop accuracy --modes (docs/data/accuracy-modes-{name}): "
             "do not edit -->\n")
    block = page[page.index(start) + len(start):page.index("<!-- end generated -->", page.index(start))]
    out = (ROOT / f"docs/data/accuracy-modes-{name}/accuracy.md").read_text()
    assert block and block in out
    rows = json.loads((ROOT / f"docs/data/accuracy-modes-{name}/accuracy.json").read_text())
    assert rows["modes"]


def test_the_mutation_table_is_the_harness_output():
    """docs/physics.md "Mutation check" holds the table tests/mutants.py renders from
    docs/data/mutants.json, of today's mutants and test list, and no mutant recorded there
    survived (run `python3 tests/mutants.py` to refresh it)."""
    import mutants
    data = json.loads(mutants.DATA.read_text())
    page = mutants.PAGE.read_text()
    i = page.index(mutants.START) + len(mutants.START)
    assert page[i:page.index(mutants.END, i)] == mutants.table(data)
    assert data["tests"] == list(mutants.TESTS)
    assert [(m["name"], m["old"], m["new"]) for m in data["mutants"]] == [
        (m.name, m.old.replace("\n", " "), m.new.replace("\n", " ")) for m in mutants.MUTANTS]
    # how each died is the harness's verdict (tests/test_mutants.py fails a mutant that no
    # assertion kills); the page says it as the data has it, and names no survivor
    assert {m["how"] for m in data["mutants"]} <= {"assertion", "error only", "not run"}
