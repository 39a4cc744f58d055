"""Small numba helpers of the device kernels (:mod:`._device_kernels`): a dense solve with partial
pivoting for the few device equations of one cable, and the tension-only law of its sections
(Stohlman & Pellegrino, Eqs. 2-3).  They call no device law, so the kernels' user-law copies share
them."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def solve_small(A, b, x):
    """Solve A x = b (small dense, partial pivoting); returns False if A is singular."""
    m = b.shape[0]
    M = A.copy()
    y = b.copy()
    scale = 0.0
    for i in range(m):
        for j in range(m):
            scale = max(scale, abs(M[i, j]))
    if scale == 0.0:
        return m == 0
    for c in range(m):
        piv = c
        for r in range(c + 1, m):
            if abs(M[r, c]) > abs(M[piv, c]):
                piv = r
        if abs(M[piv, c]) <= 1e-14 * scale:
            return False
        if piv != c:
            for j in range(m):
                M[c, j], M[piv, j] = M[piv, j], M[c, j]
            y[c], y[piv] = y[piv], y[c]
        for r in range(c + 1, m):
            fct = M[r, c] / M[c, c]
            if fct != 0.0:
                for j in range(c, m):
                    M[r, j] -= fct * M[c, j]
                y[r] -= fct * y[c]
    for c in range(m - 1, -1, -1):
        acc = y[c]
        for j in range(c + 1, m):
            acc -= M[c, j] * x[j]
        x[c] = acc / M[c, c]
    return True


@njit(cache=True)
def section_tensions(S, L, EA, T, dT_dl0, de_dl0, e):
    """Tensions T (N), strains e and their derivatives with respect to l0 (N/m, 1/m)."""
    n = L.shape[0]
    for i in range(n):
        l0 = S[i + 1] - S[i]
        e[i] = L[i] / l0 - 1.0
        de_dl0[i] = -L[i] / (l0 * l0)
        if e[i] > 0.0:
            T[i] = EA * e[i]
            dT_dl0[i] = EA * de_dl0[i]
        else:
            T[i] = 0.0
            dT_dl0[i] = 0.0


@njit(cache=True)
def cable_forces_and_tangent(S, G, H, dphi, A, RL, Rphi, T, dT_dl0, EA, f, K, dTdx):
    """Nodal forces f (6 nn,) (added to) and the consistent tangent K (6 nn, 6 nn) of one cable at its
    solved device state: ``dS/dx = -A^-1 (R_L dL/dx + R_phi dphi/dx)`` (A = dR/dS of the device
    equations at the converged set), ``dT_i/dx`` from it, ``K = sum_i T_i d2L_i/dx2 + dL_i/dx
    (dT_i/dx)^T``.  S (n+1,) material coordinates, G (n, 3 nn) and H (n, 3 nn, 3 nn) the section
    lengths' gradients and Hessians, dphi (n-1, 3 nn) the wrap angles' gradients, T (n,) N,
    dT_dl0 (n,) N/m; dTdx (n, 3 nn) a work array."""
    n = G.shape[0]
    m = n - 1
    nn = G.shape[1] // 3
    # dS/dx = -A^-1 (RL G + Rphi dphi)
    Y = np.zeros((m, 3 * nn))
    if m > 0:
        rhs = np.empty(m)
        col = np.empty(m)
        for a in range(3 * nn):
            for d in range(m):
                acc = Rphi[d] * dphi[d, a]
                for i in range(n):
                    acc += RL[d, i] * G[i, a]
                rhs[d] = -acc
            if solve_small(A, rhs, col):
                for d in range(m):
                    Y[d, a] = col[d]
    # dT_i/dx = dT/dL G_i + dT/dS_i Y_{i-1} + dT/dS_{i+1} Y_i
    for i in range(n):
        l0 = S[i + 1] - S[i]
        dTdL = EA / l0 if T[i] > 0.0 else 0.0
        for a in range(3 * nn):
            v = dTdL * G[i, a]
            if i >= 1:
                v -= dT_dl0[i] * Y[i - 1, a]  # dl0_i/dS_i = -1
            if i < m:
                v += dT_dl0[i] * Y[i, a]  # dl0_i/dS_{i+1} = +1
            dTdx[i, a] = v
    for i in range(n):
        for a in range(nn):
            for c in range(3):
                f[6 * a + c] += T[i] * G[i, 3 * a + c]
    for a in range(nn):
        for c in range(3):
            ra = 3 * a + c
            for b in range(nn):
                for d2 in range(3):
                    rb = 3 * b + d2
                    v = 0.0
                    for i in range(n):
                        v += T[i] * H[i, ra, rb] + G[i, ra] * dTdx[i, rb]
                    K[6 * a + c, 6 * b + d2] = v
