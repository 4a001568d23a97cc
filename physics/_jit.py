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


def bound(kernel, *args):
    """A zero-argument callable that runs the compiled ``kernel`` on exactly ``args`` (arrays a
    caller keeps and calls it on again and again: an environment's step on its buffers).

    A dispatcher call finds the machine code by typing every argument on every call (~1.7 µs
    for the 17 arrays of a step kernel against ~0.9 µs for the machine code's own entry). Bound
    once, the arguments' types are fixed, so the entry point of the overload compiled (or
    loaded from the disk cache) for those very types is called directly. That entry does not
    check types: it is only ever given these ``args``, which are never rebound to other arrays
    (rebinding makes a new callable). It cannot be pickled: keep it out of pickled state and
    bind again after unpickling. Where numba does not expose the entry point (another numba, or
    ``NUMBA_DISABLE_JIT``) it is the dispatcher call itself, with the same numbers."""
    from functools import partial
    try:
        types = tuple(kernel.typeof_pyval(a) for a in args)
        overload = kernel.overloads.get(types)
        if overload is None:
            kernel.compile(types)                   # compiled, or loaded from the disk cache
            overload = kernel.overloads[types]
        return partial(overload.entry_point, *args)
    except Exception:                               # the dispatcher raises its own errors
        return partial(kernel, *args)
