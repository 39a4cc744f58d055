"""Rate-independent hysteresis operators used by the effects (numba kernels, path order = row order).

* :func:`play` -- the play (backlash) operator of width ``2 r``: the output follows the input
  with a lag ``r`` and stays put for an input change of ``2 r`` after each reversal.  Applied to a
  joint moment it is Coulomb friction with a friction moment ``r`` in series with the elastic joint.
* :func:`proportional_play` -- the same with a threshold ``eta |u|`` proportional to the current
  input: the loop width grows with the load and closes at zero load (inter-fibre friction of a
  rope whose normal force grows with its tension).

Both start from the state 0 (relaxed at zero load change) and act column by column.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _play(u, r, p0):
    """Play operator with half-width r[i, j] >= 0 at each input u[i, j] (columns independent)."""
    n, m = u.shape
    out = np.empty_like(u)
    for j in range(m):
        p = p0
        for i in range(n):
            lo = u[i, j] - r[i, j]
            hi = u[i, j] + r[i, j]
            if p < lo:
                p = lo
            elif p > hi:
                p = hi
            out[i, j] = p
    return out


def play(u, r: float, p0: float = 0.0) -> np.ndarray:
    """Play operator of half-width ``r`` (unit of ``u``, >= 0) on each column of ``u`` (n,) or (n, k)."""
    u = np.asarray(u, dtype=float)
    u2 = np.ascontiguousarray(u.reshape(u.shape[0], -1))
    return _play(u2, np.full_like(u2, max(float(r), 0.0)), float(p0)).reshape(u.shape)


def proportional_play(u, eta: float, p0: float = 0.0) -> np.ndarray:
    """Play operator with half-width ``eta |u|`` (eta dimensionless, >= 0) on each column of ``u``."""
    u = np.asarray(u, dtype=float)
    u2 = np.ascontiguousarray(u.reshape(u.shape[0], -1))
    return _play(u2, max(float(eta), 0.0) * np.abs(u2), float(p0)).reshape(u.shape)
