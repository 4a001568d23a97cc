"""The generated block of a docs page: the text between a script's start and end markers, which
the docs/examples scripts rewrite and the tests compare with what the script renders."""
from __future__ import annotations

from pathlib import Path


def paste(page: Path, block: str, start: str, end: str) -> None:
    """Replace the text between ``start`` and the next ``end`` in ``page`` with ``block``."""
    text = page.read_text()
    i = text.index(start) + len(start)
    j = text.index(end, i)
    page.write_text(text[:i] + block + text[j:])


def publish(page: str, block: str, start: str, end: str) -> None:
    """Paste ``block`` into ``page`` (a path; '' for none) and print it."""
    if page:
        paste(Path(page), block, start, end)
    print(block)
