"""Sparse assembly: the CSR pattern is built once; each iteration fills it in place.

For every element family, a map from each entry (element, i, j) of its element
matrices to a position in the data array of the free-free block K_ff, and another to
the free-constrained block K_fc (needed for prescribed-displacement increments),
is computed once.  Filling is one numba loop per family, no Python work per element.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit


@njit(cache=True)
def _scatter_matrix(k, pos, data):
    n_el, m, _ = k.shape
    for e in range(n_el):
        for i in range(m):
            for j in range(m):
                p = pos[e, i, j]
                if p >= 0:
                    data[p] += k[e, i, j]


@njit(cache=True)
def _scatter_vector(f, eqs, out):
    n_el, m = f.shape
    for e in range(n_el):
        for i in range(m):
            q = eqs[e, i]
            if q >= 0:
                out[q] += f[e, i]


def _block_pattern(eq_list, row_lo, row_hi, col_lo, col_hi):
    """CSR pattern of the block [row_lo:row_hi, col_lo:col_hi] of the assembled matrix and, per
    family, the position in its data array of every element-matrix entry (-1: outside)."""
    shape = (row_hi - row_lo, col_hi - col_lo)
    keys = []
    for eqs in eq_list:
        m = eqs.shape[1]
        r = np.repeat(eqs, m, axis=1).reshape(eqs.shape[0], m, m)
        c = np.tile(eqs, (1, m)).reshape(eqs.shape[0], m, m)
        keep = (r >= row_lo) & (r < row_hi) & (c >= col_lo) & (c < col_hi)
        keys.append(np.where(keep, (r - row_lo).astype(np.int64) * shape[1] + (c - col_lo), -1))
    flat = np.concatenate([k.ravel() for k in keys]) if keys else np.zeros(0, np.int64)
    valid = np.flatnonzero(flat >= 0)
    if valid.size == 0:
        return sp.csr_matrix(shape), []
    # unique keys and the inverse map by one stable argsort (np.unique's hash path was 10x slower)
    kv = flat[valid]
    order = np.argsort(kv, kind="stable")
    s = kv[order]
    first = np.empty(s.size, dtype=bool)
    first[0] = True
    np.not_equal(s[1:], s[:-1], out=first[1:])
    key = s[first]
    pos = np.full(flat.size, -1, dtype=np.int64)
    pos[valid[order]] = np.cumsum(first) - 1
    indptr = np.zeros(shape[0] + 1, dtype=np.int64)
    indptr[1:] = np.cumsum(np.bincount(key // shape[1], minlength=shape[0]))
    mat = sp.csr_matrix((np.zeros(key.size), key % shape[1], indptr), shape=shape)
    positions = []
    offset = 0
    for k in keys:
        positions.append(pos[offset:offset + k.size].reshape(k.shape))
        offset += k.size
    return mat, positions


class Assembler:
    """Assembles internal forces (all active DOFs) and the K_ff, K_fc tangent blocks."""

    def __init__(self, dofmap, families, full: bool = False):
        self.dofmap = dofmap
        self.full = full
        self.eqs = [np.ascontiguousarray(dofmap.element_equations(f.nodes)) for f in families]
        nf, na = dofmap.n_free, dofmap.n_active
        if full:  # all active DOFs (the analysis reduces it with the constraint transformation)
            self.K_aa, self.pos_aa = _block_pattern(self.eqs, 0, na, 0, na)
        else:
            self.K_ff, self.pos_ff = _block_pattern(self.eqs, 0, nf, 0, nf)
            self.K_fc, self.pos_fc = _block_pattern(self.eqs, 0, nf, nf, na)

    def full_tangent(self, k_list):
        """K over all active DOFs (only with ``full=True``)."""
        self.K_aa.data[:] = 0.0
        for k, pos in zip(k_list, self.pos_aa):
            _scatter_matrix(k, pos, self.K_aa.data)
        return self.K_aa

    def forces(self, f_list) -> np.ndarray:
        out = np.zeros(self.dofmap.n_active)
        for f, eqs in zip(f_list, self.eqs):
            _scatter_vector(f, eqs, out)
        return out

    def tangent_into(self, k_list, data, positions):
        """Zero ``data`` and add the element matrices at ``positions`` (one (n_el, m, m) array per
        family, -1 outside): K_ff assembled straight into another layout of its entries, such
        as the linear solver's permuted matrix."""
        data[:] = 0.0
        for k, pos in zip(k_list, positions):
            _scatter_matrix(k, pos, data)

    def coupling(self, k_list):
        """K_fc alone (the free-constrained block)."""
        self.K_fc.data[:] = 0.0
        for k, pos in zip(k_list, self.pos_fc):
            _scatter_matrix(k, pos, self.K_fc.data)
        return self.K_fc

    def tangent(self, k_list, with_fc=False):
        self.K_ff.data[:] = 0.0
        for k, pos in zip(k_list, self.pos_ff):
            _scatter_matrix(k, pos, self.K_ff.data)
        if not with_fc:
            return self.K_ff, None
        self.K_fc.data[:] = 0.0
        for k, pos in zip(k_list, self.pos_fc):
            _scatter_matrix(k, pos, self.K_fc.data)
        return self.K_ff, self.K_fc
