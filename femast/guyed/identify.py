"""Identification of the mast-model parameters (the Rocaspect paper, Section IV, Eqs. 27-30).

Every fit calls :func:`scipy.optimize.least_squares` and returns a :class:`FitResult`
with the estimate ``x``, the standard errors ``stderr`` and the covariance
``cov = s^2 (J^T J)^-1``, where J is the Jacobian of the residuals at the solution and
``s^2 = |r|^2 / (n - p)`` the residual variance.  Parameters that the data cannot
determine (a singular direction of J) get ``stderr = inf`` and ``success`` stays True
with a message saying which ones.

Notes on the paper's identification equations
--------------------------------------------
* Eq. 27 is linear in ``[k0, k1, k2]``; the residual is in N.
* Eqs. 28-29 and 30 are linear in the *compliances* ``1/k_theta`` and ``1/E, 1/G``, not in
  the stiffnesses the paper lists as unknowns.  Here the stiffness (or E) itself is fitted
  (so its standard error comes out directly), started from the linear solution.
* Eq. 29 is built from J of Eq. 6; with the corrected sign (:mod:`.mast_3r`) only the
  force/moment coupling changes.
* Eq. 30, row 2 is printed ``L^3/(3 I_z) dw_2 + L^2/(2 I_z) dw_4``; the moment term
  must be ``-L^2/(2 I_z) dw_4``: a positive moment about x tips a vertical beam's top
  towards -y, and the compliance must be symmetric (row 4 has ``-L^2/(2 I_z) dw_2``).
  :func:`fit_beam_E` builds the matrix from Eqs. 8-14 and so has the right sign.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from .._moved import renamed_attributes
from ..errors import ModelError
from ._common import check_positive, check_vectors
from .cantilever import cantilever_compliance_parts, mast_section
from .mast_3r import compliance_3r, jacobian_3r, printed_sign_of


@dataclass(frozen=True)
class FitResult:
    """Result of a parameter fit (scipy-like).

    x : estimated parameters.  stderr : their standard errors (same units; inf if not identifiable).
    cov : (p, p) covariance ``s^2 (J^T J)^-1``.  names, units : parameter names and units.
    success, message : from least_squares, plus identifiability notes.  nfev : function evaluations.
    cost : half the sum of squared residuals.  fun : residuals at the solution.
    s : residual standard deviation (unit of the residuals).  dof : n_residuals - n_parameters.
    """

    x: np.ndarray
    stderr: np.ndarray
    cov: np.ndarray
    names: tuple
    units: tuple
    success: bool
    message: str
    nfev: int
    cost: float
    fun: np.ndarray
    s: float
    dof: int

    def __str__(self) -> str:
        rows = [f"{n:>8s} = {v: .6g} +- {e:.3g} {u}" for n, v, e, u in zip(self.names, self.x, self.stderr, self.units)]
        return "\n".join(rows + [f"  s = {self.s:.3g} (dof {self.dof}); {self.message}"])


def _fit(fun, x0, names, units, bounds=(-np.inf, np.inf), x_scale=None) -> FitResult:
    x0 = np.asarray(x0, dtype=float)
    scale = np.abs(x0) if x_scale is None else np.asarray(x_scale, dtype=float)
    scale = np.where(scale > 0, scale, 1.0)
    res = least_squares(fun, x0, bounds=bounds, x_scale=scale, method="trf", xtol=1e-14, ftol=1e-14, gtol=1e-14)
    n, p = res.fun.size, x0.size
    dof = n - p
    if dof <= 0:
        raise ModelError(f"{n} residuals cannot determine {p} parameters ({', '.join(names)}); give more data")
    s2 = 2.0 * res.cost / dof
    Js = res.jac * scale  # scaled Jacobian: better conditioned
    _, sv, Vt = np.linalg.svd(Js, full_matrices=False)
    good = sv > 1e-10 * sv[0] if sv.size and sv[0] > 0 else np.zeros(p, bool)
    inv = (Vt[good].T / sv[good] ** 2) @ Vt[good]
    cov = s2 * scale[:, None] * inv * scale[None, :]
    stderr = np.sqrt(np.diag(cov))
    msg = res.message.rstrip(".")
    if not np.all(good):
        null = np.abs(Vt[~good]).max(axis=0) > 1e-6
        stderr = np.where(null, np.inf, stderr)
        msg += "; not identifiable from these data: " + ", ".join(n_ for n_, b in zip(names, null) if b)
    return FitResult(
        res.x,
        stderr,
        cov,
        tuple(names),
        tuple(units),
        bool(res.success),
        msg,
        int(res.nfev),
        float(res.cost),
        res.fun,
        float(np.sqrt(s2)),
        dof,
    )


# --------------------------------------------------------------------------- Eq. 27
def shroud_design_matrix(dl, tau, l0: float = 0.5):
    """``A_s`` and ``b_s`` of Eq. 27: rows ``[dl, tau dl, tau^2 dl] / l0`` and ``tau``; dl, l0 in m, tau in N."""
    dl = np.asarray(dl, dtype=float).ravel()
    tau = np.asarray(tau, dtype=float).ravel()
    if dl.shape != tau.shape:
        raise ModelError(f"elongations ({dl.size}) and forces ({tau.size}) must pair up")
    l0 = float(check_positive("shroud sample length l0", l0, "m"))
    return np.column_stack([dl, tau * dl, tau**2 * dl]) / l0, tau


def fit_shroud_law(dl, tau, l0: float = 0.5) -> FitResult:
    """Fit ``x_s = [k0 (N), k1 (-), k2 (1/N)]`` of Eq. 25 to a tensile test (Eq. 27).

    dl : elongations, m.  tau : forces, N.  l0 : free length of the sample, m (0.5 m in the paper).
    Residuals ``A_s x_s - b_s`` in N.
    """
    A, b = shroud_design_matrix(dl, tau, l0)
    col = np.linalg.norm(A, axis=0)
    col = np.where(col > 0, col, 1.0)
    x0 = np.linalg.lstsq(A / col, b, rcond=None)[0] / col
    return _fit(lambda x: A @ x - b, x0, ("k0", "k1", "k2"), ("N", "-", "1/N"), x_scale=1.0 / col)


# --------------------------------------------------------------------------- Eqs. 28-29
def _rows(rows):
    return np.arange(6) if rows is None else np.asarray(rows, dtype=int)


def _pairs(dw, dc):
    dw = check_vectors("wrench changes dw", dw, (6,)).reshape(-1, 6)
    dc = check_vectors("top displacements dc", dc, (6,)).reshape(-1, 6)
    if dw.shape != dc.shape:
        raise ModelError(f"need one measured displacement per wrench: dw {dw.shape}, dc {dc.shape}")
    return dw, dc


def rocaspect_eq29_matrix(dw, r_oc, printed_sign: bool = False, *, seed_sign: bool | None = None) -> np.ndarray:
    """A_theta of Eq. 29 stacked over the samples (6 k, 3): column c is ``J[:, c] (J[:, c] . dw)``.

    Multiplying by the joint compliances ``1 / k_theta`` (rad/(N m)) gives the displacements (m, rad).
    """
    printed_sign = printed_sign_of(printed_sign, seed_sign, "rocaspect_eq29_matrix")
    J = jacobian_3r(r_oc, printed_sign)
    dw = check_vectors("wrench changes dw", dw, (6,)).reshape(-1, 6)
    return (J[None, :, :] * (dw @ J)[:, None, :]).reshape(-1, 3)


def fit_3r(
    dw,
    dc,
    r_oc,
    rows=None,
    free=(True, True, True),
    k_fixed=(np.inf, np.inf, np.inf),
    printed_sign: bool = False,
    *,
    seed_sign: bool | None = None,
) -> FitResult:
    """Fit the 3R joint stiffnesses k_theta (N m/rad) to wrench changes dw (k, 6; N, N m) and measured
    top displacements dc (k, 6; m, rad) (Eqs. 28-29).

    rows : which of the 6 displacement components were measured (default all; a laser tracker
        gives the translations ``(0, 1, 2)``).
    free : which joints to fit; the others are held at ``k_fixed`` (inf = rigid).  With only
        translations measured, the torsion joint (about the vertical mast axis) has no effect and
        is reported as not identifiable if left free.
    """
    printed_sign = printed_sign_of(printed_sign, seed_sign, "fit_3r")
    dw, dc = _pairs(dw, dc)
    rows = _rows(rows)
    free = np.asarray(free, dtype=bool)
    if not free.any():
        raise ModelError("fit_3r: at least one joint stiffness must be free")
    k_fixed = check_positive("fixed 3R joint stiffness", k_fixed, "N m/rad", allow_inf=True).reshape(3)
    A = rocaspect_eq29_matrix(dw, r_oc, printed_sign).reshape(-1, 6, 3)[:, rows, :].reshape(-1, 3)
    comp_fixed = np.where(free, 0.0, 1.0 / k_fixed)
    b = dc[:, rows].ravel() - A @ comp_fixed
    comp0 = np.linalg.lstsq(A[:, free], b, rcond=None)[0]
    # Start from the linear (compliance) solution; a non-positive compliance is not a stiffness.
    scale_guess = np.median(np.abs(comp0[comp0 > 0])) if np.any(comp0 > 0) else 1e-5
    comp0 = np.where(comp0 > 0, comp0, scale_guess)
    k0 = 1.0 / comp0

    def residual(kf):
        k = k_fixed.copy()
        k[free] = kf
        return (dw @ compliance_3r(k, r_oc, printed_sign).T)[:, rows].ravel() - dc[:, rows].ravel()

    names = tuple(f"k_theta{i + 1}" for i in range(3) if free[i])
    return _fit(residual, k0, names, ("N m/rad",) * len(names), bounds=(0.0, np.inf))


# --------------------------------------------------------------------------- Eq. 30
def fit_beam_E(
    dw,
    dc,
    L: float = 3.651,
    s_out: float = 0.1,
    s_in: float = 0.094,
    nu: float = 0.3,
    rows=None,
    axis=(0.0, 0.0, 1.0),
    fit_G: bool = False,
    torsion: str = "bredt",
) -> FitResult:
    """Fit the beam Young's modulus E (Pa) to wrench changes dw (k, 6; N, N m) and top displacements
    dc (k, 6; m, rad) with the cantilever model (Eqs. 15, 30).

    G = E / (2 (1 + nu)) unless ``fit_G`` (then x = [E, G]; G is only identifiable if the data
    contain torsion).  L, s_out, s_in in m; ``torsion`` as in :func:`.cantilever.mast_section`.
    """
    dw, dc = _pairs(dw, dc)
    rows = _rows(rows)
    L = float(check_positive("beam length L", L, "m"))
    sec = mast_section(1.0, nu, s_out, s_in, torsion=torsion, L=L)
    C_E, C_G = cantilever_compliance_parts(L, sec, axis)
    a_E = (dw @ C_E.T)[:, rows].ravel()
    a_G = (dw @ C_G.T)[:, rows].ravel()
    b = dc[:, rows].ravel()
    if fit_G:
        A = np.column_stack([a_E, a_G])
        comp = np.linalg.lstsq(A, b, rcond=None)[0]
        x0 = np.where(comp > 0, 1.0 / np.where(comp > 0, comp, 1.0), 7e10)

        def residual(x):
            return a_E / x[0] + a_G / x[1] - b

        return _fit(residual, x0, ("E", "G"), ("Pa", "Pa"), bounds=(0.0, np.inf))
    ratio = 2.0 * (1.0 + nu)  # 1/G = ratio / E
    a = a_E + ratio * a_G
    comp = (a @ b) / (a @ a) if a @ a > 0 else 0.0
    x0 = [1.0 / comp if comp > 0 else 7e10]
    return _fit(lambda x: a / x[0] - b, x0, ("E",), ("Pa",), bounds=(0.0, np.inf))


#: old names, kept for one release (they warn): femast 0.3 removes them
__getattr__ = renamed_attributes(__name__, {"seed_eq29_matrix": "rocaspect_eq29_matrix"})
