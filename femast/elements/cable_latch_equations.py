"""The 2n equations of a cable over pulleys and a latch (Stohlman & Pellegrino, Eqs. 2-5), as
residuals of a given solution: an independent check of :class:`~femast.elements.cable_latch.CableLatchFamily`
(which solves them reduced to one scalar equation, :mod:`._cable_kernels`)."""

from __future__ import annotations

import numpy as np

from ._cable_kernels import BACKSTOP, SLIP_OUT, STICK
from .latch_law import hysteresis_force as hysteresis_force_law
from .latch_law import latch_force


def cable_equations(
    X,
    T,
    L0_sections,
    EA,
    L0,
    *,
    latch_node=None,
    bead=None,
    latch=None,
    status=STICK,
    x_committed=None,
    hysteresis_force=0.0,
    hysteresis_length=3e-4,
):
    """Residuals of the 2n equations of one element (Stohlman & Pellegrino, Eqs. 2-5), for checking a solution.

    X : (n+1, 3) anchor positions, m.  T : (n,) tensions, N.  L0_sections : (n,) unstretched
    lengths, m.  status : latch status (stick/backstop: the latch row is x - x_committed, m;
    slipping: T_{j+1} - T_j - dT_sigma(x), N).

    Returns (2n,) residuals: rows 0..n-1 the constitutive laws (N, Eqs. 2-3), row n the
    length constraint (m, Eq. 4), rows n+1.. the jumps across nodes 1..n-1 (N; m for a
    sticking latch).  hysteresis_force, hysteresis_length: the hysteresis option (N, m).
    """
    X = np.asarray(X, float)
    T = np.asarray(T, float)
    L0s = np.asarray(L0_sections, float)
    n = T.size
    L = np.linalg.norm(np.diff(X, axis=0), axis=1)
    res = np.empty(2 * n)
    res[:n] = T - EA * np.maximum(L - L0s, 0.0) / L0s
    res[n] = L0s.sum() - L0
    j = 0 if latch_node is None else int(latch_node)
    for i in range(1, n):
        if i != j:
            res[n + i] = T[i] - T[i - 1]
            continue
        x = bead - L0s[:i].sum()
        if status in (STICK, BACKSTOP):
            res[n + i] = x - x_committed
        else:
            sigma = 1 if status == SLIP_OUT else -1
            res[n + i] = (
                T[i]
                - T[i - 1]
                - latch_force(x, sigma, latch)
                - sigma * hysteresis_force_law(x, latch, hysteresis_force, hysteresis_length)
            )
    return res


__all__ = ["cable_equations"]
