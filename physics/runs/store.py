"""Finished drops on disk as they finish: what ``--resume`` continues from.

A batch writes ``<out>/drops/manifest.json`` (what the batch is: its number of drops, scenes and
a fingerprint of every run's scene, overrides and labels, the ``evaluate`` function and the
contents of a TOML scene file) and appends one JSON line per finished drop to
``<out>/drops/done.jsonl`` (``{"i": index in the batch, "ok", "metrics", "extra", "error"}``,
and on a Ray cluster ``"node"``: the address of the node that ran it), flushed at once. A
killed driver therefore loses at most the line being written (a cut last line is dropped on
reading); ``--resume`` keeps every stored drop and runs only the missing
ones. A ``--resume`` folder of another batch is refused before anything is changed.
"""
from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import IO, Sequence

from . import UsageError
from .sweep import Evaluate, Run

FORMAT = "rotordrop-drops/1"
FOLDER = "drops"


class DropStore:
    """The records of a batch's drops, index by index; on disk when opened with :meth:`open`."""

    def __init__(self, runs: Sequence[Run], folder: Path | None = None,
                 records: dict[int, dict] | None = None, manifest: dict | None = None):
        self.n = len(runs)
        self.folder = folder
        self._records = dict(records or {})
        self._manifest = manifest            # written by begin() when the store starts afresh
        self._fh: IO[str] | None = None

    @classmethod
    def memory(cls, runs: Sequence[Run]) -> "DropStore":
        """A store that keeps nothing on disk."""
        return cls(runs)

    @classmethod
    def open(cls, out: str | Path, runs: Sequence[Run], evaluate: Evaluate | None, what: str,
             resume: bool = False) -> "DropStore":
        """The store of ``runs`` in ``out/drops``: its finished drops kept with ``resume`` (if
        it holds this very batch; a one-line UsageError otherwise), else started afresh. Nothing
        on disk changes before :meth:`begin` (so a batch that fails to start loses nothing)."""
        folder = Path(out) / FOLDER
        manifest = make_manifest(runs, evaluate, what)
        old = read_manifest(folder) if resume else None
        if old is not None and old.get("fingerprint") != manifest["fingerprint"]:
            raise UsageError(
                f"--resume {out}: it holds drops of another batch ({describe(old)}), not of this "
                f"command ({describe(manifest)}); nothing was changed: use another --out, or "
                f"leave out --resume to start over there")
        if old is None:
            return cls(runs, folder, {}, manifest)
        return cls(runs, folder, read_records(folder / "done.jsonl", len(runs)))

    def begin(self) -> None:
        """Open the file the finished drops go to (a fresh store first replaces the folder's
        manifest and drops)."""
        if self.folder is None or self._fh is not None:
            return
        self.folder.mkdir(parents=True, exist_ok=True)
        done = self.folder / "done.jsonl"
        if self._manifest is not None:
            done.write_text("")
            (self.folder / "manifest.json").write_text(json.dumps(self._manifest, indent=1))
            self._manifest = None
        else:
            cut_partial_line(done)
        self._fh = open(done, "a", encoding="utf-8")

    def missing(self) -> list[int]:
        """Indices of the drops not finished yet."""
        return [i for i in range(self.n) if i not in self._records]

    def add(self, i: int, rec: dict, node: str | None = None) -> None:
        """Keep drop ``i``'s record, as it reads back from JSON (on disk at once if opened, with
        the ``node`` that ran it when known: provenance, not part of the record)."""
        line = json.dumps({"i": i, **rec, **({"node": node} if node else {})}, separators=(",", ":"))
        stored = json.loads(line)
        del stored["i"]
        stored.pop("node", None)
        self._records[i] = stored
        self.begin()
        if self._fh is not None:
            self._fh.write(line + "\n")
            self._fh.flush()

    def sync(self) -> None:
        if self._fh is not None:
            os.fsync(self._fh.fileno())

    def records(self) -> list[dict]:
        missing = self.missing()
        if missing:
            raise RuntimeError(f"{len(missing)} drop(s) of the batch have no result")
        return [self._records[i] for i in range(self.n)]

    def close(self) -> None:
        if self._fh is not None:
            self.sync()
            self._fh.close()
            self._fh = None


def make_manifest(runs: Sequence[Run], evaluate: Evaluate | None, what: str) -> dict:
    """What identifies a batch: every run, the evaluate function and any scene file's text."""
    h = hashlib.sha256()
    ev = None if evaluate is None else f"{evaluate.__module__}.{evaluate.__qualname__}"
    scenes = sorted({r.scene for r in runs})
    h.update(json.dumps([FORMAT, ev], default=str).encode())
    for scene in scenes:
        path = Path(scene)
        if path.is_file():
            h.update(path.read_bytes())
    for r in runs:
        key = [r.scene, r.overrides, r.labels] + ([] if r.observe else ["not observed"])
        h.update(json.dumps(key, default=str).encode())
    return dict(format=FORMAT, what=what, runs=len(runs), scenes=scenes, evaluate=ev,
                fingerprint=h.hexdigest())


def describe(manifest: dict) -> str:
    return (f"{manifest.get('what', '?')}, scene {', '.join(manifest.get('scenes', ['?']))}, "
            f"{manifest.get('runs', '?')} drops")


def read_manifest(folder: Path) -> dict | None:
    """The manifest of ``folder`` (None when there is none: nothing to resume)."""
    path = folder / "manifest.json"
    if not path.exists():
        return None
    try:
        manifest = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise UsageError(f"--resume: {path} is not readable ({exc}); nothing was changed") from None
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        raise UsageError(f"--resume: {path} is not a rotordrop drop store ({FORMAT}); "
                         "nothing was changed")
    return manifest


def read_records(path: Path, n: int) -> dict[int, dict]:
    """The finished drops in ``path``; a line cut by a kill (the last one) is left out."""
    if not path.exists():
        return {}
    data = path.read_bytes()
    records = {}
    for line in data[:data.rfind(b"\n") + 1].decode("utf-8").splitlines():
        try:
            rec = json.loads(line)
            i = rec.pop("i")
            rec.pop("node", None)
        except (ValueError, KeyError, AttributeError):
            continue
        if isinstance(i, int) and 0 <= i < n:
            records[i] = rec
    return records


def cut_partial_line(path: Path) -> None:
    """Cut a line left unfinished by a kill off the end of ``path``, so that the next record
    starts on a line of its own."""
    if not path.exists():
        return
    data = path.read_bytes()
    end = data.rfind(b"\n") + 1
    if end < len(data):
        with open(path, "r+b") as fh:
            fh.truncate(end)
