"""The kernel cache is keyed by every kernel source, so editing a callee recompiles its callers."""
import shutil

from physics import _jit


def test_editing_any_kernel_file_changes_the_cache_directory(tmp_path):
    root = _jit.Path(_jit.__file__).resolve().parent.parent
    for pkg in _jit._PACKAGES:
        shutil.copytree(root / pkg, tmp_path / pkg, ignore=shutil.ignore_patterns("__pycache__"))
    before = _jit._kernel_sources_hash(tmp_path)
    assert before == _jit._kernel_sources_hash(root)
    model = tmp_path / "physics" / "model.py"                 # a callee of integrate_segment
    model.write_text(model.read_text() + "\n# edited\n")
    assert _jit._kernel_sources_hash(tmp_path) != before
    assert _jit.CACHE_DIR.endswith(before)
    # the slot layout the kernels compile in as constants counts as kernel source too
    layout = tmp_path / "physics" / "layout.py"
    edited = _jit._kernel_sources_hash(tmp_path)
    layout.write_text(layout.read_text() + "\n# edited\n")
    assert _jit._kernel_sources_hash(tmp_path) != edited


def test_decorating_leaves_numba_global_cache_setting_alone():
    """Our kernels cache into CACHE_DIR, yet numba's global setting never points there: not after
    importing the package (which decorates every kernel), nor after decorating one more."""
    from numba.core import config
    previous = config.CACHE_DIR
    assert previous != _jit.CACHE_DIR

    @_jit.njit
    def twice(x):
        return 2 * x

    assert twice(2) == 4 and config.CACHE_DIR == previous
    assert twice._cache._cache_path.startswith(_jit.CACHE_DIR)


def test_a_bound_kernel_runs_its_own_machine_code_with_the_dispatchers_numbers():
    """physics.jit.bound calls the overload compiled for exactly its arguments' types (its
    entry point, not the dispatcher) and gives the dispatcher's numbers; something that is not
    a numba dispatcher is called as it is."""
    import numpy as np
    from physics.jit import bound
    from rotordrop_env import kernels as K
    rng = np.random.default_rng(3)
    out, M, C = rng.normal(size=K.N_O), rng.normal(size=K.N_M), rng.normal(size=K.N_C)
    by_dispatch, by_bound = np.zeros(K.N_V), np.zeros(K.N_V)
    K.info_values(out, M, C, by_dispatch)
    call = bound(K.info_values, out, M, C, by_bound)
    assert call.func is not K.info_values and call.args == (out, M, C, by_bound)
    call()
    assert np.array_equal(by_bound, by_dispatch)
    plain = bound(np.add, 1.0, 2.0)
    assert plain.func is np.add and plain() == 3.0
