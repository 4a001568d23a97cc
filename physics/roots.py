"""Root finding for set-up quantities (not the hot path)."""
from __future__ import annotations

from typing import Callable


def bisect_decreasing(f: Callable[[float], float], target: float, lo: float, hi: float,
                      iterations: int = 200) -> float:
    """x in [lo, hi] with f(x) = target for f decreasing on the interval (f(lo) > target >=
    f(hi)); bisection, robust to kinks such as a bearing's clearance. It stops early once the
    bracket no longer moves (adjacent doubles: every further iteration would repeat the last),
    so the result is that of all ``iterations``."""
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        before = (lo, hi)
        if f(mid) > target:
            lo = mid
        else:
            hi = mid
        if (lo, hi) == before:
            break
    return 0.5 * (lo + hi)
