"""Zero pivots judged on the model: when is a factorised tangent singular?

A factorisation meets a zero pivot when the tangent has a mechanism, and only then; in floating
point, a pivot is "zero" when it is round-off.  Round-off against what?  Against the largest pivot
of the model, the test said before: a chain of springs from 1e12 N/m down to 1e-3 N/m, or a
telescoping mast with stiff struts, soft torsion pads and a bearing plane a few millimetres from a
mesh node, has pivots 15 orders of magnitude apart and is perfectly solvable, yet failed it.  Here a
pivot is judged against its own DOF:

* :func:`suspect`: a pivot is suspect when it is round-off against the stiffness of its own DOF
  (``|u_kk| <= PIVOT_TOL |B_kk|``, the diagonal of the factorised matrix), or below double
  precision against the largest pivot (``|u_kk| <= EPS_TOL max |u|``: nothing can be resolved
  there, whatever the DOF);
* :func:`confirm`: a suspect factorisation is confirmed by SuperLU with partial pivoting (COLAMD
  order, a row interchange whenever a diagonal is below its column's largest entry): it stops at an
  exactly zero pivot, or one of its pivots is round-off against the largest entry of its column
  (or below double precision against its largest pivot).
  If SuperLU factorises the tangent with sound pivots, its factorisation is used instead: a stiffness
  contrast the first pivot sequence could not resolve is not a mechanism.

A real mechanism (a frame without a diagonal, a beam free to twist) has a pivot that is round-off
against its own DOF's stiffness in any order, and is still refused and named
(tests/analysis/test_singularity_judged_on_the_model.py).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as spla

from ...errors import SingularModelError

PIVOT_TOL = 1e-13  # a pivot this small against its DOF's stiffness (or column) is round-off: a mechanism
EPS_TOL = 1e-16  # a pivot this small against the largest one is below double precision whatever its DOF


def suspect(d, diag) -> bool:
    """Whether pivot magnitudes ``d`` may be a mechanism's: non-finite, round-off against their DOF's
    diagonal ``diag`` of the factorised matrix (same order), or against the largest pivot to double
    precision.  ``diag`` None (a back-end pivoting in an order of its own): the relative test
    against the largest pivot at PIVOT_TOL."""
    if not np.all(np.isfinite(d)):
        return True
    big = float(np.max(d))
    if diag is None:
        return float(np.min(d)) <= PIVOT_TOL * big
    return bool(np.any(d <= np.maximum(PIVOT_TOL * diag, EPS_TOL * big)))


def confirm(B):
    """SuperLU's partial-pivoting LU of ``B`` (a sparse matrix) and its largest pivot, if its pivots are
    sound against their columns; None if B is singular for it too."""
    B = B.tocsc()
    try:
        lu = spla.splu(B, permc_spec="COLAMD", diag_pivot_thresh=1.0)
    except RuntimeError:  # an exactly zero pivot
        return None
    u = np.abs(lu.U.diagonal())
    colmax = np.abs(B).max(axis=0).toarray().ravel()[lu.perm_c]
    if not np.all(np.isfinite(u)) or np.any(u <= np.maximum(PIVOT_TOL * colmax, EPS_TOL * np.max(u))):
        return None
    return lu, float(np.max(u, initial=0.0))


class PivotChecks:
    """The zero-pivot checks of :class:`~femast.analysis.linalg.linear.SparseLU` (a mixin: it uses the
    solver's ``_lu``, ``_B``, ``_engine``, ``_dmax``, ``_checked``, ``_confirmed``, ``confirmations``
    and ``pivot_check``)."""

    def _guarded(self, step):
        """Run ``step()`` (sets self._lu; True if the pattern was newly analysed) with SuperLU's
        failures raised as SingularModelError, then the zero-pivot test when it is due.  A
        factorisation that stopped at an exactly zero pivot is confirmed by SuperLU first
        (:meth:`_confirm_singular`): another pivot sequence may well get through."""
        try:  # SuperLU reports a singular matrix as RuntimeError (only spsolve warns instead)
            analysed = step()
        except RuntimeError as exc:
            self._lu = None
            if self._B is None or self._confirm_singular():
                raise SingularModelError(str(exc)) from None
            return
        self._checked = False
        if analysed or self.pivot_check == "always" or self._dmax is None:
            self._check_pivots()

    def _check_pivots(self):
        """Zero-pivot test of the factorisation (scipy builds L and U as CSC matrices for SuperLU's:
        ~10 % of a factorisation), judged on the model (:mod:`~femast.analysis.linalg.pivots`): a
        suspect factorisation is confirmed by SuperLU's partial pivoting before the tangent is called
        singular."""
        if self._lu is self._confirmed:  # SuperLU's, after a suspect factorisation: judged as then
            if self._confirm_singular():
                self._lu = None
                raise SingularModelError("zero pivot in the LU factorisation")
            return
        pivots = getattr(self._lu, "pivot_magnitudes", None)
        d = pivots() if pivots is not None else np.abs(self._lu.U.diagonal())
        if d.size and suspect(d, self._diagonal()) and self._confirm_singular():
            self._lu = None
            raise SingularModelError("zero pivot in the LU factorisation")
        if self._lu is not None and not self._checked:
            self._dmax = float(np.max(d, initial=0.0))
            self._checked = True

    def _diagonal(self):
        """|B_kk| of the matrix just factorised, in the order of its pivots, or None when the
        back-end pivots in an order of its own (CHOLMOD, PARDISO)."""
        engine = self._engine
        if engine is not None and engine.name not in ("banded", "dense"):
            return None
        if self._band_input() and engine._from_band:
            return np.abs(engine._L[0])  # (split band storage: row 0 of the lower part is B's diagonal)
        return np.abs(self._B.diagonal())

    def _confirm_singular(self) -> bool:
        """True if SuperLU with partial pivoting finds the tangent just factorised singular too
        (:func:`~femast.analysis.linalg.pivots.confirm`); False: its factorisation replaces the
        suspect one."""
        if self._B is None:
            return True
        B = self._B
        if self._band_input() and self._engine._from_band:  # the values are in the band storage
            B = B.copy()
            B.data = self._engine.band_values[self._engine.band_positions(np.arange(B.nnz))]
        got = confirm(B)
        if got is None:
            return True
        self._lu = self._confirmed = got[0]  # (it solves B x = b like the factor it replaces)
        self._dmax = got[1]
        self._checked = True
        self.confirmations += 1
        return False
