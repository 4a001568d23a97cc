"""The docs: generated results tables match the committed data, the user pages carry no work
history, and the README's links resolve. (The site itself is built by `mkdocs build --strict`
in .ci/run.)"""
import json
import re
from pathlib import Path

from agents import results

ROOT = Path(__file__).resolve().parents[1]
USER_PAGES = [ROOT / "README.md"] + [p for p in (ROOT / "docs").rglob("*.md")
                                     if "experiments" not in p.relative_to(ROOT / "docs").parts]


def test_results_page_and_readme_leaderboard_match_the_committed_data():
    for path, text in results.generated(ROOT).items():
        assert path.read_text() == text, f"{path.name} is stale: run `python -m agents.results`"
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
    assert "\nold\n" not in readme and "| 1 | `whirl-brake` |" in readme
    assert "## Nominal suite" in (root / "docs/results.md").read_text()
    assert results.main(["--root", str(root), "--check"]) == 0
    oracle = tmp_path / "oracle.json"
    oracle.write_text((ROOT / "docs/data/oracle-robust.json").read_text())
    assert results.main(["--root", str(root), "--oracle-robust", str(oracle)]) == 0
    page = (root / "docs/results.md").read_text()
    assert "## Oracle bound" in page and "| `oracle` |" in page
    (root / "docs/results.md").write_text("edited by hand\n")
    assert results.main(["--root", str(root), "--check"]) == 1


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
