"""The numba decorators used by every kernel: compiled once, cached on disk, no Python objects.

numba's disk cache checks only the source file of the function it caches, so a kernel that calls a
kernel in another file (``integrate_segment`` -> ``model.rhs``) would silently keep stale machine
code after that other file changes. We therefore cache into a directory named by a hash of every
kernel source of the package: any change to any kernel recompiles everything once. The directory
is set only while our own functions are decorated; numba's global configuration is left as found.
Base directory: ``$ROTORDROP_CACHE_DIR``, else ``$NUMBA_CACHE_DIR``, else ``~/.cache/rotordrop``.
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numba
from numba.core import config as _numba_config

_PACKAGES = ("physics", "rotordrop_env")


def _kernel_sources_hash(root: Path | None = None) -> str:
    root = root or Path(__file__).resolve().parent.parent
    digest = hashlib.sha1(numba.__version__.encode())
    for pkg in _PACKAGES:
        for path in sorted((root / pkg).rglob("*.py")):
            text = path.read_bytes()
            if b"njit" in text:
                digest.update(path.relative_to(root).as_posix().encode())
                digest.update(text)
    return digest.hexdigest()[:16]


def _cache_dir() -> str:
    base = (os.environ.get("ROTORDROP_CACHE_DIR") or os.environ.get("NUMBA_CACHE_DIR")
            or os.path.join(os.path.expanduser("~"), ".cache", "rotordrop"))
    return os.path.join(base, f"numba-{_kernel_sources_hash()}")


CACHE_DIR = _cache_dir()


def _cached(**options):
    def decorate(func):
        previous = _numba_config.CACHE_DIR
        _numba_config.CACHE_DIR = CACHE_DIR
        try:
            return numba.njit(cache=True, nogil=True, **options)(func)
        finally:
            _numba_config.CACHE_DIR = previous
    return decorate


njit = _cached()
"""Serial kernel decorator (``@njit``)."""

njit_parallel = _cached(parallel=True)
"""Kernel decorator for ``prange`` loops over environments (``@njit_parallel``)."""


def _has_option(name: str) -> bool:
    """True when this numba's CPU target takes the (private) option ``name``."""
    from numba.core import cpu
    return hasattr(getattr(cpu, "CPUTargetOptions", None), name)


njit_borrow = _cached(_nrt=False) if _has_option("_nrt") else njit
"""Serial kernel decorator for kernels that allocate nothing and only read and write the arrays
they are given (``@njit_borrow``): compiled without numba's reference counting (its ``_nrt``
flag), so a call does not increment and decrement every array argument's count, nor a row view's
(an atomic operation each; the arrays belong to the caller, which holds them through the call).
Measured on ``rhs``, ``twin_planes`` and ``sample_diagnostics`` (paper drop, the same bits): the
output samples' diagnostics 560 -> 380 ns per sample, the integration 43 -> 37.6 ms CPU per
simulated second. ``_nrt`` is private to numba: a numba without it gets plain :data:`njit` (the
same numbers, slower)."""

njit_inline = _cached(_nrt=False, inline="always") if _has_option("_nrt") else _cached(
    inline="always")
"""Decorator of the effects' kernels that :func:`physics.model.rhs` calls (``@njit_inline``):
:data:`njit_borrow`, inlined into the caller by numba (its IR, before typing) instead of called.
Measured on the paper drop's rhs: called, the kernels' many arguments and tuple returns cost
~1.7 x the rhs of one written-out function; inlined, the same machine code cost (and the
``dy is None`` variant still drops the blocks that only feed the rates)."""
