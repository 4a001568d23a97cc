"""The error of a bad hyperparameter and the checks every config key shares (:mod:`agents.learning.hyperparams`
validates the files, :mod:`agents.learning.reward` its ``reward_kwargs`` with them)."""
from __future__ import annotations

import difflib
import math
from typing import Any


class ConfigError(ValueError):
    """A hyperparameter file or value is invalid; the message names the key."""


def is_finite_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def check_keys(kind: str, given, allowed) -> None:
    """ConfigError naming the first key of ``given`` not in ``allowed`` (and a close match)."""
    unknown = [k for k in given if k not in allowed]
    if unknown:
        close = difflib.get_close_matches(str(unknown[0]), list(allowed), n=1)
        hint = f" (did you mean {close[0]}?)" if close else ""
        raise ConfigError(f"{kind}: unknown key {unknown[0]!r}{hint}; allowed: {', '.join(allowed)}")
