"""docs/tasks.md states each task's standing from the committed data: every score it quotes for a
row, the oracle margins, the robust target and the hard benchmark's reference must match
docs/data/*.json (re-running a benchmark without updating the page fails here)."""
import json
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "docs" / "data"
SECTIONS = {"Damping": ("nominal", "damping"), "Re-levitation": ("nominal", "relevitate"),
            "Full: damping and re-levitation": ("nominal", "full"), "Robust suite": ("robust", "full")}


def _sections() -> dict[str, str]:
    parts = re.split(r"^## (.+)$", (ROOT / "docs" / "tasks.md").read_text(), flags=re.M)
    return dict(zip(parts[1::2], parts[2::2]))


def _load(name):
    return json.loads((DATA / f"{name}.json").read_text())


def test_every_quoted_row_score_is_the_committed_one():
    sections, checked = _sections(), 0
    for title, (suite, task) in SECTIONS.items():
        rows = {e["controller"]: e for e in _load(f"leaderboard-{suite}")["leaderboard"]
                if e["task"] == task}
        status = sections[title].split("**Status", 1)[1]
        for name, score, se in re.findall(r"`([\w-]+)` (-?\d+\.\d\d)\b(?: ± (\d+\.\d\d))?", status):
            assert name in rows, (title, name)
            assert f"{rows[name]['score']:.2f}" == score, (title, name, rows[name]["score"], score)
            assert se == f"{rows[name]['score_se']:.2f}", (title, name, "SE", se)   # quoted with it
            checked += 1
    assert checked >= 8


def test_oracle_margins_robust_target_and_hard_reference():
    sections = _sections()
    nominal = {r["controller"]: r["score"] for r in _load("oracle-nominal")["summary"]}
    full = sections["Full: damping and re-levitation"]
    assert f"{nominal['oracle']:.2f}" in full and f"{nominal['whirl-brake']:.2f}" in full
    assert f"{nominal['oracle'] - nominal['whirl-brake']:+.2f} points" in full
    summary = _load("oracle-robust")["summary"]
    robust = {r["controller"]: r["score"] for r in summary}
    best_designed = robust[summary[0]["reference"]]           # the best designed row there
    text = sections["Robust suite"]
    assert f"{robust['oracle']:.2f}" in text and f"{robust['oracle'] - best_designed:.2f}" in text
    target = _load("leaderboard-robust")["target"]
    assert ("not met" in text) == (not target["met"]) and f"+{target['margin']:g}" in text
    for name in ("hard-pid-relevitate", "hard-whirl-brake"):
        hard = _load(name)
        n, rate = hard["summary"]["episodes"], hard["summary"]["relevitation_success_rate"]
        assert f"{round(rate * n)} / {n}" in sections["Hard benchmark: raw currents"]


def test_hard_benchmark_algorithm_rows_quote_the_committed_table():
    """Every `algo` (variant) mean ± std the hard-benchmark section quotes is the algorithm
    table's (docs/data/hard-table.json, as docs/results.md shows it), and each variant is quoted."""
    from agents.benchmarking.results import hard_algorithm_rows
    table = _load("hard-table")
    text = _sections()["Hard benchmark: raw currents"]
    quoted = re.findall(r"`(\w+)` \((nominal|noisy)\) (\d\.\d\d) ± (\d\.\d\d)", text)
    assert {variant for _, variant, _, _ in quoted} == {"nominal", "noisy"}
    for algo, variant, mean, std in quoted:
        row = {r["name"]: r for r in hard_algorithm_rows(table, variant)}[algo]
        assert (f"{row['rate_mean']:.2f}", f"{row['rate_std']:.2f}") == (mean, std), (algo, variant)
