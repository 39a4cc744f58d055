"""The reduced tangent T^T K T + G of a constrained model, on a pattern computed once.

With rigid bodies and ties the analysis eliminates the dependent DOFs (femast/model/constraints.py):
the tangent on the independent DOFs is T^T K T + G.  K (all active DOFs) and T (active ->
independent) keep their sparsity patterns for the whole analysis; only their values change.  The
pattern of the product is therefore computed once, with every contribution

    C[i, j] += T[k, i] * K[k, l] * T[l, j]

listed as positions in the three data arrays, and each iteration is one compiled loop over that
list.  The pattern keeps entries that happen to cancel, so the linear solver sees the same
matrix layout every iteration (scipy's sparse product would drop exact zeros and allocate new
arrays each time).  Rows are kept for the free independent DOFs only: the block K_ff and, for
prescribed-displacement increments, K_fc.
"""

from __future__ import annotations

import hashlib
import threading

import numpy as np
import scipy.sparse as sp
from numba import njit


@njit(cache=True)
def _count(a_indptr, a_indices, t_indptr, t_indices, nf):
    n = 0
    for k in range(a_indptr.size - 1):
        for ti in range(t_indptr[k], t_indptr[k + 1]):
            if t_indices[ti] >= nf:
                continue
            for p in range(a_indptr[k], a_indptr[k + 1]):
                l = a_indices[p]
                n += t_indptr[l + 1] - t_indptr[l]
    return n


@njit(cache=True)
def _list(a_indptr, a_indices, t_indptr, t_indices, nf, n_ind, pa, pt1, pt2, key):
    c = 0
    for k in range(a_indptr.size - 1):
        for ti in range(t_indptr[k], t_indptr[k + 1]):
            i = t_indices[ti]
            if i >= nf:
                continue
            for p in range(a_indptr[k], a_indptr[k + 1]):
                l = a_indices[p]
                for tj in range(t_indptr[l], t_indptr[l + 1]):
                    pa[c] = p
                    pt1[c] = ti
                    pt2[c] = tj
                    key[c] = i * n_ind + t_indices[tj]
                    c += 1


@njit(cache=True)
def _fill(a_data, t_data, pa, pt1, pt2, pos, g_vals, g_pos, out):
    out[:] = 0.0
    for c in range(pa.size):
        out[pos[c]] += t_data[pt1[c]] * a_data[pa[c]] * t_data[pt2[c]]
    for g in range(g_pos.size):
        if g_pos[g] >= 0:
            out[g_pos[g]] += g_vals[g]


# The layout of the reduced blocks depends on the patterns of K, T and G alone: a process that sets
# up the same model again and again (the FE fits of femast.experiments: 50-100 runs of one ADAM mast
# with other parameters in a diagnosis) computes it once (the 40-bay mast's: 70 ms, a twentieth of a
# run).  The last LAYOUTS_KEPT layouts are remembered by a SHA-1 of the patterns; their arrays are
# read-only and shared.
LAYOUTS_KEPT = 4
_LAYOUTS: dict = {}
_LAYOUTS_LOCK = threading.Lock()  # (models set up in threads: a Study on dask threads)


def _layout_key(arrays, nf, n_ind) -> bytes:
    h = hashlib.sha1(f"{nf} {n_ind}".encode())
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(f"|{a.dtype.str}{a.shape}|".encode())
        h.update(a.data)
    return h.digest()


def _layout(a_ptr, a_idx, t_ptr, t_idx, g_rows, g_cols, nf, n_ind):
    """The contributions (pa, pt1, pt2) and their positions ``pos`` in the data array of the two
    blocks, the positions ``g_pos`` of G's entries, and the blocks' CSR structure."""
    n = _count(a_ptr, a_idx, t_ptr, t_idx, nf)
    pa, pt1, pt2, key = (np.empty(n, np.int64) for _ in range(4))
    _list(a_ptr, a_idx, t_ptr, t_idx, nf, n_ind, pa, pt1, pt2, key)
    g_key = np.where(g_rows < nf, g_rows * n_ind + g_cols, -1)
    all_keys = np.concatenate([key, g_key[g_key >= 0]])
    uniq = np.unique(all_keys)
    rows, cols = uniq // n_ind, uniq % n_ind
    in_ff = cols < nf
    # one data array holding both blocks: ff entries first (row-major), then fc entries
    order = np.concatenate([np.flatnonzero(in_ff), np.flatnonzero(~in_ff)])
    slot = np.empty(uniq.size, np.int64)
    slot[order] = np.arange(uniq.size)
    pos = slot[np.searchsorted(uniq, key)]
    g_pos = np.full(g_key.size, -1, np.int64)
    ok = g_key >= 0
    g_pos[ok] = slot[np.searchsorted(uniq, g_key[ok])]
    ff_r, ff_c = rows[in_ff], cols[in_ff]
    fc_r, fc_c = rows[~in_ff], cols[~in_ff] - nf
    out = dict(
        pa=pa, pt1=pt1, pt2=pt2, pos=pos, g_pos=g_pos, size=int(uniq.size), n_ff=int(in_ff.sum()),
        ff=(ff_c, _indptr(ff_r, nf)), fc=(fc_c, _indptr(fc_r, nf)),
    )  # fmt: skip
    for v in (pa, pt1, pt2, pos, g_pos, ff_c, fc_c, out["ff"][1], out["fc"][1]):
        v.flags.writeable = False
    return out


def _remembered_layout(K, T, g_rows, g_cols, nf):
    n_ind = T.shape[1]
    a_ptr, a_idx = K.indptr.astype(np.int64), K.indices.astype(np.int64)
    t_ptr, t_idx = T.indptr.astype(np.int64), T.indices.astype(np.int64)
    g_rows = np.asarray(g_rows, np.int64)
    g_cols = np.asarray(g_cols, np.int64)
    key = _layout_key((a_ptr, a_idx, t_ptr, t_idx, g_rows, g_cols), nf, n_ind)
    hit = _LAYOUTS.get(key)
    if hit is None:
        hit = _layout(a_ptr, a_idx, t_ptr, t_idx, g_rows, g_cols, nf, n_ind)
        with _LAYOUTS_LOCK:
            while _LAYOUTS and len(_LAYOUTS) >= LAYOUTS_KEPT:
                _LAYOUTS.pop(next(iter(_LAYOUTS)))  # the oldest
            _LAYOUTS[key] = hit
    return hit


class ReducedTangent:
    """T^T K T + G restricted to the free rows, filled in place into fixed CSR blocks.

    K : CSR (n_active x n_active) with the assembler's fixed pattern; T : CSR (n_active x n_ind),
    fixed pattern; G entries at (g_rows, g_cols) in independent numbering; nf free DOFs first."""

    def __init__(self, K, T, g_rows, g_cols, nf):
        n_ind = T.shape[1]
        lay = _remembered_layout(K, T, g_rows, g_cols, nf)
        self.pa, self.pt1, self.pt2, self.pos, self.g_pos = lay["pa"], lay["pt1"], lay["pt2"], lay["pos"], lay["g_pos"]
        self.data = np.zeros(lay["size"])
        n_ff = lay["n_ff"]
        # CSR blocks viewing self.data (their index arrays copied: the solver may keep them)
        ff_c, ff_ptr = (a.copy() for a in lay["ff"])
        fc_c, fc_ptr = (a.copy() for a in lay["fc"])
        self.K_ff = sp.csr_matrix((self.data[:n_ff], ff_c, ff_ptr), shape=(nf, nf))
        self.K_fc = sp.csr_matrix((self.data[n_ff:], fc_c, fc_ptr), shape=(nf, n_ind - nf))
        self.K_ff.data = self.data[:n_ff]  # views: filling self.data fills both blocks
        self.K_fc.data = self.data[n_ff:]
        self.K_ff.has_canonical_format = True
        self.K_fc.has_canonical_format = True

    def fill(self, K_data, T_data, g_vals):
        """Refill both blocks from the current values of K, T and G; returns (K_ff, K_fc)."""
        _fill(K_data, T_data, self.pa, self.pt1, self.pt2, self.pos, np.asarray(g_vals, float), self.g_pos, self.data)
        return self.K_ff, self.K_fc


def _indptr(rows, n):
    """CSR row pointer of row-sorted entries in rows ``rows`` of an n-row matrix."""
    ptr = np.zeros(n + 1, np.int64)
    ptr[1:] = np.cumsum(np.bincount(rows, minlength=n))
    return ptr
