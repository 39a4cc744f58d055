"""Linear systems: sparse LU (SuperLU) of the tangent, with the ordering computed once.

The tangent keeps its sparsity pattern from one Newton iteration to the next (the assembler
fills the same CSR arrays in place), so the fill-reducing ordering -- the symbolic part that can
be reused with SuperLU as scipy exposes it -- is computed once per pattern:

* reverse Cuthill-McKee (RCM, best for slender, chain-like structures such as masts and
  cantilevers) is computed first, from the pattern alone.  When its envelope (the fill an LU
  without pivoting can have in that order) holds at most twice the entries of K, it is kept
  straight away: no ordering can give factors smaller than K itself, so no other could save
  more than that factor.  This test needs no values, so :meth:`SparseLU.analyse` can run it when
  the model is set up, with the assembly pattern (symbolic analysis, as in Abaqus' pre-processing);
* otherwise, on the first factorisation of the pattern, RCM and SuperLU's minimum degree on
  A^T + A are both tried on the actual values and the one with less fill is kept;
* every later factorisation of the same pattern gathers the values into the permuted CSC
  matrix P K P^T (one precomputed index, no CSR -> CSC conversion) and factorises it with the
  NATURAL column order in SuperLU's symmetric mode (diagonal pivots preferred, the structure of
  femast tangents is symmetric even when the values are not);
* a tangent whose pattern differs -- the reduced tangent of a constrained model, T^T K T, drops
  exact zeros from one iteration to the next -- is laid out on this master pattern with zeros
  where it has no entries; only a tangent with entries outside it makes the master pattern the
  union of the two, analysed once more (with the ordering kind chosen the first time).

Pivoting: with a symmetric tangent (every family symmetric) the diagonal is always taken
(``diag_pivot_thresh=0``, as before); otherwise a row interchange happens when the diagonal is
below 1 % of the largest entry of its column (threshold partial pivoting, MUMPS' default).
``ordering="colamd"`` restores scipy's default (COLAMD, partial pivoting, no reuse).

A singular tangent raises :class:`~femast.errors.SingularModelError` (the analysis names the DOFs
of the mechanism through :func:`mechanism_dofs`): on the first factorisation of a pattern (so a
model with a mechanism fails at its first iteration, as before) the diagonal of U is tested; on
later ones that test -- which needs scipy to build L and U as sparse matrices, ~10 % of a
factorisation -- runs only when a solution is amplified by more than 1e11 (``pivot_check="always"``
tests every factorisation).
"""

from __future__ import annotations

import math
from time import perf_counter

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

from ...errors import ModelError, SingularModelError
from . import backends
from .ordering import entry_keys, permuted, permuted_positions, rcm, same_pattern, try_orderings
from .pivots import PivotChecks

try:  # scipy's SuperLU binding, called directly for the matrix refactorised every iteration
    from scipy.sparse.linalg._dsolve._superlu import gstrf as _gstrf
except ImportError:  # pragma: no cover - a scipy that moved it: splu is used instead
    _gstrf = None
_DIRECT = {"gstrf": _gstrf}  # set to None if the binding's signature ever differs

ORDERINGS = ("auto", "rcm", "mmd", "colamd")
BACKENDS = backends.NAMES
_FLOAT_MAX = float(np.finfo(float).max)


@njit(cache=True)
def _permute(rhs, perm, b):
    """b = rhs[perm] in one pass; returns max |rhs| (the amplification test's scale)."""
    m = 0.0
    for i in range(perm.shape[0]):
        v = rhs[perm[i]]
        b[i] = v
        a = abs(v)
        if a > m:
            m = a
    return m


@njit(cache=True)
def _unpermute(y, perm, x):
    """x[perm] = y in one pass; returns max |x|, or NaN as soon as an entry is not finite."""
    m = 0.0
    for i in range(y.shape[0]):
        v = y[i]
        a = abs(v)
        if not a <= 1.7976931348623157e308:  # NaN or inf
            return math.nan
        x[perm[i]] = v
        if a > m:
            m = a
    return m


class SparseLU(PivotChecks):
    """Factorise once per iteration, solve for one or more right-hand sides.

    symmetric : every element family has a symmetric tangent (diagonal pivoting only).
    ordering : "auto" (the better of "rcm" and "mmd" on the first factorisation of a pattern),
        "rcm", "mmd" (minimum degree on A^T + A), or "colamd" (scipy's default, no reuse).
    pivot_threshold : relative size below which a diagonal pivot is replaced (unsymmetric case).
    pivot_check : "always": test every factorisation for a zero pivot (|u_kk| <= 1e-13 max |u_kk|);
        "auto" (default): test the first factorisation of each pattern, and later ones only when a
        solution is amplified enough (|x| max|u_kk| > 1e11 |b|) for such a pivot to be possible.
    backend : who factorises the permuted matrix (:mod:`femast.analysis.linalg.backends`): "auto" (the
        rule of :func:`~femast.analysis.linalg.backends.choose`), "superlu", "banded", "dense", "cholmod",
        "pardiso".  An optional back-end that is not installed falls back to SuperLU with a
        warning saying how to install it.
    """

    def __init__(
        self,
        symmetric: bool = False,
        ordering: str = "auto",
        pivot_threshold: float = 0.01,
        pivot_check: str = "auto",
        backend: str = "auto",
    ):
        if ordering not in ORDERINGS:
            raise ValueError(f"ordering must be one of {ORDERINGS}, not {ordering!r}")
        if pivot_check not in ("auto", "always"):
            raise ValueError(f"pivot_check must be 'auto' or 'always', not {pivot_check!r}")
        if backend not in BACKENDS:
            raise ModelError(f"linear solver back-end {backend!r} is not one of {BACKENDS}")
        self.backend = backend
        if backend == "banded" and ordering == "auto":
            ordering = "rcm"  # the band comes from the RCM order
        self._engine = None  # a non-SuperLU factor object working on self._B, or None
        self.engine = "superlu"  # name of the back-end in use
        self.pivot_check = pivot_check
        self._dmax = None  # largest |pivot| at the last zero-pivot test
        self._checked = False  # zero-pivot test done for the current factorisation
        self.symmetric = symmetric
        self.ordering = ordering
        self.pivot_threshold = 0.0 if symmetric else float(pivot_threshold)
        self._lu = None
        self._perm = None  # symmetric permutation p: B = K[p][:, p]
        self._B = None  # permuted CSC matrix, data refilled each factorisation
        self._gather = None  # B.data = K.data[gather]
        self._B_int = None  # (indices, indptr, and both as C ints) of B, for SuperLU
        self._pattern = None  # (shape, indptr, indices) of the master pattern the ordering belongs to
        self._master_keys = None  # row * n + col of its entries, ascending
        self._sub = None  # the last pattern seen inside the master one, and its positions there
        self._sub_ids = None  # (indptr, indices, size) objects last found equal to that pattern
        self._sub_data = None  # its values and a trailing zero, and the permuted matrix's data
        self._sub_gather = None  # as indices into them (the trailing zero where it has no entry)
        self.analyses = 0  # orderings computed (1 for a fixed-pattern run)
        self.chosen = None  # name of the ordering in use
        self._validated = None  # (indptr, indices) objects last found equal to the master pattern
        self.superlu_seconds = 0.0  # wall time inside SuperLU (kept factorisations + solves), s
        self.factorizations = 0  # numeric factorisations kept (trial orderings not counted)
        self.layout = 0  # bumped whenever the permuted matrix (its pattern or ordering) changes
        self.confirmations = 0  # suspect factorisations SuperLU found regular (and replaced)
        self._confirmed = None  # SuperLU's factorisation that replaced a suspect one

    # ------------------------------------------------------------------ symbolic part
    def _is_master(self, K):
        """K has the master pattern.  The assembler refills the same CSR arrays every iteration, so
        arrays once found equal are recognised by identity (same objects, same lengths)."""
        v = self._validated
        if v is not None and v[0] is K.indptr and v[1] is K.indices and v[2] == K.indices.size:
            return True
        if same_pattern(self._pattern, K):
            self._validated = (K.indptr, K.indices, K.indices.size)
            return True
        return False

    def analyse(self, K):
        """Symbolic analysis from the pattern of K alone (values unused), if RCM is the ordering to
        keep (see the module docstring); otherwise it is left to the first factorisation.
        Returns the ordering chosen, or None."""
        if self.ordering not in ("auto", "rcm"):
            return None
        K = K if K.format == "csr" else K.tocsr()
        perm, enough = rcm(K)
        if self.ordering == "auto" and not enough:
            return None
        self.analyses += 1
        self._set_master(K)
        self.chosen = "rcm"
        self._perm = perm
        self._B, self._gather = permuted(K, perm)
        self._choose_engine()
        return self.chosen

    def _choose_engine(self):
        """The back-end for the current permuted matrix (a new layout: a new choice)."""
        self._engine = backends.make(
            self.backend, self._B, self.chosen, self.symmetric, lambda B: self._factor_permuted(B, superlu=True)
        )
        self.engine = "superlu" if self._engine is None else self._engine.name

    def has_pattern(self, K) -> bool:
        """True if K has exactly the pattern the current ordering was analysed for."""
        return self._pattern is not None and self._is_master(K)

    def permuted_positions(self, pos):
        """Positions in :attr:`values` of the entries at positions ``pos`` (-1: none) of the data
        array of a matrix with the master pattern: an assembler can then fill the solver's
        permuted matrix directly (no gather per factorisation; see :meth:`factorize_values`)."""
        if self._gather is None:
            raise RuntimeError("SparseLU.permuted_positions: no pattern analysed yet")
        if self._band_input():  # the band back-end: straight into its band storage
            return self._engine.band_positions(pos, self._gather)
        return permuted_positions(self._gather, pos)

    def _band_input(self):
        """The back-end takes the permuted matrix in its own band storage (the banded one)."""
        return self._engine is not None and hasattr(self._engine, "band_positions")

    @property
    def values(self):
        """The values of the permuted matrix that :meth:`factorize_values` factorises (write them
        in place, at the positions given by :meth:`permuted_positions`): the permuted CSC matrix's
        data, or the band back-end's band storage."""
        return self._engine.band_values if self._band_input() else self._B.data

    def factorize_values(self):
        """Factorise the matrix whose values were written into :attr:`values` (same checks and
        errors as :meth:`factorize`)."""

        def step():
            if self._band_input():
                self._lu = self._timed(self._engine.factorize_band)
            else:
                self._lu = self._timed(self._factor_permuted, self._B)
            return False

        self._guarded(step)

    def _set_master(self, K):
        self.layout += 1
        self._pattern = (K.shape, K.indptr.copy(), K.indices.copy())
        self._master_keys = entry_keys(K.shape, K.indptr, K.indices)
        self._sub = None
        self._sub_ids = None
        self._validated = None

    def _positions(self, K):
        """Positions of K's entries in the master pattern, or None if one is outside it."""
        keys = entry_keys(K.shape, K.indptr, K.indices)
        pos = np.searchsorted(self._master_keys, keys)
        pos[pos >= self._master_keys.size] = 0
        if not np.array_equal(self._master_keys[pos], keys):
            return None
        return pos

    def _factor_permuted(self, B, superlu=False):
        """LU of the permuted matrix B in its own (NATURAL) column order.  The matrix refactorised
        every iteration (:attr:`values`) goes straight to scipy's SuperLU binding with its index
        arrays converted once: ``splu`` checks and converts them on every call, ~30 us, 2 % of a
        40-bay iteration.  The options are those ``splu`` passes."""
        if self._engine is not None and B is self._B and not superlu:
            return self._engine.factorize()
        if _DIRECT["gstrf"] is not None and B is self._B:
            if self._B_int is None or self._B_int[0] is not B.indices or self._B_int[1] is not B.indptr:
                self._B_int = (B.indices, B.indptr, B.indices.astype(np.intc), B.indptr.astype(np.intc))
            try:
                return _DIRECT["gstrf"](
                    B.shape[0],
                    B.nnz,
                    B.data,
                    self._B_int[2],
                    self._B_int[3],
                    csc_construct_func=sp.csc_array,
                    ilu=False,
                    options=dict(
                        DiagPivotThresh=self.pivot_threshold,
                        ColPerm="NATURAL",
                        PanelSize=None,
                        Relax=None,
                        SymmetricMode=True,
                    ),
                )
            except TypeError:  # pragma: no cover - another scipy signature: use splu from now on
                _DIRECT["gstrf"] = None
        return spla.splu(
            B, permc_spec="NATURAL", diag_pivot_thresh=self.pivot_threshold, options=dict(SymmetricMode=True)
        )

    def _timed(self, factor, *args):
        """``factor(*args)``: a kept numeric factorisation, its wall time added to superlu_seconds."""
        t0 = perf_counter()
        lu = factor(*args)
        self.superlu_seconds += perf_counter() - t0
        self.factorizations += 1
        return lu

    def _analyse(self, K):
        """Choose the ordering for the pattern of K (the master pattern from now on); returns the
        LU of K in that ordering.  The first pattern tries every candidate ordering; a later one
        (the union of the master and a tangent with entries outside it) reuses the kind chosen."""
        self.analyses += 1
        kinds = [self.chosen] if self.chosen else (["rcm", "mmd"] if self.ordering == "auto" else [self.ordering])
        best, first, error = try_orderings(K, kinds, self._factor_permuted, self.pivot_threshold)
        self._set_master(K)
        if best is None:  # singular: keep an ordering so that the pattern is not analysed again
            if first is None:
                perm = np.arange(K.shape[0])
                first = (kinds[0], perm) + permuted(K, perm)
            self.chosen, self._perm, self._B, self._gather = first
            self._choose_engine()
            raise error
        self.chosen, self._perm, self._B, self._gather = best[1]
        self._choose_engine()
        if self._engine is not None:  # the trial was SuperLU's: factorise again with the back-end
            return self._timed(self._factor_permuted, self._B)
        self.superlu_seconds += best[3]  # the kept factorisation; the trial of the other is overhead
        self.factorizations += 1
        return best[2]

    def _master_data(self, K):
        """(values, index) with values[index] the permuted matrix's data for K's values, or None
        after a new analysis (which has factorised already; the LU is in self._lu).

        K with the master pattern gives (K.data, gather).  K with a pattern inside it (a stabilised
        step's damped tangent, or a reduced tangent after the union of two patterns was analysed)
        gives its values with a trailing zero and an index composed once per pattern: one copy and
        one gather per factorisation (the same values as a scatter onto the master pattern)."""
        if self._is_master(K):
            return K.data, self._gather
        ids = self._sub_ids
        if not (ids is not None and ids[0] is K.indptr and ids[1] is K.indices and ids[2] == K.indices.size):
            if not same_pattern(self._sub, K):
                pos = self._positions(K)
                if pos is None:  # entries outside the master pattern: analyse the union once
                    ones = sp.csr_matrix((np.ones(K.nnz), K.indices, K.indptr), shape=K.shape)
                    master = sp.csr_matrix(
                        (np.ones(self._master_keys.size), self._pattern[2], self._pattern[1]), shape=K.shape
                    )
                    union = (ones + master).tocsr()
                    union.sort_indices()
                    union.data[:] = 0.0
                    self._master_keys = entry_keys(union.shape, union.indptr, union.indices)
                    union.data[self._positions(K)] = K.data
                    self._lu = self._analyse(union)
                    return None
                self._sub = (K.shape, K.indptr.copy(), K.indices.copy())
                where = np.full(self._master_keys.size, K.nnz, dtype=np.int64)  # K.nnz: the trailing zero
                where[pos] = np.arange(K.nnz)
                self._sub_gather = where[self._gather]
                self._sub_data = np.zeros(K.nnz + 1)
            self._sub_ids = (K.indptr, K.indices, K.indices.size)  # recognised by identity from now on
        self._sub_data[:-1] = K.data
        return self._sub_data, self._sub_gather

    # ------------------------------------------------------------------ numeric part
    def factorize(self, K):
        self._guarded(lambda: self._factorize_matrix(K))

    def _factorize_matrix(self, K):
        """Set self._lu to the LU of K; returns True if K's pattern was (re)analysed."""
        if self.ordering == "colamd":
            self._perm = None
            self._lu = self._timed(spla.splu, K.tocsc())
            return True
        K = K if K.format == "csr" else K.tocsr()
        if not K.has_canonical_format:
            K = K.copy()
            K.sum_duplicates()
        if self._pattern is None:
            self._lu = self._analyse(K)
            return True
        data = self._master_data(K)
        if data is None:  # a new analysis, which has factorised already
            return True
        np.take(data[0], data[1], out=self._B.data)
        self._lu = self._timed(self._factor_permuted, self._B)
        return False

    def solve(self, rhs):
        rhs = np.asarray(rhs, dtype=float)
        if self._perm is None:
            t0 = perf_counter()
            x = self._lu.solve(rhs)
            self.superlu_seconds += perf_counter() - t0
            xmax = float(np.abs(x).max(initial=0.0)) if np.isfinite(x).all() else math.nan
        else:
            b = np.empty(rhs.shape[0])
            rmax = _permute(rhs, self._perm, b)
            t0 = perf_counter()
            y = self._lu.solve(b)
            self.superlu_seconds += perf_counter() - t0
            x = np.empty_like(y)
            xmax = _unpermute(y, self._perm, x)
        if not xmax <= _FLOAT_MAX:
            raise SingularModelError("non-finite solution of the linear system")
        if not self._checked and xmax * self._dmax > 1e11 * (
            np.abs(rhs).max(initial=0.0) if self._perm is None else rmax
        ):
            # an amplification this large means a pivot within ~1e-11 of the largest: test them
            self._check_pivots()
        return x


def mechanism_dofs(K, max_dense: int = 4000, n_show: int = 6):
    """Equation numbers that take part in the near-null space of ``K`` (largest components of
    the singular vector of the smallest singular value), or None if K is too large to check."""
    n = K.shape[0]
    diag = np.abs(K.diagonal())
    zero = np.flatnonzero(diag <= 1e-14 * max(diag.max(initial=0.0), 1e-300))
    if zero.size:
        return zero[:n_show]
    if n > max_dense:
        return None
    A = K.toarray()
    scale = 1.0 / np.sqrt(np.maximum(diag, 1e-300))
    A = A * scale[:, None] * scale[None, :]
    _, s, vt = scipy.linalg.svd(A)
    v = np.abs(vt[-1] * scale)
    v /= v.max()
    return np.argsort(-v)[:n_show]
