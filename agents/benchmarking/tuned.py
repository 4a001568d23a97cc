"""The constants designed laws were tuned with on a suite's validation drops
(``agents/benchmarking/tuned/<suite>.json``, package data; written by
:mod:`agents.benchmarking.tune_designed`): the benchmark runs a designed row with them on that
suite (:func:`tuned_gains`)."""
from __future__ import annotations

import json
from pathlib import Path

#: where the tuned constants live (package data)
TUNED_DIR = Path(__file__).resolve().parent / "tuned"


def record_path(suite) -> Path:
    """The records of the suite whose validation drops tuned ``suite``'s designed rows."""
    return TUNED_DIR / f"{suite.tuned_on or suite.name}.json"


def load_records(suite) -> dict:
    path = record_path(suite)
    return json.loads(path.read_text()) if path.exists() else {}


def tuned_gains(suite, name: str, env_id: str) -> dict | None:
    """The constants of designed law ``name`` tuned on ``suite`` for ``env_id``; None when no
    record has them."""
    rec = load_records(suite).get(name)
    if rec is None or rec["env_id"] != env_id:
        return None
    return dict(rec["gains"])
