"""A dense LU through LAPACK for small tangents.

For a system of a few dozen to a couple of hundred DOFs the arithmetic of any factorisation is a
few microseconds; what costs is the bookkeeping around it (SuperLU's symbolic structures, the
band back-end's refinement against the unsymmetric tangent).  :class:`DenseFactor` scatters the
permuted matrix ``B`` into an n x n Fortran array and factorises it with ``dgetrf`` (LU with
partial pivoting: the exact Newton step for an unsymmetric tangent, no refinement), one LAPACK
call per factorisation and one ``dgetrs`` per solve.  The automatic choice of it is
:func:`femast.analysis.linalg.backends.choose` (:data:`DENSE_MAX_DOFS`).

Zero pivots: ``dgetrf`` reports an exactly zero one (``info > 0``); like SuperLU's diagonal test,
``|u_kk| <= 1e-13 max |u_kk|`` is a singular tangent (:meth:`DenseFactor.pivot_magnitudes`).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import lapack

from .banded import _scatter

DENSE_MAX_DOFS = 64  # the automatic choice takes the dense LU up to this many DOFs (see backends.choose)
DENSE_FORCED_MAX = 4000  # a forced dense LU beyond this many DOFs (128 MB) falls back to SuperLU


class DenseFactor:
    """Dense LAPACK LU (``dgetrf``/``dgetrs``) of a CSC matrix with a fixed pattern.

    B : the CSC matrix (its pattern is fixed; :meth:`factorize` reads its current values).
    """

    name = "dense"
    kind = "lu"

    def __init__(self, B):
        n = B.shape[0]
        self.n = n
        self.B = B
        cols = np.repeat(np.arange(n, dtype=np.int64), np.diff(B.indptr))
        self._to = B.indices.astype(np.int64) + cols * n  # Fortran order: row + col * n
        self._A = np.zeros((n, n), order="F")
        self._flat = self._A.reshape(-1, order="F")  # a view (Fortran-contiguous)
        self._lu = None
        self._piv = None
        self.nnz = n * n

    def factorize(self):
        """LU of the current values of B; returns self.  RuntimeError on an exactly zero pivot."""
        self._flat.fill(0.0)
        _scatter(self.B.data, self._to, self._flat)
        lu, piv, info = lapack.dgetrf(self._A, overwrite_a=1)
        if info > 0:
            raise RuntimeError("Factor is exactly singular")
        if info < 0:  # pragma: no cover - an argument error is a bug here
            raise ValueError(f"dgetrf: illegal argument {-info}")
        self._lu, self._piv = lu, piv
        return self

    def pivot_magnitudes(self):
        """|u_kk|, the diagonal of U (for the zero-pivot test)."""
        return np.abs(np.diagonal(self._lu))

    def solve(self, rhs):
        x, info = lapack.dgetrs(self._lu, self._piv, rhs)
        return x
