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

**The predicted correction** (``predicted=True``, the default).  The correction test above bounds
the error of the *previous* iterate: when it passes, Newton has already spent an iteration whose
only purpose was to measure that the iterate before it was converged.  Abaqus/Standard therefore
also accepts an iteration whose residual passes when the *estimated* next correction passes the
correction test (Abaqus Analysis User's Guide, "Convergence criteria for nonlinear problems").
femast does not extrapolate that estimate from the residuals (on a mast's soft modes a residual
at round-off still carries a large displacement); it computes it: the simplified Newton correction
c~ = K_(k-1)^-1 r_k, one more solve with the factorisation already in hand (Deuflhard 2004,
*Newton Methods for Nonlinear Problems*, sec. 2.1.2: the natural monotonicity test and the error
estimate of the accepted iterate).  Iteration k (of full Newton, under fixed loads) is accepted
without iteration k + 1 when, with every correction measured as in the correction test (largest
entry over the field's increment, the larger of the two fields):

* the force test passes and no element answered provisionally;
* k >= 3: the first iteration of an increment is its step, so iterations 2 .. k are at least two
  corrections of Newton iterates, and the last one contracted: rho = |du_k| / |du_(k-1)| <=
  ``max_contraction`` (never on one iteration's rate, never on a non-contracting sequence: on the
  1000-bay mast's soft mode |du_3| = 0.995 |du_2| while c~ still looks small, and the true |du_4|
  is 15 times c~);
* c~ contracts too: theta = |c~| / |du_k| <= ``max_contraction``;
* the error left in iterate k, estimated as the geometric series c~ / (1 - theta), is at most
  half the correction tolerance: 2 |c~| / (1 - theta) <= ``disp_tol`` |Du|.  The factor 2 covers the
  estimate's own error: c~ differs from the Newton correction by a factor up to 1 + omega |du_k|,
  where omega |du_k| ~ 2 rho^2 <= 1/2 from Newton's quadratic contraction (Deuflhard's
  affine-covariant Lipschitz constant omega).

The strict rule stays selectable: ``Convergence(predicted=False)``.

**A convergence test of your own** (the contract :class:`~femast.analysis.newton.Newton` honours).
Any object with an integer ``max_iterations`` (iterations per attempt) and a method

    check(r, du, Du, is_rot, ref_force, ref_moment, length, iteration) -> (converged, residual_ratio)

is a convergence test: pass it as ``Analysis(..., convergence=test)``.  Newton calls ``check`` after
every iteration of every attempt, with ``r`` the residual on the free DOFs (N, N m; the free DOFs'
order), ``du`` the correction of that iteration and ``Du`` the increment so far (m, rad; ``du`` is
None only when there is no correction yet), ``is_rot`` the mask of rotational free DOFs,
``ref_force`` / ``ref_moment`` the reference force (N) and moment (N m) of the force test above,
``length`` the model size (m) and ``iteration`` the number of iterations done in the attempt (1
after the first).  It stops the attempt when ``converged`` is true; ``residual_ratio`` (a float,
dimensionless) is what the divergence test and the messages report.  A subclass of
:class:`Convergence` that overrides :meth:`Convergence.check` is such a test; its own checks replace
femast's, and the predicted-correction acceptance (which needs femast's measures) is off for it.
:func:`evaluate` is the one place the analysis asks a test.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..errors import ModelError
from ..model import validation


@njit(cache=True)
def field_abs_max(v, is_rot):
    """(largest |v_i| over the translational DOFs, over the rotational ones) of a vector on the
    free DOFs (``is_rot`` flags the rotations); -1 for a field without DOFs, NaN if v holds one.
    One pass, no temporaries (the masked maxima of numpy cost ~10 us per call)."""
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


@njit(cache=True)
def scaled_size(v, Dv, is_rot, length):
    """The correction test's measure of a correction ``v``: over translations and rotations, the
    larger of (largest |v_i| / largest |Dv_i|), with ``Dv`` the increment so far and its floors
    (1e-9 ``length`` (m), 1e-9 rad) for round-off increments; 0 without DOFs; NaN if v holds one.
    The correction test is ``scaled_size(du, Du) <= disp_tol``."""
    vt, vr = field_abs_max(v, is_rot)
    dt, dr = field_abs_max(Dv, is_rot)
    if math.isnan(vt) or math.isnan(vr):
        return math.nan
    s = 0.0
    if vt >= 0.0:
        s = vt / max(dt, 1e-9 * length)
    if vr >= 0.0:
        s = max(s, vr / max(dr, 1e-9))
    return s


MIN_TOL = 1e-15  # a relative tolerance below round-off can never be met
MAX_TOL = 1e-2  # above 1 % of the force scale a "converged" increment is not in equilibrium


@dataclass
class Convergence:
    """force_tol, disp_tol : relative tolerances (dimensionless); max_iterations per attempt;
    linear_tol : residual ratio below which an increment is accepted as linear after its first
    iteration (dimensionless; the tighter of it and force_tol is used).
    predicted : also accept an iteration on its predicted next correction (module docstring);
    False: the strict correction test only.  max_contraction : the largest ratio of successive
    corrections (dimensionless, 0 < max_contraction < 1) for which the prediction is trusted."""

    force_tol: float = 1e-6
    disp_tol: float = 1e-6
    max_iterations: int = 25
    linear_tol: float = 1e-8
    predicted: bool = True
    max_contraction: float = 0.5

    def __post_init__(self):
        self.validate()

    def validate(self) -> None:
        """Every field a number in its range, or a ModelError naming it (also called by the analysis,
        for fields changed after construction): a tolerance is a finite relative tolerance between
        :data:`MIN_TOL` (round-off) and :data:`MAX_TOL` (1 %); ``max_iterations`` a whole number >= 1."""
        for name in ("force_tol", "disp_tol", "linear_tol"):
            v = getattr(self, name)
            real = isinstance(v, numbers.Real) and not isinstance(v, bool)
            if not (real and MIN_TOL <= v <= MAX_TOL):  # (NaN: no)
                shown = f"{v:g}" if real else repr(v)
                raise ModelError(
                    f"Convergence: {name} = {shown} is not a tolerance; give a relative tolerance between "
                    f"{MIN_TOL:g} and {MAX_TOL:g} (default {getattr(Convergence, name):g})"
                )
        self.max_iterations = validation.whole(self.max_iterations, "Convergence: max_iterations", minimum=1)
        try:
            ok = 0.0 < float(self.max_contraction) < 1.0  # (NaN: no)
        except (TypeError, ValueError):  # not a number
            ok = False
        if not ok:
            raise ModelError(
                f"Convergence: max_contraction={self.max_contraction!r} must be between 0 and 1 (e.g. 0.5)"
            )

    def check(self, r, du, Du, is_rot, ref_force, ref_moment, length, iteration=0):
        """Return (converged, residual_ratio) given the free residual ``r``, the last
        correction ``du``, the increment so far ``Du``, the bool mask ``is_rot`` and the number
        of Newton iterations done in this attempt (1: the linear-increment rule applies).

        The method a test of your own overrides (module docstring): Newton then calls it after every
        iteration instead of femast's force and correction tests."""
        return self.measure(r, du, Du, is_rot, ref_force, ref_moment, length, iteration)[:2]

    def accept_predicted(self, previous, last, predicted):
        """Accept an iteration whose force test passed on its predicted next correction?
        ``previous``, ``last``: the scaled sizes (:func:`scaled_size`) of the attempt's last two
        corrections; ``predicted``: that of the simplified Newton correction c~ (module docstring)."""
        if not self.predicted:
            return False
        rate = self.max_contraction
        if not (previous > 0.0 and last <= rate * previous):  # a contracting sequence (NaN: no)
            return False
        theta = predicted / last if last > 0.0 else math.inf
        return theta <= rate and 2.0 * predicted <= (1.0 - theta) * self.disp_tol

    def measure(self, r, du, Du, is_rot, ref_force, ref_moment, length, iteration=0):
        """(converged, residual_ratio, forces_ok, correction): :meth:`check`'s answer, whether the
        force (moment) test alone passed, and the scaled size of the correction ``du``
        (:func:`scaled_size`; NaN without one)."""
        ok = True
        forces = True
        linear = iteration == 1
        linear_tol = min(self.linear_tol, self.force_tol)
        worst = 0.0
        is_rot = np.asarray(is_rot, dtype=np.bool_)
        rmax = field_abs_max(np.asarray(r, dtype=float), is_rot)
        if du is not None:
            dmax = field_abs_max(np.asarray(du, dtype=float), is_rot)
            Dmax = field_abs_max(np.asarray(Du, dtype=float), is_rot)
        for k, ref, dref in ((0, ref_force, length), (1, ref_moment, 1.0)):
            if rmax[k] < 0.0:  # no DOF of this field
                continue
            ratio = rmax[k] / ref if ref > 0 else (0.0 if rmax[k] == 0 else np.inf)
            worst = max(worst, ratio)
            if not ratio <= self.force_tol:  # NaN never converges
                ok = forces = False
            if not ratio <= linear_tol:
                linear = False
            if du is not None and not dmax[k] <= self.disp_tol * max(Dmax[k], 1e-9 * dref):
                ok = False  # floor 1e-9 dref: round-off-sized increments
        size = math.nan  # the correction's scaled size, as scaled_size(du, Du) from the maxima above
        if du is not None and not math.isnan(dmax[0]):
            size = 0.0
            for k, dref in ((0, length), (1, 1.0)):
                if dmax[k] >= 0.0:
                    size = max(size, dmax[k] / max(Dmax[k], 1e-9 * dref))
        return ok or linear, worst, forces, size


def evaluate(test, r, du, Du, is_rot, ref_force, ref_moment, length, iteration=0):
    """Ask the convergence test ``test`` about an iteration: (converged, residual_ratio, forces_ok,
    correction size).  femast's own :class:`Convergence` answers all four (:meth:`Convergence.measure`);
    a test whose ``check`` is its own (a class of yours, or a subclass overriding
    :meth:`Convergence.check`) answers the first two, and forces_ok is then False and the size NaN,
    so the predicted-correction acceptance is never used on its behalf."""
    if getattr(type(test), "check", None) is Convergence.check:
        return test.measure(r, du, Du, is_rot, ref_force, ref_moment, length, iteration)
    ok, ratio = test.check(r, du, Du, is_rot, ref_force, ref_moment, length, iteration)
    return bool(ok), float(ratio), False, math.nan


def predicts(test) -> bool:
    """Whether ``test`` accepts iterations on their predicted correction: femast's own test with
    ``predicted=True`` (a test with its own ``check`` never does)."""
    return getattr(type(test), "check", None) is Convergence.check and bool(getattr(test, "predicted", False))


def validate(test):
    """``test`` if it keeps the contract (module docstring), else a one-line :class:`ModelError`."""
    name = type(test).__name__
    if not callable(getattr(test, "check", None)):
        raise ModelError(
            f"convergence={name}: a convergence test needs a method check(r, du, Du, is_rot, ref_force, "
            "ref_moment, length, iteration) returning (converged, residual_ratio); see femast.analysis.convergence"
        )
    n = getattr(test, "max_iterations", None)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ModelError(f"convergence={name}: max_iterations={n!r} must be a whole number >= 1")
    if isinstance(test, Convergence):
        test.validate()  # (its tolerances may have been changed after construction)
    return test
