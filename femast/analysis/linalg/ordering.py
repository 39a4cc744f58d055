"""Patterns and fill-reducing orderings of the sparse LU (:class:`~.linear.SparseLU`): the
symbolic part, functions of a matrix's pattern (and, for the trial of orderings, of its values).
The reasoning behind the choices is in :mod:`.linear`'s docstring."""

from __future__ import annotations

from time import perf_counter

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit
from scipy.sparse.csgraph import reverse_cuthill_mckee

from ...jit import setup_call


def same_pattern(pattern, K) -> bool:
    """K (CSR) has the pattern ``(shape, indptr, indices)`` (None: no pattern)."""
    return (
        pattern is not None
        and pattern[0] == K.shape
        and np.array_equal(pattern[1], K.indptr)
        and np.array_equal(pattern[2], K.indices)
    )


def entry_keys(shape, indptr, indices) -> np.ndarray:
    """``row * n_cols + col`` of the entries of a CSR pattern, in storage order."""
    rows = np.repeat(np.arange(shape[0], dtype=np.int64), np.diff(indptr))
    return rows * shape[1] + indices


def rcm(K):
    """RCM permutation of K's pattern and whether its envelope bounds the LU fill to at most
    twice nnz(K) (then no other ordering is worth a trial factorisation)."""
    perm = np.asarray(reverse_cuthill_mckee(K, symmetric_mode=True), dtype=np.int64)
    n = K.shape[0]
    inv = np.empty(n, dtype=np.int64)
    inv[perm] = np.arange(n)
    rows = np.repeat(inv, np.diff(K.indptr))
    cols = inv[K.indices]
    lo = np.full(n, n, dtype=np.int64)  # leftmost column of each permuted row (symmetric pattern)
    np.minimum.at(lo, rows, cols)
    np.minimum.at(lo, cols, rows)
    envelope = int(np.sum(np.arange(n) - np.minimum(lo, np.arange(n))))
    return perm, 2 * envelope + n <= 2 * K.nnz


@njit(cache=True)
def _permuted_csc(indptr, indices, inv, n_cols):
    """CSC pattern (indptr, indices) of P K P^T for a square CSR pattern of K (``inv``: the new
    index of each old one) and the gather index of its entries into K's data; rows sorted in each
    column (a counting sort by column, the rows visited in their new order)."""
    n = indptr.shape[0] - 1
    nnz = indices.shape[0]
    out_ptr = np.zeros(n_cols + 1, dtype=np.int64)
    for k in range(nnz):
        out_ptr[inv[indices[k]] + 1] += 1
    for j in range(n_cols):
        out_ptr[j + 1] += out_ptr[j]
    fill = out_ptr[:n_cols].copy()
    rows = np.empty(nnz, dtype=np.int64)
    gather = np.empty(nnz, dtype=np.int64)
    perm = np.empty(n, dtype=np.int64)
    for i in range(n):
        perm[inv[i]] = i
    for r in range(n):  # the new rows in order: each column receives its rows sorted
        i = perm[r]
        for k in range(indptr[i], indptr[i + 1]):
            j = inv[indices[k]]
            rows[fill[j]] = r
            gather[fill[j]] = k
            fill[j] += 1
    return out_ptr, rows, gather


def permuted(K, perm):
    """(B, gather): the CSC matrix K[perm][:, perm] (K square CSR, without duplicate entries) and
    the index with B.data = K.data[gather]."""
    n = K.shape[0]
    inv = np.empty(n, dtype=np.int64)
    inv[np.asarray(perm, dtype=np.int64)] = np.arange(n)
    indptr, indices, gather = setup_call(
        _permuted_csc, K.nnz, K.indptr.astype(np.int64), K.indices.astype(np.int64), inv, n
    )
    B = sp.csc_matrix((K.data[gather], indices, indptr), shape=K.shape)
    return B, gather


def permuted_positions(gather, pos) -> np.ndarray:
    """Positions in the permuted matrix's data of the entries at positions ``pos`` (-1: none) of
    the data of the matrix it was permuted from (``gather`` from :func:`permuted`)."""
    inv = np.empty(gather.size, dtype=np.int64)
    inv[gather] = np.arange(gather.size)
    pos = np.asarray(pos)
    return np.where(pos >= 0, inv[np.maximum(pos, 0)], -1)


def try_orderings(K, kinds, factor, pivot_threshold):
    """Factorise K (CSR) in each ordering of ``kinds`` ("rcm", "mmd": SuperLU's minimum degree on
    A^T + A) with ``factor(B)`` of the permuted matrix; stops at RCM when its fill is bounded.

    Returns ``(best, first, error)``: ``best = (nnz of the LU, (kind, perm, B, gather), LU, wall s)``
    of the least fill (None if every factorisation failed), ``first = (kind, perm, B, gather)`` of
    the first ordering computed (None if none), ``error`` the last factorisation error."""
    best = None
    first = None
    error = RuntimeError("Factor is exactly singular")
    for kind in kinds:
        enough = False
        if kind == "rcm":
            perm, enough = rcm(K)  # enough: its fill is within 2x of any ordering's
        else:
            try:
                lu = spla.splu(
                    K.tocsc(),
                    permc_spec="MMD_AT_PLUS_A",
                    diag_pivot_thresh=pivot_threshold,
                    options=dict(SymmetricMode=True),
                )
            except RuntimeError as exc:
                error = exc
                continue
            perm = np.argsort(lu.perm_c).astype(np.int64)
        B, gather = permuted(K, perm)
        first = first or (kind, perm, B, gather)
        try:
            t0 = perf_counter()
            lu = factor(B)
            dt = perf_counter() - t0
        except RuntimeError as exc:
            error = exc
            continue
        if best is None or lu.nnz < best[0]:
            best = (lu.nnz, (kind, perm, B, gather), lu, dt)
        if enough:
            break
    return best, first, error
