"""Stiffness and strength degradation of a connection: a damage law driven by its slip history.

Continuum damage (Kachanov): a damage ``D`` in [0, 1) makes the undamaged connection carry the
*effective* load ``F / (1 - D)``.  Its elastic stiffness is then ``k (1 - D)`` and every strength
of its slip mechanisms (a friction threshold, the embedment strength of a gap) ``(1 - D)`` times
the undamaged one: one variable degrades stiffness and strength together, as cyclic tests of
timber and steel connections show (the repeated cycles at one amplitude reach less load, with a
softer reloading).

``D`` grows with a measure ``X`` of the slip history (:func:`damage`):

    D = D_max (1 - exp(-X / X_d))

linear at first (``dD/dX = D_max / X_d``) and saturating at ``D_max`` (a connection whose cycles
stabilise at one amplitude).  Two measures, both non-decreasing along the path:

* **cumulative slip** ``X = S = sum |ds|`` (displacement unit; :func:`cumulative_slip`) -- wear of
  the contact surfaces and repeated crushing grow with the distance slid;
* **dissipated energy** ``X = E = sum F ds`` (load unit x displacement unit, J for N and m;
  :func:`dissipated_energy`, the trapezoidal rule) -- the energy idea of Park & Ang's damage index.

The slip ``s`` is that of the connection's slip mechanisms (its displacement less the elastic
part), which itself depends on ``D``: :func:`degrade` solves ``D = law(X(s(F / (1 - D))))`` along
the whole path by fixed-point iteration (each pass runs the slip mechanisms once; the path is
causal, so the iteration converges: 10-60 passes to 1e-9 on the 30,000 rows of a connection test).

Closed forms (``tests/effects/test_damage.py``): a slider of constant strength ``r`` driven
between ``+-F_m`` slips ``2 (F_m - r)`` per half cycle, so ``S`` after ``N`` half cycles is known
and, with damage, the fixed point of a rigid-plastic slider is explicit half cycle by half cycle.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..errors import ConvergenceError

DRIVERS = ("slip", "energy")


def damage(X, D_max: float, X_d: float) -> np.ndarray:
    """``D_max (1 - exp(-X / X_d))`` (dimensionless) of a non-negative measure ``X`` (unit of X_d)."""
    if not (0.0 <= D_max < 1.0) or not X_d > 0.0:
        raise ValueError(f"damage: need 0 <= D_max < 1 and X_d > 0 (got D_max={D_max!r}, X_d={X_d!r})")
    return D_max * -np.expm1(-np.maximum(np.asarray(X, dtype=float), 0.0) / X_d)


def cumulative_slip(s) -> np.ndarray:
    """``S_i = sum_{j <= i} |s_j - s_{j-1}|`` along the rows (axis 0), 0 at the first row."""
    s = np.asarray(s, dtype=float)
    S = np.zeros_like(s)
    S[1:] = np.cumsum(np.abs(np.diff(s, axis=0)), axis=0)
    return S


def dissipated_energy(F, s) -> np.ndarray:
    """``E_i = sum_{j <= i} (F_j + F_{j-1}) / 2 (s_j - s_{j-1})`` (trapezoidal work of the load on the
    slip), 0 at the first row.  Positive for slip against a resisting load (friction, crushing)."""
    F = np.asarray(F, dtype=float)
    s = np.asarray(s, dtype=float)
    E = np.zeros(np.broadcast_shapes(F.shape, s.shape))
    E[1:] = np.cumsum(0.5 * (F[1:] + F[:-1]) * np.diff(s, axis=0), axis=0)
    return E


def damage_measure(F, s, driver: str) -> np.ndarray:
    """The measure ``X`` of :func:`damage`: ``driver`` "slip" (cumulative slip) or "energy"."""
    if driver == "slip":
        return cumulative_slip(s)
    if driver == "energy":
        return dissipated_energy(F, s)
    raise ValueError(f"damage driver '{driver}': use one of {', '.join(DRIVERS)}")


def degrade(
    F,
    slip_of: Callable,
    D_max: float,
    X_d: float,
    driver: str = "slip",
    *,
    tol: float = 1e-9,
    max_passes: int = 500,
) -> tuple[np.ndarray, np.ndarray]:
    """Damage ``D`` along the path of the load ``F`` (n,) or (n, m) and the effective load ``F / (1 - D)``.

    slip_of : ``slip_of(F_eff) -> s`` the slip of the connection's mechanisms (shape of ``F``) under
        the effective load.  D_max, X_d, driver : the law of :func:`damage` and its measure.
    Solves ``D = damage(X(F, s(F / (1 - D))))`` by fixed-point iteration until ``D`` changes by less
    than ``tol`` (after a quarter of ``max_passes`` the update is halved, against a slip that flips
    between two paths); raises :class:`~femast.errors.ConvergenceError` after ``max_passes`` passes.  Each
    column of ``F`` has its own damage.  Returns ``(D, F_eff)``.
    """
    F = np.asarray(F, dtype=float)
    D = np.zeros_like(F)
    F_eff = F
    if D_max == 0.0:
        return D, F_eff
    change = np.inf
    relax = 1.0
    for k in range(max_passes):
        if k == max_passes // 4:
            relax = 0.5  # still moving: the slip jumps between two paths (a threshold crossed or not); damp
        s = np.asarray(slip_of(F_eff), dtype=float)
        D_new = damage(damage_measure(F, s, driver), D_max, X_d)
        change = float(np.max(np.abs(D_new - D))) if D.size else 0.0
        D = D + relax * (D_new - D)
        F_eff = F / (1.0 - D)
        if change < tol:
            return D, F_eff
    raise ConvergenceError(
        f"damage: the fixed point of D along the path did not settle in {max_passes} passes (last change "
        f"{change:.2g}, D_max {D_max:g}, X_d {X_d:g}); a damage this fast runs away: bound X_d from below"
    )
