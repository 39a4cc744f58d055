"""Linear systems: sparse LU (SuperLU) of the tangent, with a symmetric mode.

When every element family reports a symmetric tangent, SuperLU runs in symmetric
mode (minimum-degree ordering on A^T + A, diagonal pivoting preferred), the setting
scipy recommends for symmetric matrices.  A singular tangent raises
:class:`~femast.errors.SingularModelError` naming the DOFs of the mechanism.
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg
import scipy.sparse.linalg as spla

from ..errors import SingularModelError


class SparseLU:
    """Factorise once per iteration, solve for one or more right-hand sides."""

    def __init__(self, symmetric: bool = False):
        self.symmetric = symmetric
        self._lu = None

    def factorize(self, K):
        K = K.tocsc()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error", spla.MatrixRankWarning)
                if self.symmetric:
                    self._lu = spla.splu(K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                         options=dict(SymmetricMode=True))
                else:
                    self._lu = spla.splu(K)
        except (RuntimeError, spla.MatrixRankWarning) as exc:
            self._lu = None
            raise SingularModelError(str(exc)) from None
        d = self._lu.U.diagonal()
        if d.size and (not np.all(np.isfinite(d)) or np.min(np.abs(d)) <= 1e-13 * np.max(np.abs(d))):
            self._lu = None
            raise SingularModelError("zero pivot in the LU factorisation")

    def solve(self, rhs):
        x = self._lu.solve(np.asarray(rhs, dtype=float))
        if not np.all(np.isfinite(x)):
            raise SingularModelError("non-finite solution of the linear system")
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
