"""The numba decorators every kernel uses (:mod:`physics._jit`: compiled once, cached on disk, no
Python objects), under a public name for kernels outside physics (rotordrop_env's batch step, an
effect of one's own: docs/howto/physical-effect.md)."""
from ._jit import bound, njit, njit_borrow, njit_inline, njit_parallel

__all__ = ["bound", "njit", "njit_borrow", "njit_inline", "njit_parallel"]
