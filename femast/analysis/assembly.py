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

from ..jit import setup_call


@njit(cache=True)
def _scatter_matrix(k, pos, data):
    """Add the element matrices ``k`` (n_el, m, m) into ``data`` at positions ``pos`` (n_el, m, m):
    ``p >= 0`` adds at p, -1 is outside; ``p <= -2`` (from :func:`_assign_first_positions`) assigns
    at -2 - p, so that ``data`` needs no zeroing (the same sums: 0 + a = a).  The assignment test
    is reached only for negative positions: plain positions cost no extra branch per entry."""
    n_el, m, _ = k.shape
    for e in range(n_el):
        for i in range(m):
            for j in range(m):
                p = pos[e, i, j]
                if p >= 0:
                    data[p] += k[e, i, j]
                elif p <= -2:
                    data[-2 - p] = k[e, i, j]


@njit(cache=True)
def _assign_first_positions(pos, seen, out):
    """``out``: ``pos`` (int32) with each position's first entry in scatter order (families, then
    element, i, j) encoded as -2 - p (:func:`_scatter_matrix` assigns it instead of adding), -1 kept
    (outside).
    ``seen``: bool flags per position of the target array, shared across the families."""
    flat = pos.ravel()
    o = out.ravel()
    for k in range(flat.shape[0]):
        p = flat[k]
        if p < 0:
            o[k] = -1
        elif seen[p]:
            o[k] = p
        else:
            seen[p] = True
            o[k] = -2 - p


def assigning_positions(positions, size):
    """Positions (one array per family, -1 outside) re-encoded for :meth:`Assembler.tangent_into`
    without zeroing: the first entry of each position of a ``size``-long target assigns it (int32
    when the target is below 2**31 - 2 entries, half the memory traffic of the scatter)."""
    dtype = np.int32 if size < 2**31 - 2 else np.int64
    seen = np.zeros(size, dtype=np.bool_)
    out = []
    for pos in positions:
        o = np.empty(pos.shape, dtype=dtype)
        setup_call(_assign_first_positions, pos.size, np.ascontiguousarray(pos), seen, o)
        out.append(o)
    return out


@njit(cache=True)
def _scatter_vector(f, eqs, out):
    n_el, m = f.shape
    for e in range(n_el):
        for i in range(m):
            q = eqs[e, i]
            if q >= 0:
                out[q] += f[e, i]


@njit(cache=True)
def _scatter_diagonal(k, eqs, n, out):
    """Add the element matrices' entries on the diagonal of the assembled matrix (equations
    below ``n``) to ``out``, in the order :func:`_scatter_matrix` adds them."""
    n_el, m, _ = k.shape
    for e in range(n_el):
        for i in range(m):
            q = eqs[e, i]
            if q < 0 or q >= n:
                continue
            for j in range(m):
                if eqs[e, j] == q:
                    out[q] += k[e, i, j]


@njit(cache=True)
def _pattern_kernel(el_ptr, el_eq, ent_ptr, row_lo, row_hi, col_lo, col_hi):
    """CSR pattern (indptr, indices) of the block [row_lo:row_hi, col_lo:col_hi] of the matrix
    assembled from elements whose equations are ``el_eq[el_ptr[e]:el_ptr[e + 1]]`` (-1: none), and
    the position in its data array of every element-matrix entry (e, i, j), stored at
    ``ent_ptr[e] + i m_e + j`` (-1: outside the block).  Row by row: the elements incident to a row
    (a row -> (element, local index) incidence built first), their columns marked once, sorted."""
    nr = row_hi - row_lo
    nc = col_hi - col_lo
    n_el = el_ptr.shape[0] - 1
    inc_ptr = np.zeros(nr + 1, dtype=np.int64)
    for k in range(el_eq.shape[0]):
        r = el_eq[k]
        if r >= row_lo and r < row_hi:
            inc_ptr[r - row_lo + 1] += 1
    for r in range(nr):
        inc_ptr[r + 1] += inc_ptr[r]
    inc_el = np.empty(inc_ptr[nr], dtype=np.int64)  # element and flat index k of each incidence
    inc_k = np.empty(inc_ptr[nr], dtype=np.int64)
    fill = inc_ptr[:nr].copy()
    for e in range(n_el):
        for k in range(el_ptr[e], el_ptr[e + 1]):
            r = el_eq[k]
            if r >= row_lo and r < row_hi:
                inc_el[fill[r - row_lo]] = e
                inc_k[fill[r - row_lo]] = k
                fill[r - row_lo] += 1
    # pass 1: distinct columns per row (marker stamped with the row)
    marker = np.full(nc, -1, dtype=np.int64)
    indptr = np.zeros(nr + 1, dtype=np.int64)
    for r in range(nr):
        count = 0
        for t in range(inc_ptr[r], inc_ptr[r + 1]):
            e = inc_el[t]
            for kk in range(el_ptr[e], el_ptr[e + 1]):
                c = el_eq[kk] - col_lo
                if c >= 0 and c < nc and marker[c] != r:
                    marker[c] = r
                    count += 1
        indptr[r + 1] = indptr[r] + count
    # pass 2: the sorted columns of each row, and the positions of the entries in it
    indices = np.empty(indptr[nr], dtype=np.int64)
    pos = np.full(ent_ptr[n_el], -1, dtype=np.int64)
    marker[:] = -1
    where = np.empty(nc, dtype=np.int64)
    for r in range(nr):
        q = indptr[r]
        for t in range(inc_ptr[r], inc_ptr[r + 1]):
            e = inc_el[t]
            for kk in range(el_ptr[e], el_ptr[e + 1]):
                c = el_eq[kk] - col_lo
                if c >= 0 and c < nc and marker[c] != r:
                    marker[c] = r
                    indices[q] = c
                    q += 1
        indices[indptr[r] : q] = np.sort(indices[indptr[r] : q])
        for q2 in range(indptr[r], q):
            where[indices[q2]] = q2
        for t in range(inc_ptr[r], inc_ptr[r + 1]):
            e = inc_el[t]
            k0 = el_ptr[e]
            m = el_ptr[e + 1] - k0
            i = inc_k[t] - k0
            base = ent_ptr[e] + i * m
            for j in range(m):
                c = el_eq[k0 + j] - col_lo
                if c >= 0 and c < nc:
                    pos[base + j] = where[c]
    return indptr, indices, pos


def _block_pattern(eq_list, row_lo, row_hi, col_lo, col_hi):
    """CSR pattern of the block [row_lo:row_hi, col_lo:col_hi] of the assembled matrix and, per
    family, the position in its data array of every element-matrix entry (-1: outside).
    ``eq_list``: one (n_el, m) array of element equations per family (-1: not an equation)."""
    shape = (row_hi - row_lo, col_hi - col_lo)
    sizes = [int(eqs.size) for eqs in eq_list]
    ms = [int(eqs.shape[1]) for eqs in eq_list]
    el_ptr = np.concatenate([[0]] + [np.full(eqs.shape[0], m, dtype=np.int64) for eqs, m in zip(eq_list, ms)])
    el_ptr = np.cumsum(el_ptr)
    ent_ptr = np.cumsum(
        np.concatenate([[0]] + [np.full(eqs.shape[0], m * m, dtype=np.int64) for eqs, m in zip(eq_list, ms)])
    )
    el_eq = np.concatenate([np.ravel(eqs) for eqs in eq_list]).astype(np.int64) if sum(sizes) else np.zeros(0, np.int64)
    indptr, indices, pos = setup_call(
        _pattern_kernel, el_eq.size * 36, el_ptr, el_eq, ent_ptr, row_lo, row_hi, col_lo, col_hi
    )
    mat = sp.csr_matrix((np.zeros(indices.size), indices, indptr), shape=shape)
    positions = []
    offset = 0
    for eqs, m in zip(eq_list, ms):
        n = eqs.shape[0] * m * m
        positions.append(pos[offset : offset + n].reshape(eqs.shape[0], m, m))
        offset += n
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
        self._fc = None  # (K_fc, pos_fc), built when first needed (prescribed-value increments)

    @property
    def K_fc(self):
        """The free-constrained block (CSR pattern built on first use)."""
        return self._fc_block()[0]

    @property
    def pos_fc(self):
        return self._fc_block()[1]

    def _fc_block(self):
        if self._fc is None:
            nf, na = self.dofmap.n_free, self.dofmap.n_active
            self._fc = _block_pattern(self.eqs, 0, nf, nf, na)
        return self._fc

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

    def tangent_into(self, k_list, data, positions, assigning=False):
        """Zero ``data`` and add the element matrices at ``positions`` (one (n_el, m, m) array per
        family, -1 outside): K_ff assembled straight into another layout of its entries, such
        as the linear solver's permuted matrix.  ``assigning``: the positions come from
        :func:`assigning_positions` (the first entry of each position assigns it: no zeroing;
        entries of ``data`` that no element writes keep their value, zero in a fresh array)."""
        if not assigning:
            data[:] = 0.0
        for k, pos in zip(k_list, positions):
            _scatter_matrix(k, pos, data)

    def diagonal(self, k_list):
        """The diagonal of K_ff (the same sums as in the assembled K_ff)."""
        out = np.zeros(self.dofmap.n_free)
        for k, eqs in zip(k_list, self.eqs):
            setup_call(_scatter_diagonal, k.size, k, eqs, self.dofmap.n_free, out)
        return out

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
