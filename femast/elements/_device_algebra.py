"""Small numba helpers of the device kernels (:mod:`._device_kernels`): a dense solve with partial
pivoting for the few device equations of one cable, and the tension-only law of its sections
(Stohlman & Pellegrino, Eqs. 2-3).  They call no device law, so the kernels' user-law copies share
them."""

from __future__ import annotations

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
