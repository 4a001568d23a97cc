"""The docs site people look at: every leaderboard as a compact table with its Δ figure (drawn
from the CSV of the same numbers) and every column one click away; the home page's drop, whose
committed data are physical and are the drop the code gives; the built site in a real browser
(headless Chromium, when one is installed)."""
import csv
import importlib.util
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from agents.benchmarking import results

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "results.md"


def load(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_every_leaderboard_has_a_compact_table_a_figure_and_every_column():
    page = PAGE.read_text()
    boards = results.leaderboards(ROOT)
    assert set(boards) == {"nominal-damping", "nominal-relevitate", "nominal-full", "robust-full"}
    for slug, (_, entries) in boards.items():
        png = ROOT / results.FIGURES / f"{slug}.png"
        assert png.is_file() and png.stat().st_size > 10_000, png
        assert f"]({png.relative_to(ROOT / 'docs').as_posix()})" in page
        for rank, e in enumerate(entries, 1):
            lo, hi = e["diff_ci95"]
            row = (f"| {rank} | `{e['controller']}` | {e.get('seat') or results.DEFAULT_SEAT} | "
                   f"{e['score']:.2f} ± {e['score_se']:.2f} | {e['diff_vs_reference']:+.2f} "
                   f"[{lo:+.2f}, {hi:+.2f}] |")
            assert row in page, row
        with (ROOT / results.FIGURES / f"{slug}.csv").open(newline="") as fh:
            plotted = list(csv.DictReader(fh))
        assert [r["controller"] for r in plotted] == [e["controller"] for e in entries]
        assert all(float(r["lo"]) <= float(r["diff"]) <= float(r["hi"]) for r in plotted)
    # the full tables sit in collapsed blocks, one per leaderboard
    assert page.count('??? info "Every column"') == len(boards)


def test_a_seat_in_the_data_is_shown():
    entry = dict(results.leaderboards(ROOT)["nominal-full"][1][0], seat="currents")
    assert f"| `{entry['controller']}` | currents |" in "\n".join(results.compact_table([entry]))


def test_the_figures_are_drawn_again_when_missing(tmp_path):
    root = tmp_path / "repo"
    (root / "docs" / "data").mkdir(parents=True)
    for name in ("leaderboard-nominal.json", "leaderboard-robust.json"):
        shutil.copy(ROOT / "docs" / "data" / name, root / "docs" / "data" / name)
    (root / "README.md").write_text(f"# x\n\n{results.START}\nold\n{results.END}\n")
    assert results.main(["--root", str(root)]) == 0
    pngs = sorted((root / results.FIGURES).glob("*.png"))
    assert len(pngs) == 4 and results.main(["--root", str(root), "--check"]) == 0
    pngs[0].unlink()
    assert results.main(["--root", str(root), "--check"]) == 1            # a figure is missing


def test_the_home_page_drop_is_physical_and_the_drop_the_code_gives(tmp_path):
    ex = load(ROOT / "docs" / "examples" / "home_drop.py", "home_drop")
    meta, rows = ex.read()
    t, x, y, force = rows.T
    r = np.hypot(x, y)
    assert np.all(np.diff(t) > 0) and t[0] == 0.0
    assert np.all(force >= 0.0) and force.max() == pytest.approx(meta["peak_contact_force_N"],
                                                                  rel=0.05)
    # no contact force while the rotor is inside the clearance of a centred sleeve and housing
    assert np.all(force[r < 0.9 * meta["clearance_um"]] == 0.0)
    # a valid run: no warnings, and the orbit stays near the AMB air gap (the stator contact)
    assert meta["warnings"] == [] and meta["backward_whirl"] and r.max() < 700.0
    caption = (ROOT / "docs" / "index.md").read_text()
    assert "](img/home-drop.png)" in caption.split("\n\n")[1]           # the page opens with it
    assert f"peaking at {meta['peak_contact_force_N'] / 1e3:.1f} kN" in caption
    assert ex.draw(meta, rows, tmp_path / "drop.png").stat().st_size > 10_000
    # the first 20 ms (the fall and the first impacts) are the drop the code gives today
    fresh_meta, fresh = ex.simulate_drop()
    early = t < 0.02
    assert np.allclose(fresh[: early.sum()], rows[early], rtol=1e-5, atol=1e-3)
    assert fresh_meta["backward_whirl"] == meta["backward_whirl"]


@pytest.mark.skipif(shutil.which("chromium") is None and shutil.which("chromium-browser") is None
                    and shutil.which("google-chrome") is None, reason="no Chromium installed")
def test_the_built_site_in_a_browser(tmp_path):
    pytest.importorskip("mkdocs")
    done = subprocess.run([sys.executable, str(ROOT / "docs" / "screenshots.py"), "--out",
                           str(tmp_path / "shots"), "--site", str(tmp_path / "site")],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    from PIL import Image
    for name, height in (("home", 1300), ("results", 2600)):
        image = np.asarray(Image.open(tmp_path / "shots" / f"{name}.png").convert("RGB"))
        assert image.shape == (height, 1400, 3)
        assert image.std() > 20.0                            # a page was drawn, not a blank
    home = (tmp_path / "site" / "index.html").read_text()
    assert re.search(r'<img[^>]+src="img/home-drop.png"', home)
