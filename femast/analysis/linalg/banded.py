"""Banded factorisations through LAPACK for tangents whose reverse Cuthill-McKee band is narrow.

A mast is a chain of identical bays: in RCM order every DOF couples only to DOFs of its own and
the neighbouring frames, so the tangent is a band matrix of half-bandwidth ``b`` (41 for the
four-longeron truss mast at every length).  LAPACK's blocked band kernels then factorise it with
dense level-3 BLAS on (b + 1) x n storage, without the sparse bookkeeping of a general sparse LU.

Two factorisations of the permuted matrix ``B`` (the CSC matrix :class:`~femast.analysis.linalg.linear.SparseLU`
refills every iteration, already in RCM order):

* **Cholesky of the symmetric part** (``dpbtrf``/``dpbtrs``) when ``B`` is numerically symmetric:
  ``max |B - B^T| <= SYMMETRY_TOL * max |B|``.  The corotational beam tangent in spin variables is
  symmetric at equilibrium and unsymmetric by terms of the order of the out-of-balance moments
  away from it (docs/beam_element.md): 1e-17 to 4e-9 relative on the masts.  Unless ``B`` is
  symmetric to 0.1 ``BACKWARD_TOL`` (then the Cholesky solve is backward stable for ``B`` itself),
  every solution is refined against ``B`` itself (``x += C^-1 (b - B x)``) until its normwise
  backward error is at most ``BACKWARD_TOL``, so the Newton step is the exact one, as from an LU
  of ``B``.  A refinement that does not contract (``B`` farther from symmetric than it looked) makes
  the solver fall back to the LU for this tangent.
* **LU with partial pivoting** (``dgbtrf``/``dgbtrs``) otherwise: an unsymmetric tangent (joint
  friction in slip, latches), and a symmetric one that is not positive definite (past a limit
  point or a bifurcation: ``dpbtrf`` stops at the first non-positive pivot and the LU is used
  for the next :data:`LU_AFTER_INDEFINITE` factorisations).

Zero pivots: ``dgbtrf`` reports an exactly zero one (``info > 0``); like SuperLU's diagonal test,
``|u_kk| <= 1e-13 max |u_kk|`` is a singular tangent (:meth:`BandedFactor.pivot_magnitudes`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.linalg import lapack

from ...jit import setup_call

SYMMETRY_TOL = 1e-6  # relative asymmetry below which the Cholesky of the symmetric part is tried
BACKWARD_TOL = 1e-14  # normwise backward error a refined solution must reach (LU: ~1e-16 x growth)
MAX_REFINE = 4  # refinement steps before falling back to the LU
LU_AFTER_INDEFINITE = 8  # factorisations that go straight to the LU after a failed Cholesky


def band_of(indptr, indices) -> int:
    """Half-bandwidth max |i - j| of a CSC (or CSR) pattern."""
    cols = np.repeat(np.arange(indptr.size - 1), np.diff(indptr))
    return int(np.abs(indices - cols).max(initial=0))


def band_rule(n: int, bandwidth: int, nnz: int) -> bool:
    """The automatic choice of a banded factorisation: the band's storage n (b + 1) of one
    triangle holds at most 4 times the entries of K's triangle (nnz + n) / 2, so a band solver
    wastes at most that factor on zeros that a sparse factor would skip.  Holds for masts and
    cantilevers (the 400-bay mast: 1.9), fails for compact 3D meshes, whose RCM band is wide."""
    return n * (bandwidth + 1) <= 2.0 * (nnz + n)


@njit(cache=True)
def _fill(data, to_chol, partner, chol):
    """Scatter the symmetric part of B (the mean of (i, j) and (j, i)) into the lower Cholesky
    band; returns (max |B_ij - B_ji|, max |B_ij|)."""
    asym = 0.0
    big = 0.0
    for k in range(data.shape[0]):
        v = data[k]
        a = abs(v)
        if a > big:
            big = a
        p = partner[k]
        w = data[p] if p >= 0 else 0.0
        d = abs(v - w)
        if d > asym:
            asym = d
        if to_chol[k] >= 0:
            chol[to_chol[k]] = 0.5 * (v + w)
    return asym, big


@njit(cache=True)
def _fill_split(L, U, chol):
    """The symmetric part of B, given in split band storage (``L[d, j] = B_(j+d, j)``, the lower
    triangle; ``U[d, j] = B_(j, j+d)``, the upper one transposed, ``U[0]`` unused; both (b + 1, n)),
    into the lower Cholesky band ``chol`` ((b + 1, n)); returns (max |B_ij - B_ji|, max |B_ij|).
    The same values and operations as :func:`_fill` on B's pattern (entries of the band outside it
    are zeros on both sides), with both triangles read in order."""
    ldc = chol.shape[0]
    n = chol.shape[1]
    asym = 0.0
    big = 0.0
    for j in range(n):
        v = L[0, j]
        big = max(big, abs(v))
        chol[0, j] = 0.5 * (v + v)
        for d in range(1, ldc):
            v = L[d, j]
            w = U[d, j]
            big = max(big, abs(v), abs(w))
            asym = max(asym, abs(v - w))
            chol[d, j] = 0.5 * (v + w)
    return asym, big


@njit(cache=True, inline="always")
def _residual_maxima(r, rows, x, rhs):
    """(max |r_i|, max rows_i, max |x_i|, max |rhs_i|): the backward-error terms of :func:`refine`
    (inlined into the residual kernels; the kernels' plain-Python fallback calls its Python function)."""
    rmax = 0.0
    amax = 0.0
    xmax = 0.0
    bmax = 0.0
    for i in range(x.shape[0]):
        if abs(r[i]) > rmax:
            rmax = abs(r[i])
        if rows[i] > amax:
            amax = rows[i]
        if abs(x[i]) > xmax:
            xmax = abs(x[i])
        if abs(rhs[i]) > bmax:
            bmax = abs(rhs[i])
    return rmax, amax, xmax, bmax


@njit(cache=True)
def _residual_split(L, U, x, rhs, r):
    """:func:`_residual` for B in split band storage (:func:`_fill_split`): the same sums in the
    same order (each row's terms by ascending column; the band's zeros add nothing)."""
    ldc = L.shape[0]
    n = x.shape[0]
    for i in range(n):
        r[i] = rhs[i]
    rows = np.zeros(n)
    for j in range(n):
        xj = x[j]
        m = min(ldc, n - j)
        for d in range(m):  # column j: B_(j+d, j), rows j, j+1, ...
            v = L[d, j]
            r[j + d] -= v * xj
            rows[j + d] += abs(v)
        rj = r[j]
        sj = rows[j]
        for d in range(1, m):  # row j: B_(j, j+d), after its columns <= j
            v = U[d, j]
            rj -= v * x[j + d]
            sj += abs(v)
        r[j] = rj
        rows[j] = sj
    return _residual_maxima(r, rows, x, rhs)


@njit(cache=True)
def _split_positions(indptr, indices, b, gather, pos):
    """Positions in split band storage (:meth:`BandedFactor.band_positions`) of the entries at
    positions ``pos`` (any shape, -1: none) of the data of the matrix B was permuted from
    (``B.data = K.data[gather]``; ``gather`` empty: of B's data itself)."""
    n = indptr.shape[0] - 1
    nnz = indices.shape[0]
    to_split = np.empty(nnz, dtype=np.int64)
    for j in range(n):
        for k in range(indptr[j], indptr[j + 1]):
            i = indices[k]
            if i >= j:
                to_split[k] = (i - j) + j * (b + 1)
            else:
                to_split[k] = (b + 1) * n + (j - i) + i * (b + 1)
    if gather.shape[0] > 0:
        inv = np.empty(nnz, dtype=np.int64)
        for k in range(nnz):
            inv[gather[k]] = k
        comp = np.empty(nnz, dtype=np.int64)
        for k in range(nnz):
            comp[k] = to_split[inv[k]]
        to_split = comp
    flat = pos.ravel()
    out = np.empty(flat.shape[0], dtype=np.int64)
    for k in range(flat.shape[0]):
        p = flat[k]
        out[k] = to_split[p] if p >= 0 else -1
    return out.reshape(pos.shape)


@njit(cache=True)
def _split_to_lu(L, U, lu):
    """B from split band storage into LAPACK's LU band storage (B_ij at row 2b + i - j)."""
    ldc = L.shape[0]
    b = ldc - 1
    n = L.shape[1]
    for j in range(n):
        for k in range(b):
            lu[k, j] = 0.0
        for d in range(ldc):
            lu[2 * b + d, j] = L[d, j] if j + d < n else 0.0
            if d > 0:
                lu[2 * b - d, j] = U[d, j - d] if j - d >= 0 else 0.0
    return lu


@njit(cache=True)
def _scatter(data, to, out):
    for k in range(data.shape[0]):
        out[to[k]] = data[k]


@njit(cache=True)
def _residual(indptr, indices, data, x, b, r):
    """r = b - B x for a CSC matrix B; returns (max |r|, max row sum of |B|, max |x|, max |b|)."""
    n = x.shape[0]
    for i in range(n):
        r[i] = b[i]
    rows = np.zeros(n)
    for j in range(n):
        xj = x[j]
        for k in range(indptr[j], indptr[j + 1]):
            i = indices[k]
            r[i] -= data[k] * xj
            rows[i] += abs(data[k])
    return _residual_maxima(r, rows, x, b)


class BandedFactor:
    """Banded LAPACK factorisations of a CSC matrix with a fixed pattern (see module docstring).

    B : the CSC matrix (its pattern is fixed; :meth:`factorize` reads its current values).
    cholesky : try the Cholesky of the symmetric part when B is numerically symmetric (False: LU only).
    bandwidth : B's half-bandwidth, if known (computed otherwise).
    """

    name = "banded"

    def __init__(self, B, cholesky: bool = True, bandwidth: int | None = None):
        n = B.shape[0]
        self.n = n
        self.B = B
        self.b = b = band_of(B.indptr, B.indices) if bandwidth is None else int(bandwidth)
        self.allow_cholesky = cholesky
        # Fortran-ordered band storage, flat index i + j * ldab
        self._ld_chol = b + 1
        self._ld_lu = 3 * b + 1
        self._csc_maps = None  # (to_chol, to_lu, partner): where B's data entries go (CSC input)
        self._split = None  # B in split band storage, when assembled there
        self._from_band = False  # the last factorisation read B from the band storage
        self._chol = np.zeros((self._ld_chol, n), order="F")
        self._lu = np.zeros((self._ld_lu, n), order="F")
        self._r = np.zeros(n)
        self.kind = None  # "cholesky" or "lu": the factorisation in use
        self.asymmetry = np.nan  # max |B - B^T| / max |B| of the last factorisation
        self.refinements = 0  # refinement steps taken (all solves)
        self.fallbacks = 0  # Cholesky attempts that ended in the LU
        self._lu_only = 0  # factorisations left that skip the Cholesky
        self._ipiv = None
        self._factor = None
        self.nnz = 0

    # ------------------------------------------------------------------ band storage input
    def band_positions(self, pos, gather=None):
        """Positions in :attr:`band_values` of the entries at positions ``pos`` (-1: none) of B's
        data array (or, given ``gather``, of the data of the matrix K that B permutes:
        ``B.data = K.data[gather]``): an assembler then writes the element matrices straight into
        band storage (no CSC values, no scatter into the band per factorisation; :meth:`factorize_band`).

        The storage is split: the lower triangle as LAPACK's lower band (B_ij at (i - j) + j (b + 1),
        i >= j), then the upper one transposed (B_ij at (b + 1) n + (j - i) + i (b + 1), i < j), so
        that the symmetric part and the asymmetry are formed in one pass in storage order."""
        if self._split is None:
            self._split = np.zeros(2 * (self.b + 1) * self.n)
            m = (self.b + 1) * self.n
            self._L = self._split[:m].reshape((self.b + 1, self.n), order="F")
            self._U = self._split[m:].reshape((self.b + 1, self.n), order="F")
        g = np.zeros(0, np.int64) if gather is None else np.asarray(gather, dtype=np.int64)
        return setup_call(
            _split_positions,
            self.B.nnz + np.size(pos),
            self.B.indptr,
            self.B.indices,
            self.b,
            g,
            np.ascontiguousarray(pos, dtype=np.int64),
        )

    def _entries(self):
        """(column, row) of every entry of B's data array."""
        B = self.B
        return np.repeat(np.arange(self.n, dtype=np.int64), np.diff(B.indptr)), B.indices.astype(np.int64)

    def _maps(self):
        """Where each entry of B's data goes in the Cholesky band (-1: upper triangle) and the LU
        band, and the position of its transposed partner in B's data (-1: none); built on the
        first factorisation from B's data (an assembly into band storage never needs them)."""
        if self._csc_maps is None:
            cols, rows = self._entries()
            n, b = self.n, self.b
            to_chol = np.where(rows >= cols, (rows - cols) + cols * self._ld_chol, -1)
            to_lu = (2 * b + rows - cols) + cols * self._ld_lu
            keys = cols * n + rows  # CSC entries are sorted by (col, row)
            tkeys = rows * n + cols
            pos = np.searchsorted(keys, tkeys)
            pos[pos >= keys.size] = 0
            self._csc_maps = (to_chol, to_lu, np.where(keys[pos] == tkeys, pos, -1))
        return self._csc_maps

    @property
    def band_values(self):
        """The flat split band storage of B (:meth:`band_positions`)."""
        return self._split

    # ------------------------------------------------------------------ factorisations
    def factorize(self):
        """Factorise the current values of B; returns self (the factor object, with ``solve``).
        Raises RuntimeError on an exactly zero pivot of the LU (a singular matrix)."""
        self._chol.fill(0.0)
        to_chol, _, partner = self._maps()
        asym, big = _fill(self.B.data, to_chol, partner, self._chol.reshape(-1, order="F"))
        self._from_band = False
        return self._factor_symmetric_part(asym, big)

    def factorize_band(self):
        """:meth:`factorize` of the values written into :attr:`band_values` (bit for bit the same
        factorisation and solves as from B's data holding the same values)."""
        asym, big = _fill_split(self._L, self._U, self._chol)
        self._from_band = True
        return self._factor_symmetric_part(asym, big)

    def _factor_symmetric_part(self, asym, big):
        """The Cholesky of the symmetric part now in the Cholesky band if B is symmetric enough
        (relative asymmetry ``asym / big``) and it is positive definite, else the LU of B."""
        self.asymmetry = asym / big if big > 0 else 0.0
        if self.allow_cholesky and self._lu_only == 0 and self.asymmetry <= SYMMETRY_TOL:
            c, info = lapack.dpbtrf(self._chol, lower=1, overwrite_ab=1)
            if info == 0:
                self.kind, self._factor = "cholesky", c
                self.nnz = self.n * (self.b + 1)
                return self
            self._lu_only = LU_AFTER_INDEFINITE  # not positive definite: the LU for a while
        elif self._lu_only:
            self._lu_only -= 1
        self._factor_lu()
        return self

    def _factor_lu(self):
        """The band LU of B's current values (the band filled only here: 3b + 1 rows)."""
        b = self.b
        if self._from_band:
            _split_to_lu(self._L, self._U, self._lu)
        else:
            self._lu.fill(0.0)
            _scatter(self.B.data, self._maps()[1], self._lu.reshape(-1, order="F"))
        lu, ipiv, info = lapack.dgbtrf(self._lu, b, b, overwrite_ab=1)
        if info > 0:
            raise RuntimeError("Factor is exactly singular")
        if info < 0:  # pragma: no cover - an argument error is a bug here
            raise ValueError(f"dgbtrf: illegal argument {-info}")
        self.kind, self._factor, self._ipiv = "lu", lu, ipiv
        self.nnz = self.n * (2 * b + 1)

    def pivot_magnitudes(self):
        """|pivots| of the factorisation (diagonal of U, or the squared diagonal of the Cholesky
        factor), for the zero-pivot test."""
        if self.kind == "cholesky":
            return self._factor[0] ** 2
        return np.abs(self._factor[2 * self.b])

    # ------------------------------------------------------------------ solves
    def solve(self, rhs):
        rhs = np.asarray(rhs, dtype=float)
        if self.kind == "lu":
            x, info = lapack.dgbtrs(self._factor, self.b, self.b, rhs, self._ipiv)
            return x
        if self.asymmetry <= 0.1 * BACKWARD_TOL:
            # K equals its symmetric part to 1e-15: the Cholesky solve is backward stable for K
            # itself (backward error <= asymmetry + Cholesky's), no residual check needed
            return lapack.dpbtrs(self._factor, rhs, lower=1)[0]
        x, steps = refine(self._cholesky_solve, (self._L, self._U) if self._from_band else self.B, rhs, self._r)
        self.refinements += steps
        if x is not None:
            return x
        # the LU of B itself, kept for the other solves of this tangent
        self.fallbacks += 1
        self._factor_lu()
        return self.solve(rhs)

    def _cholesky_solve(self, v):
        return lapack.dpbtrs(self._factor, v, lower=1)[0]


def refine(solve, B, rhs, r):
    """Solve B x = rhs with ``solve`` (the factor of B's symmetric part) and iterative refinement
    against B until the normwise backward error ||rhs - B x|| / (||B|| ||x|| + ||rhs||) (infinity
    norms) is at most BACKWARD_TOL.  Returns (x, refinement steps), x None if a step did not
    contract the error tenfold (B too far from symmetric: use an LU).  B: a CSC matrix, or its
    split band storage (L, U) (:func:`_fill_split`).
    ``r``: scratch (n,)."""
    x = solve(rhs)
    last = np.inf
    split = isinstance(B, tuple)
    for step in range(MAX_REFINE + 1):  # (the maxima from the residual kernel: no numpy temporaries)
        if split:
            rmax, amax, xmax, bmax = _residual_split(B[0], B[1], x, rhs, r)
        else:
            rmax, amax, xmax, bmax = _residual(B.indptr, B.indices, B.data, x, rhs, r)
        eta = rmax / (amax * xmax + bmax + 1e-300)
        if eta <= BACKWARD_TOL or not math.isfinite(eta):
            return x, step
        if eta > 0.1 * last or step == MAX_REFINE:
            return None, step
        last = eta
        x = x + solve(r)
    return None, MAX_REFINE  # pragma: no cover - the loop returns
