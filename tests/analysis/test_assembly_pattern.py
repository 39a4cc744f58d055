"""The assembly pattern (femast/analysis/assembly.py): the CSR pattern of a block of the assembled
matrix and the position of every element-matrix entry in it, against a dictionary built entry by
entry; the diagonal summed from the element matrices against the assembled matrix's."""

import numpy as np
import pytest

from femast.analysis.assembly import _block_pattern, _scatter_diagonal, _scatter_matrix


def reference_pattern(eq_list, row_lo, row_hi, col_lo, col_hi):
    """Sorted (row, col) entries of the block and the position of each element entry (-1: outside)."""
    keys = sorted(
        {
            (r - row_lo, c - col_lo)
            for eqs in eq_list
            for el in eqs
            for r in el
            for c in el
            if row_lo <= r < row_hi and col_lo <= c < col_hi
        }
    )
    index = {k: p for p, k in enumerate(keys)}
    positions = [
        np.array(
            [
                [[index.get((r - row_lo, c - col_lo), -1) if r >= 0 and c >= 0 else -1 for c in el] for r in el]
                for el in eqs
            ],
            dtype=np.int64,
        ).reshape(len(eqs), eqs.shape[1], eqs.shape[1])
        for eqs in eq_list
    ]
    return keys, positions


@pytest.mark.parametrize("seed", range(12))
def test_block_pattern_matches_an_entry_by_entry_reference(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 30))
    # families of 1-12 equations per element, -1 for DOFs that are not equations
    eq_list = [
        rng.integers(-1, n, size=(int(rng.integers(0, 20)), int(rng.integers(1, 13))))
        for _ in range(int(rng.integers(1, 4)))
    ]
    nf = int(rng.integers(0, n + 1))
    for block in ((0, nf, 0, nf), (0, nf, nf, n), (0, n, 0, n)):
        mat, positions = _block_pattern(eq_list, *block)
        keys, ref = reference_pattern(eq_list, *block)
        rows = np.repeat(np.arange(mat.shape[0]), np.diff(mat.indptr))
        assert list(zip(rows.tolist(), mat.indices.tolist())) == keys
        for p, q in zip(positions, ref):
            np.testing.assert_array_equal(p, q)


def test_diagonal_from_the_element_matrices_is_the_assembled_diagonal_bit_for_bit():
    rng = np.random.default_rng(7)
    n = 40
    eqs = rng.integers(-1, n, size=(60, 12))
    k = rng.normal(size=(60, 12, 12))
    mat, (pos,) = _block_pattern([eqs], 0, 30, 0, 30)
    data = np.zeros(mat.nnz)
    _scatter_matrix(k, pos, data)
    mat.data = data
    diag = np.zeros(30)
    _scatter_diagonal(k, eqs, 30, diag)
    assert np.array_equal(diag, mat.diagonal())


def test_assigning_scatter_needs_no_zeroing_and_gives_the_same_sums():
    """The first entry of each position assigns it: a target holding the last assembly's values
    (here: garbage) ends up with the very sums of a zeroed target, over two families."""
    from femast.analysis.assembly import Assembler, assigning_positions

    rng = np.random.default_rng(11)
    eq_list = [rng.integers(-1, 25, size=(40, 12)), rng.integers(-1, 25, size=(15, 6))]
    k_list = [rng.normal(size=(40, 12, 12)), rng.normal(size=(15, 6, 6))]
    mat, positions = _block_pattern(eq_list, 0, 25, 0, 25)
    ref = np.zeros(mat.nnz)
    for k, pos in zip(k_list, positions):
        _scatter_matrix(k, pos, ref)
    enc = assigning_positions(positions, mat.nnz)
    assert all(p.dtype == np.int32 for p in enc)
    data = rng.normal(size=mat.nnz) * 1e6  # what a previous assembly left there
    Assembler.tangent_into(None, k_list, data, enc, assigning=True)
    assert np.array_equal(data, ref)


@pytest.mark.parametrize("seed", range(3))
def test_setup_kernels_give_the_same_results_as_plain_python(seed, monkeypatch):
    """Small models run the set-up kernels as plain Python (femast.jit.setup_call), large ones
    compiled: the same pattern, positions and diagonal either way."""
    from femast import jit

    rng = np.random.default_rng(20 + seed)
    eq_list = [rng.integers(-1, 30, size=(25, 12))]
    k = rng.normal(size=(25, 12, 12))
    results = []
    for limit in (10**9, -1):  # everything in Python, then everything compiled
        monkeypatch.setattr(jit, "SETUP_PYTHON_MAX", limit)
        mat, (pos,) = _block_pattern(eq_list, 0, 20, 0, 20)
        diag = np.zeros(20)
        jit.setup_call(_scatter_diagonal, k.size, k, eq_list[0], 20, diag)
        results.append((mat.indptr, mat.indices, pos, diag))
    for a, b in zip(*results):
        assert np.array_equal(a, b)
