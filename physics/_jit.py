"""The one numba decorator used by every kernel: compiled once, cached on disk, no Python objects."""
import numba

njit = numba.njit(cache=True, fastmath=False, nogil=True)
