"""femast.jit.setup_call remembers the plain-Python results of the pure set-up kernels:
the same results as computing them, never shared with the caller, and a kernel listed as pure
writes none of its arguments."""

import numpy as np
import pytest

from femast import jit
from femast.analysis.assembly import _block_pattern, _pattern_kernel
from femast.analysis.linalg.ordering import _permuted_csc, permuted


def _pattern_args(seed):
    rng = np.random.default_rng(seed)
    eqs = rng.integers(-1, 30, size=(25, 12)).astype(np.int64)
    el_ptr = np.arange(0, eqs.size + 1, 12, dtype=np.int64)
    ent_ptr = np.arange(0, 25 * 144 + 1, 144, dtype=np.int64)
    return eqs, (el_ptr, eqs.ravel(), ent_ptr, 0, 20, 0, 20)


def _csr(seed):
    import scipy.sparse as sp

    rng = np.random.default_rng(seed)
    a = sp.random(30, 30, density=0.2, random_state=rng, format="csr")
    return (a + a.T + sp.identity(30)).tocsr(), rng.permutation(30)


def test_every_memo_kernel_is_known():
    """Each name in MEMO_KERNELS is one of the kernels tested here (a renamed kernel would silently
    stop being remembered)."""
    names = {f"{k.py_func.__module__}.{k.py_func.__name__}" for k in (_pattern_kernel, _permuted_csc)}
    assert jit.MEMO_KERNELS == names


@pytest.mark.parametrize("kernel", ["pattern", "permuted"])
def test_memo_kernels_write_none_of_their_arguments(kernel):
    """A remembered kernel must be a function of its arguments alone: it leaves them unchanged."""
    if kernel == "pattern":
        _, args = _pattern_args(1)
        f = _pattern_kernel.py_func
    else:
        K, perm = _csr(1)
        inv = np.empty(30, np.int64)
        inv[perm] = np.arange(30)
        args = (K.indptr.astype(np.int64), K.indices.astype(np.int64), inv, 30)
        f = _permuted_csc.py_func
    before = [a.copy() if isinstance(a, np.ndarray) else a for a in args]
    f(*args)
    for a, b in zip(args, before):
        assert np.array_equal(a, b)


def test_remembered_results_equal_computed_ones_and_are_copies(monkeypatch):
    monkeypatch.setattr(jit, "_MEMO", {})
    for seed in range(3):
        eqs, args = _pattern_args(seed)
        fresh = _pattern_kernel.py_func(*args)
        first = jit.setup_call(_pattern_kernel, 10, *args)
        again = jit.setup_call(_pattern_kernel, 10, *args)
        for a, b, c in zip(fresh, first, again):
            assert np.array_equal(a, b) and np.array_equal(a, c)
        again[0][:] = -7  # a caller writing into its result changes nothing remembered
        third = jit.setup_call(_pattern_kernel, 10, *args)
        assert np.array_equal(third[0], fresh[0])
    assert len(jit._MEMO) == 3  # three distinct argument sets, three entries
    # the same pattern through the public function, twice, and another model's differs
    m1, p1 = _block_pattern([_pattern_args(0)[0]], 0, 20, 0, 20)
    m2, p2 = _block_pattern([_pattern_args(0)[0]], 0, 20, 0, 20)
    m3, _ = _block_pattern([_pattern_args(1)[0]], 0, 20, 0, 20)
    assert np.array_equal(m1.indices, m2.indices) and np.array_equal(p1[0], p2[0])
    assert not (m1.indices.shape == m3.indices.shape and np.array_equal(m1.indices, m3.indices))
    K, perm = _csr(2)
    B1, g1 = permuted(K, perm)
    B2, g2 = permuted(K, perm)
    dense = K.toarray()[perm][:, perm]
    assert np.array_equal(B1.toarray(), dense) and np.array_equal(B2.toarray(), dense)
    assert np.array_equal(g1, g2)


def test_memo_is_bounded(monkeypatch):
    monkeypatch.setattr(jit, "_MEMO", {})
    monkeypatch.setattr(jit, "MEMO_ENTRIES", 2)
    for seed in range(5):
        jit.setup_call(_pattern_kernel, 10, *_pattern_args(seed)[1])
    assert len(jit._MEMO) == 2


def test_large_inputs_are_not_remembered(monkeypatch):
    monkeypatch.setattr(jit, "_MEMO", {})
    monkeypatch.setattr(jit, "SETUP_PYTHON_MAX", 5)
    res = jit.setup_call(_pattern_kernel, 10, *_pattern_args(0)[1])  # compiled path
    assert not jit._MEMO
    for a, b in zip(res, _pattern_kernel.py_func(*_pattern_args(0)[1])):
        assert np.array_equal(a, b)
