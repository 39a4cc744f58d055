"""Linear-solver back-ends for the tangent, and the rule that picks one per model.

:class:`~femast.analysis.linalg.linear.SparseLU` computes the fill-reducing ordering and refills the
permuted matrix ``B`` every iteration; a back-end factorises ``B``:

=========== ==================================================== ===============================
name        what                                                 needs
=========== ==================================================== ===============================
"superlu"   scipy's SuperLU (threshold pivoting, symmetric mode)  scipy (always there)
"banded"    LAPACK band Cholesky of the symmetric part, refined   scipy (always there)
            against B, or band LU with partial pivoting
            (:mod:`femast.analysis.linalg.banded`)
"dense"     LAPACK dense LU with partial pivoting (``dgetrf``)     scipy (always there)
            (:mod:`femast.analysis.linalg.dense`)
"cholmod"   CHOLMOD's supernodal Cholesky of the symmetric part,  ``pip install femast[cholmod]``
            refined against B; SuperLU when B is unsymmetric or   (scikit-sparse; Debian:
            not positive definite                                 ``apt-get install libsuitesparse-dev``)
"pardiso"   MKL PARDISO, unsymmetric LU with the analysis once    ``pip install femast[pardiso]``
=========== ==================================================== ===============================

**The automatic choice** (``backend="auto"``, :func:`choose`): the dense LU for a system of at most
:data:`~femast.analysis.linalg.dense.DENSE_MAX_DOFS` (64) DOFs (below that a factorisation's
arithmetic is a few microseconds and the dense LU needs the fewest calls: no symbolic structures, no
refinement; ``python benchmarks/small_systems.py``); otherwise the band back-end when the
ordering is reverse Cuthill-McKee and its band is narrow (:func:`~femast.analysis.linalg.banded.band_rule`:
the band storage of one triangle, n (b + 1), at most 4x the entries of K's triangle: the masts);
otherwise PARDISO when it is installed and the model has at least :data:`PARDISO_MIN_DOFS` DOFs
(the ADAM mast: 1.0-2.0x faster than SuperLU); otherwise SuperLU.  CHOLMOD is never chosen
automatically (slower than the band on the masts, and most tangents of the unbanded models are
unsymmetric).  Measurements: ``python benchmarks/solver_backends.py``, docs/performance.md.  A
back-end named but not installed falls back to SuperLU with a warning that says how to install it.
"""

from __future__ import annotations

import warnings

import numpy as np

from .banded import SYMMETRY_TOL, BandedFactor, band_of, band_rule, refine
from .dense import DENSE_FORCED_MAX, DENSE_MAX_DOFS, DenseFactor

NAMES = ("auto", "superlu", "banded", "dense", "cholmod", "pardiso")
PARDISO_MIN_DOFS = 1000  # the automatic choice takes PARDISO (when installed) from this size on
THREADS = 1  # MKL threads of PARDISO
INSTALL = {
    "cholmod": "pip install 'femast[cholmod]' (scikit-sparse; on Debian first: apt-get install libsuitesparse-dev)",
    "pardiso": "pip install 'femast[pardiso]' (pypardiso, Intel MKL)",
}


def available(name: str) -> tuple[bool, str]:
    """(installed, why not) for a back-end name."""
    try:
        if name == "cholmod":
            import sksparse.cholmod  # noqa: F401
        elif name == "pardiso":
            import pypardiso  # noqa: F401
    except (ImportError, OSError) as exc:
        return False, f"{exc}"
    return True, ""


def choose(backend: str, B, ordering: str) -> str:
    """The back-end to use for the permuted matrix B (CSC, in the order ``ordering``)."""
    n = B.shape[0]
    if backend == "auto":
        if n <= DENSE_MAX_DOFS:
            return "dense"
        if ordering == "rcm" and band_rule(n, _band(B), B.nnz):
            return "banded"
        if n >= PARDISO_MIN_DOFS and available("pardiso")[0]:
            return "pardiso"
        return "superlu"
    if backend in ("cholmod", "pardiso"):
        ok, why = available(backend)
        if not ok:
            warnings.warn(
                f"linear solver back-end '{backend}' is not installed ({why}); using SuperLU. "
                f"Install it with: {INSTALL[backend]}",
                stacklevel=4,
            )
            return "superlu"
    if backend == "dense" and n > DENSE_FORCED_MAX:
        warnings.warn(
            f"linear solver back-end 'dense' for {n} DOFs (an {n} x {n} matrix, "
            f"{8 * n * n / 1e9:.2g} GB) is beyond its limit of {DENSE_FORCED_MAX} DOFs; using SuperLU",
            stacklevel=4,
        )
        return "superlu"
    if backend == "banded" and ordering != "rcm":
        return "superlu"  # a band needs the RCM order (forced by SparseLU(backend="banded"))
    return backend


def _band(B) -> int:
    """The half-bandwidth of B, computed once per matrix object (the rule and the band back-end
    both need it)."""
    cached = getattr(B, "_femast_band", None)
    if cached is None or cached[0] is not B.indices:
        cached = (B.indices, band_of(B.indptr, B.indices))
        B._femast_band = cached
    return cached[1]


def make(backend: str, B, ordering: str, symmetric: bool, superlu_factor):
    """A factor object for B (``factorize()`` -> object with ``solve``, ``nnz``, ``pivot_magnitudes``),
    or None for SuperLU.  ``superlu_factor(B)``: SuperLU's LU of B (the fall-back of CHOLMOD)."""
    name = choose(backend, B, ordering)
    if name == "banded":
        return BandedFactor(B, bandwidth=_band(B))
    if name == "dense":
        return DenseFactor(B)
    if name == "cholmod":
        return CholmodFactor(B, superlu_factor)
    if name == "pardiso":
        return PardisoFactor(B)
    return None


def _partner(B):
    """Position of the (j, i) entry of each (i, j) entry of a CSC matrix (-1: not in the pattern)."""
    n = B.shape[0]
    cols = np.repeat(np.arange(n, dtype=np.int64), np.diff(B.indptr))
    rows = B.indices.astype(np.int64)
    keys = cols * n + rows
    tkeys = rows * n + cols
    pos = np.searchsorted(keys, tkeys)
    pos[pos >= keys.size] = 0
    return np.where(keys[pos] == tkeys, pos, -1)


class CholmodFactor:
    """CHOLMOD's supernodal Cholesky of (B + B^T) / 2 (symbolic analysis once), each solve refined
    against B; SuperLU's LU when B is not numerically symmetric or not positive definite."""

    name = "cholmod"

    def __init__(self, B, superlu_factor):
        import scipy.sparse as sp
        from sksparse.cholmod import analyze

        self.B = B
        self._superlu = superlu_factor
        partner = _partner(B)
        if np.any(partner < 0):  # structurally unsymmetric: (B + B^T) / 2 on the union pattern
            ones = sp.csc_matrix((np.ones(B.nnz), B.indices, B.indptr), shape=B.shape)
            U = (ones + ones.T).tocsc()
            U.sort_indices()
            n = B.shape[0]
            keys = np.repeat(np.arange(n, dtype=np.int64), np.diff(U.indptr)) * n + U.indices
            cols = np.repeat(np.arange(n, dtype=np.int64), np.diff(B.indptr))
            self._at = np.searchsorted(keys, cols * n + B.indices)  # (i, j) of B in S
            self._at_t = np.searchsorted(keys, B.indices.astype(np.int64) * n + cols)  # (j, i)
            self._S = sp.csc_matrix((np.ones(U.nnz), U.indices, U.indptr), shape=B.shape)
            self._partner = None
        else:
            self._S = sp.csc_matrix((np.ones(B.nnz), B.indices, B.indptr), shape=B.shape)
            self._partner = partner
        self._analysis = analyze(self._S, mode="supernodal")
        self._r = np.zeros(B.shape[0])
        self.kind = None
        self._lu = None
        self.nnz = 0
        self.refinements = 0
        self.fallbacks = 0

    def factorize(self):
        from sksparse.cholmod import CholmodNotPositiveDefiniteError

        d = self.B.data
        S = self._S.data
        if self._partner is not None:
            np.multiply(0.5, d + d[self._partner], out=S)
            asym = np.abs(d - d[self._partner]).max(initial=0.0)
        else:
            S[:] = 0.0
            np.add.at(S, self._at, 0.5 * d)
            np.add.at(S, self._at_t, 0.5 * d)
            asym = 2.0 * np.abs(S[self._at] - d).max(initial=0.0)
        big = np.abs(d).max(initial=0.0)
        if big > 0 and asym <= SYMMETRY_TOL * big:
            try:
                self._analysis.cholesky_inplace(self._S)
                self.kind, self._lu = "cholesky", None
                self.nnz = int(self._analysis.L().nnz)
                return self
            except CholmodNotPositiveDefiniteError:
                pass
        return self._to_lu()

    def _to_lu(self):
        self.kind, self._lu = "lu", self._superlu(self.B)
        self.nnz = int(self._lu.nnz)
        return self

    def pivot_magnitudes(self):
        if self.kind == "cholesky":
            return np.abs(self._analysis.D())
        return np.abs(self._lu.U.diagonal())

    def solve(self, rhs):
        rhs = np.asarray(rhs, dtype=float)
        if self.kind == "lu":
            return self._lu.solve(rhs)
        x, steps = refine(self._analysis.solve_A, self.B, rhs, self._r)
        self.refinements += steps
        if x is None:
            self.fallbacks += 1
            self._to_lu()
            return self._lu.solve(rhs)
        return x


class PardisoFactor:
    """MKL PARDISO (real unsymmetric, ``mtype=11``): the analysis (phase 11) once per pattern,
    the numeric factorisation (22) per tangent, the solve (33) per right-hand side.  B's CSC
    arrays are passed as the CSR arrays of B^T with the transposed solve (``iparm[12] = 2``).

    PARDISO replaces pivots below 1e-13 of the scale by +-1e-13 instead of stopping; a tangent
    with such a perturbed pivot is reported as singular (:meth:`pivot_magnitudes`)."""

    name = "pardiso"

    def __init__(self, B):
        import ctypes

        import pypardiso

        self._ps = ps = pypardiso.PyPardisoSolver(mtype=11)
        try:  # one thread: reproducible bits from run to run, and no waiting on a shared core
            ps.libmkl.MKL_Set_Num_Threads(ctypes.c_int(THREADS))
        except AttributeError:  # pragma: no cover - an MKL without the symbol
            pass
        self.B = B
        n = B.shape[0]
        ps.iparm[:] = 0
        ps.iparm[0] = 1  # user-set iparm
        ps.iparm[1] = 2  # nested dissection (METIS) ordering
        ps.iparm[9] = 13  # pivot perturbation 1e-13
        ps.iparm[10] = 1  # scaling
        ps.iparm[11] = 2  # transposed solve: the CSC arrays are B^T's CSR arrays
        ps.iparm[12] = 1  # weighted matching
        ps.iparm[34] = 1  # zero-based indices
        ps.iparm[17] = -1  # report the entries of the factors
        self._ia = B.indptr.astype(np.int32)
        self._ja = B.indices.astype(np.int32)
        self._n = ctypes.c_int32(n)
        self._ct = ctypes
        self._x = np.zeros(n)
        self.kind = "lu"
        self.nnz = 0
        self._call(11, np.zeros(n))

    def _call(self, phase, b):
        ct = self._ct
        ps = self._ps
        err = ct.c_int32(0)
        i32 = ct.POINTER(ct.c_int32)
        f64 = ct.POINTER(ct.c_double)
        x = np.zeros_like(b)
        ps._mkl_pardiso(
            ps.pt.ctypes.data_as(ct.POINTER(ps._pt_type[0])),
            ct.byref(ct.c_int32(1)),
            ct.byref(ct.c_int32(1)),
            ct.byref(ct.c_int32(11)),
            ct.byref(ct.c_int32(phase)),
            ct.byref(self._n),
            self.B.data.ctypes.data_as(f64),
            self._ia.ctypes.data_as(i32),
            self._ja.ctypes.data_as(i32),
            ps.perm.ctypes.data_as(i32),
            ct.byref(ct.c_int32(1)),
            ps.iparm.ctypes.data_as(i32),
            ct.byref(ct.c_int32(0)),
            b.ctypes.data_as(f64),
            x.ctypes.data_as(f64),
            ct.byref(err),
        )
        if err.value == -4:
            raise RuntimeError("Factor is exactly singular (PARDISO: zero pivot)")
        if err.value != 0:
            raise RuntimeError(f"PARDISO error {err.value}")
        return x

    def factorize(self):
        self._call(22, np.zeros(self.B.shape[0]))
        self.nnz = int(self._ps.iparm[17])
        return self

    def pivot_magnitudes(self):
        return np.array([0.0, 1.0]) if self._ps.iparm[13] > 0 else np.ones(1)

    def solve(self, rhs):
        return self._call(33, np.ascontiguousarray(rhs, dtype=float))

    def __del__(self):  # release MKL's memory for this factorisation
        try:
            self._call(-1, np.zeros(self.B.shape[0]))
        except Exception:  # pragma: no cover - interpreter shutdown
            pass
