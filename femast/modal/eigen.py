"""The eigensolver of the modal analysis: ``K phi = omega^2 M phi`` with a mass matrix that may be
singular (DOFs without mass).

Two paths, chosen by the number of free DOFs that carry mass (``n_m``):

* **few massed DOFs** (``n_m <= DENSE_MASSED``, or more modes asked for than a Krylov basis of
  the massed DOFs holds): exact static condensation of the massless DOFs, then a dense symmetric
  eigensolution.  A massless DOF carries no inertia, so in a mode it follows the massed ones
  statically: with ``o`` the massless and ``m`` the massed DOFs,

      phi_o = -K_oo^-1 K_om phi_m,     (K_mm - K_mo K_oo^-1 K_om) phi_m = omega^2 M_mm phi_m

  (M is positive semi-definite, so a zero diagonal term means a zero row and column: M_om = 0).
  M_mm may still be singular (a point mass with an offset and no rotary inertia has rank 3 on 6
  DOFs); its null directions are condensed the same way in the eigenbasis of M_mm, and the rest
  is a standard symmetric problem solved by LAPACK (``scipy.linalg.eigh``).  The result is the
  exact eigensolution of the full pencil, with no shift and no starting vector.
* **many massed DOFs**: ARPACK's shift-invert Lanczos (``scipy.sparse.linalg.eigsh``, mode 3,
  which allows a singular M) with its Lanczos basis no larger than the number of massed DOFs:
  the operator ``(K - sigma M)^-1 M`` has rank ``n_m``, so a basis of more vectors than that
  cannot be built (ARPACK's error -9999 with a few point masses on a massless frame).

Both paths fail only on a real defect, which the error names: massless DOFs that form a
mechanism (``K_oo`` singular: a DOF no element stiffens and no mass holds), or an eigenvalue
exactly at a shift the user gave.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import ModelError

DENSE_MASSED = 600
"""Largest number of massed free DOFs solved by condensation and a dense eigensolution."""

LANCZOS_MIN = 20
"""ARPACK's default smallest Lanczos basis (scipy: ``max(2 k + 1, 20)``)."""


class MasslessMechanism(ModelError):
    """The DOFs without mass are not held by any stiffness (``K_oo`` singular)."""


def default_shift(K, M, massed):
    """A shift omega^2 < 0 below the lowest eigenvalue of a stable state: -1e-2 of the smallest
    K_ii / M_ii (each is a Rayleigh quotient, an upper bound of the lowest eigenvalue)."""
    kd, md = K.diagonal()[massed], M.diagonal()[massed]
    q = kd / md
    q = q[q > 0]
    return -1e-2 * float(q.min()) if q.size else -1.0


def _mechanism_dof(Koo):
    """Index (into Koo) of the largest entry of a null vector of the dense symmetric ``Koo``."""
    w, V = np.linalg.eigh(Koo)
    return int(np.argmax(np.abs(V[:, int(np.argmin(np.abs(w)))])))


def _condense(Kmm, Kmo, Koo, where, describe):
    """``(K_c, X)`` with ``K_c = K_mm - K_mo X`` and ``X = K_oo^-1 K_om`` (dense)."""
    if Koo.shape[0] == 0:
        return Kmm, np.zeros((0, Kmm.shape[0]))
    try:
        if sp.issparse(Koo):
            lu = spla.splu(sp.csc_matrix(Koo))
            X = lu.solve(np.asarray(Kmo.T.toarray() if sp.issparse(Kmo) else Kmo.T))
        else:
            X = sla.solve(Koo, Kmo.T, assume_a="sym")
        if not np.all(np.isfinite(X)):
            raise np.linalg.LinAlgError
    except (RuntimeError, np.linalg.LinAlgError):
        dense = Koo.toarray() if sp.issparse(Koo) else Koo
        i = where[_mechanism_dof(dense)] if dense.shape[0] <= 3000 else None
        dof = f" (for example {describe(i)})" if (i is not None and describe is not None) else ""
        raise MasslessMechanism(
            "the DOFs without mass form a mechanism: no element stiffens them and no mass holds "
            f"them{dof}. Fix or tie that DOF, stiffen it, or give it mass (a point mass or a density)"
        ) from None
    Kc = Kmm - np.asarray(Kmo @ X)
    return 0.5 * (Kc + Kc.T), X


def _dense_modes(K, M, massed, n_modes, sigma, describe):
    """All eigenpairs by condensation (module note); the ``n_modes`` nearest ``sigma``, ascending."""
    K = sp.csr_matrix(K)
    M = sp.csr_matrix(M)
    mi = np.flatnonzero(massed)
    oi = np.flatnonzero(~massed)
    Kmm = K[mi][:, mi].toarray()
    Kc, X = _condense(Kmm, K[mi][:, oi], K[oi][:, oi], oi, describe)
    Mmm = M[mi][:, mi].toarray()
    Mmm = 0.5 * (Mmm + Mmm.T)
    d, Q = np.linalg.eigh(Mmm)
    pos = d > 1e-12 * d.max()
    Kq = Q.T @ Kc @ Q
    Qp, Qn = Q[:, pos], Q[:, ~pos]
    Kc2, Y = _condense(
        Kq[np.ix_(pos, pos)], Kq[np.ix_(pos, ~pos)], Kq[np.ix_(~pos, ~pos)], mi[np.argmax(np.abs(Qn), axis=0)], describe
    )
    s = 1.0 / np.sqrt(d[pos])
    lam, Z = np.linalg.eigh((s[:, None] * Kc2) * s[None, :])
    order = np.sort(np.argsort(np.abs(lam - sigma), kind="stable")[:n_modes])
    lam, Z = lam[order], Z[:, order]
    yp = s[:, None] * Z  # y_p^T D y_p = 1
    phi_m = Qp @ yp - Qn @ (Y @ yp)
    V = np.zeros((K.shape[0], len(lam)))
    V[mi] = phi_m
    V[oi] = -X @ phi_m
    return lam, V


def _lanczos_modes(K, M, massed, n_modes, sigma, n_mass, describe):
    n = K.shape[0]
    try:
        lu = spla.splu(sp.csc_matrix(K - sigma * M))
    except RuntimeError:
        # singular at this shift: at another one too only if the massless DOFs are a mechanism
        try:
            spla.splu(sp.csc_matrix(K - (2.0 * sigma - 1.0) * M))
        except RuntimeError:
            raise MasslessMechanism(
                "K - sigma M is singular at two shifts: DOFs without mass form a mechanism (no element "
                "stiffens them and no mass holds them). Fix or tie them, stiffen them, or give them mass"
            ) from None
        raise ModelError(
            f"an eigenvalue sits exactly at the shift omega^2 = {sigma:.6g} (rad/s)^2: give another shift_hz"
        ) from None
    op = spla.LinearOperator((n, n), matvec=lu.solve, dtype=float)
    rng = np.random.default_rng(0)  # reproducible starting vector
    v0 = M @ rng.standard_normal(n) + 1e-3 * rng.standard_normal(n) * massed
    ncv = min(n_mass, max(2 * n_modes + 1, LANCZOS_MIN), n)
    lam, V = spla.eigsh(K, k=n_modes, M=M, sigma=sigma, which="LM", OPinv=op, v0=v0, ncv=ncv)
    return lam, V


def solve_eigen(K, M, n_modes: int, sigma: float | None = None, describe=None):
    """The ``n_modes`` eigenpairs of K phi = lam M phi nearest ``sigma`` ((rad/s)^2; default
    :func:`default_shift`), sorted ascending; vectors M-normalised.  K, M symmetric sparse (n, n),
    M positive semi-definite.  ``describe(i)``: optional text naming free DOF i, for messages.

    Raises :class:`MasslessMechanism` (a :class:`~femast.errors.ModelError`) when the DOFs without
    mass are not held, ModelError when an eigenvalue sits exactly at the shift."""
    md = M.diagonal()
    massed = md > 0
    n_mass = int(np.count_nonzero(massed))
    if sigma is None:
        sigma = default_shift(K, M, massed)
    if n_mass <= DENSE_MASSED or 2 * n_modes + 1 > n_mass:
        lam, V = _dense_modes(K, M, massed, n_modes, sigma, describe)
    else:
        lam, V = _lanczos_modes(K, M, massed, n_modes, sigma, n_mass, describe)
    order = np.argsort(lam)
    lam, V = lam[order], V[:, order]
    norms = np.sqrt(np.abs(np.einsum("ij,ij->j", V, M @ V)))
    return lam, V / np.where(norms > 0, norms, 1.0)


__all__ = ["solve_eigen", "default_shift", "MasslessMechanism", "DENSE_MASSED"]
