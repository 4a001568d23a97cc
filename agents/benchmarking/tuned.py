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


def tuned_spec(law: str, suite_name: str) -> dict:
    """``{law, gains}``: designed law ``law`` with the constants tuned on suite ``suite_name``'s
    validation drops (what a config's ``residual: {law, tuned_on}`` stands for); ValueError
    naming the suites with records, or the missing record."""
    path = TUNED_DIR / f"{suite_name}.json"
    if not path.exists():
        have = ", ".join(sorted(p.stem for p in TUNED_DIR.glob("*.json")))
        raise ValueError(f"tuned_on = {suite_name!r}: no tuned records for that suite (suites "
                         f"with records: {have})")
    rec = json.loads(path.read_text()).get(law)
    if rec is None:
        raise ValueError(f"no tuned record of {law!r} on the {suite_name} suite "
                         "(rotordrop research tune-designed)")
    return {"law": law, "gains": dict(rec["gains"])}
