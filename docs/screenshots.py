"""Build the documentation site and screenshot pages in headless Chromium, as a reader sees them.

    python docs/screenshots.py --out out/screenshots [--width 1400] [--site DIR] [--no-build]

Writes ``home.png`` and ``results.png`` (and any ``--page NAME=PATH`` given) into ``--out``:
each page of the built site opened from disk at ``--width`` pixels, the first ``HEIGHT`` pixels
of it. Needs ``mkdocs`` (extra ``docs``) and a Chromium on the PATH (``chromium``,
``chromium-browser`` or ``google-chrome``; Debian: ``apt-get install chromium``). Chromium runs
with a fresh profile in a temporary folder, without network services, and is ended after
``--timeout`` seconds per page.
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BROWSERS = ("chromium", "chromium-browser", "google-chrome")
#: page name -> (path in the site, window height [px])
PAGES = {"home": ("index.html", 1300), "results": ("results/index.html", 2600)}
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run",
         "--disable-default-apps", "--hide-scrollbars", "--mute-audio")


def find_browser() -> str | None:
    """The first Chromium on the PATH, or None."""
    return next((p for p in map(shutil.which, BROWSERS) if p), None)


def build_site(site: Path) -> Path:
    """``mkdocs build --strict`` of this checkout into ``site``."""
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--quiet", "--site-dir",
                    str(site)], cwd=ROOT, env=env, check=True)
    return site


def screenshot(browser: str, page: Path, out: Path, width: int, height: int,
               timeout: float = 120.0) -> Path:
    """One page (a file of the built site) as a PNG of ``width`` x ``height`` pixels."""
    if not page.is_file():
        raise FileNotFoundError(f"{page}: no such page in the built site")
    with tempfile.TemporaryDirectory(prefix="rotordrop-chromium-") as profile:
        cmd = [browser, *FLAGS, f"--user-data-dir={profile}", f"--window-size={width},{height}",
               f"--screenshot={out}", page.resolve().as_uri()]
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    if done.returncode != 0 or not out.is_file():
        raise RuntimeError(f"{Path(browser).name} made no screenshot of {page} "
                           f"(exit {done.returncode}): {done.stderr.strip()[-500:]}")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="folder for the PNGs")
    ap.add_argument("--width", type=int, default=1400, help="window width [px] (default 1400)")
    ap.add_argument("--site", default=None, help="site folder (default: a temporary one)")
    ap.add_argument("--no-build", action="store_true", help="use the site already in --site")
    ap.add_argument("--page", action="append", default=[], metavar="NAME=PATH",
                    help="another page: its path in the site, e.g. env=environments/index.html")
    ap.add_argument("--timeout", type=float, default=120.0, help="seconds per page")
    args = ap.parse_args(argv)
    browser = find_browser()
    if browser is None:
        print(f"screenshots: error: no Chromium on the PATH ({', '.join(BROWSERS)})",
              file=sys.stderr)
        return 2
    if args.no_build and not args.site:
        print("screenshots: error: --no-build needs --site", file=sys.stderr)
        return 2
    pages = dict(PAGES)
    for spec in args.page:
        name, _, path = spec.partition("=")
        pages[name] = (path, PAGES["results"][1])
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="rotordrop-site-") as tmp:
        site = Path(args.site or tmp)
        if not args.no_build:
            build_site(site)
        for name, (path, height) in pages.items():
            png = screenshot(browser, site / path, out / f"{name}.png", args.width, height,
                             args.timeout)
            print(f"wrote {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
