"""Convergence test of Newton iterations (Abaqus-like, separate force and moment fields).

An increment has converged when, for translations and rotations separately,

* the largest residual force (moment) is at most ``force_tol`` times the reference
  force (moment): the largest nodal force (moment) that any element carries or any load
  applies, with a floor for fields that carry nothing (moments: force x model size);
* the largest Newton correction of displacement (rotation) is at most ``disp_tol``
  times the largest displacement (rotation) increment of the increment so far.

Defaults 1e-6 are tighter than Abaqus' 5e-3 / 1e-2 so that verification results are
accurate to well below 1e-4; Newton's quadratic convergence makes them cheap.

A *linear* increment is accepted after its first iteration when every residual is at most
``min(linear_tol, force_tol)`` times its reference, whatever the correction (Abaqus' R_l = 1e-8).
Without this rule an increment that changes the loads by round-off never converges: its whole
increment is round-off, so the correction test compares round-off with round-off.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit


@njit(cache=True)
def field_abs_max(v, is_rot):
    """(largest |v_i| over the translational DOFs, over the rotational ones) of a vector on the
    free DOFs (``is_rot`` flags the rotations); -1 for a field without DOFs, NaN if v holds one.
    One pass, no temporaries (the masked maxima of numpy cost ~10 us per call, issue 8)."""
    t = -1.0
    r = -1.0
    for i in range(v.shape[0]):
        a = abs(v[i])
        if math.isnan(a):
            return math.nan, math.nan
        if is_rot[i]:
            if a > r:
                r = a
        elif a > t:
            t = a
    return t, r


@njit(cache=True)
def all_finite(a):
    """True if no entry of ``a`` (any shape) is NaN or infinite: one pass, no temporaries (numpy's
    ``np.isfinite(a).all()`` costs ~2 us a call on a small model, twice per Newton iteration)."""
    for v in a.flat:
        if not abs(v) <= 1.7976931348623157e308:
            return False
    return True


@njit(cache=True)
def force_moment_abs_max(f):
    """(largest |force|, largest |moment|) of a 2D array whose rows are nodal vectors laid out
    6 per node (fx fy fz mx my mz ...), e.g. element force vectors or nodal loads (0 if empty)."""
    fm = 0.0
    mm = 0.0
    for e in range(f.shape[0]):
        for j in range(f.shape[1]):
            a = abs(f[e, j])
            if j % 6 < 3:
                if a > fm:
                    fm = a
            elif a > mm:
                mm = a
    return fm, mm


@dataclass
class Convergence:
    """force_tol, disp_tol : relative tolerances (dimensionless); max_iterations per attempt;
    linear_tol : residual ratio below which an increment is accepted as linear after its first
    iteration (dimensionless; the tighter of it and force_tol is used)."""

    force_tol: float = 1e-6
    disp_tol: float = 1e-6
    max_iterations: int = 25
    linear_tol: float = 1e-8

    def check(self, r, du, Du, is_rot, ref_force, ref_moment, length, iteration=0):
        """Return (converged, residual_ratio) given the free residual ``r``, the last
        correction ``du``, the increment so far ``Du``, the bool mask ``is_rot`` and the number
        of Newton iterations done in this attempt (1: the linear-increment rule applies)."""
        ok = True
        linear = iteration == 1
        linear_tol = min(self.linear_tol, self.force_tol)
        worst = 0.0
        is_rot = np.asarray(is_rot, dtype=np.bool_)
        rmax = field_abs_max(np.asarray(r, dtype=float), is_rot)
        if du is not None:
            dmax = field_abs_max(np.asarray(du, dtype=float), is_rot)
            Dmax = field_abs_max(np.asarray(Du, dtype=float), is_rot)
        for k, ref, dref in ((0, ref_force, length), (1, ref_moment, 1.0)):
            if rmax[k] < 0.0:   # no DOF of this field
                continue
            ratio = rmax[k] / ref if ref > 0 else (0.0 if rmax[k] == 0 else np.inf)
            worst = max(worst, ratio)
            if not ratio <= self.force_tol:   # NaN never converges
                ok = False
            if not ratio <= linear_tol:
                linear = False
            if du is not None and not dmax[k] <= self.disp_tol * max(Dmax[k], 1e-9 * dref):
                ok = False     # floor 1e-9 dref: round-off-sized increments
        return ok or linear, worst
