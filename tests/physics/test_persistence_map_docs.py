"""docs/physics.md "Persistent contact with the AMBs on" holds exactly the tables that
docs/examples/persistence_map.py renders from docs/data/persistence-map.json (re-run the script:
it rewrites the block), and the committed data is the study the script describes: its grid, a
bi-stable cell of the stiff machine, and the harmonic-balance check within its stated tolerance
wherever the run ends in a forward rub."""
import importlib.util
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _study():
    spec = importlib.util.spec_from_file_location(
        "persistence_map", ROOT / "docs/examples/persistence_map.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_page_holds_the_tables_of_the_committed_data():
    study = _study()
    page = (ROOT / "docs/physics.md").read_text()
    assert page.count(study.START) == 1
    i = page.index(study.START) + len(study.START)
    data = json.loads((ROOT / "docs/data/persistence-map.json").read_text())
    assert page[i:page.index(study.END, i)] == study.tables(data)
    assert (ROOT / "docs/img/persistence-map.png").stat().st_size > 20_000
    assert (ROOT / "docs/img/persistence-bistable.png").stat().st_size > 10_000
    assert (ROOT / "docs/data/persistence-map.csv").read_text().count("\n") == 1 + len(data["runs"])


def test_the_data_is_the_scripts_grid_and_shows_a_bistable_cell():
    study = _study()
    data = json.loads((ROOT / "docs/data/persistence-map.json").read_text())
    assert data["speeds_rpm"] == list(study.SPEEDS) and data["shocks_g"] == list(study.SHOCKS)
    assert len(data["runs"]) == len(study.jobs())
    cells = study.states_by_cell(data)
    rpm, mass, shock = study.EXAMPLE
    example = cells[("stiff support", rpm, mass)]
    assert study.bistable(example)
    assert example[0.0] == "contact_free" and example[shock] == "forward_rub"
    assert data["example"]["0"]["label"] == "contact_free"
    assert data["example"][f"{shock:g}"]["label"] == "forward_rub"


def test_the_harmonic_balance_check_holds_its_tolerance_on_every_rub():
    data = json.loads((ROOT / "docs/data/persistence-map.json").read_text())
    rubs = [c for c in data["checks"] if c["end_state"] == "forward_rub"]
    assert len(rubs) >= 2
    for c in rubs:
        s, b = c["simulated"], c["balance"]
        assert abs(s["amplitude"] / b["amplitude"] - 1) < 0.02
        assert abs(s["contact_force"] / b["contact_force"] - 1) < 0.02
        assert abs((s["phase_deg"] - b["phase_deg"] + 180) % 360 - 180) < 5.0
        assert b["residual"] < 1e-9
