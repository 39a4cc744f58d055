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

from dataclasses import dataclass

import numpy as np


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
        for mask, ref, dref in ((~is_rot, ref_force, length), (is_rot, ref_moment, 1.0)):
            if not mask.any():
                continue
            rmax = float(np.max(np.abs(r[mask])))
            ratio = rmax / ref if ref > 0 else (0.0 if rmax == 0 else np.inf)
            worst = max(worst, ratio)
            if ratio > self.force_tol:
                ok = False
            if ratio > linear_tol:
                linear = False
            if du is not None:
                dmax = float(np.max(np.abs(du[mask])))
                Dmax = float(np.max(np.abs(Du[mask])))
                if dmax > self.disp_tol * max(Dmax, 1e-9 * dref):  # floor: round-off-sized increments
                    ok = False
        return ok or linear, worst
