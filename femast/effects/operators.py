"""Rate-independent hysteresis operators used by the effects (numba kernels, path order = row order).

* :func:`play` -- the play (backlash) operator of width ``2 r``: the output follows the input
  with a lag ``r`` and stays put for an input change of ``2 r`` after each reversal.  Applied to a
  joint moment it is Coulomb friction with a friction moment ``r`` in series with the elastic joint.
* :func:`proportional_play` -- the same with a threshold ``eta |u|`` proportional to the current
  input: the loop width grows with the load and closes at zero load (inter-fibre friction of a
  rope whose normal force grows with its tension).
* :func:`proportional_iwan` -- many proportional plays with a distribution of coefficients (a rope's
  fibre groups): smooth zero-closing loops; one coefficient is :func:`proportional_play`.
* :func:`jenkins` -- an elastic joint in parallel with a Jenkins element (a spring in series with
  a Coulomb slider) driven by its load: ``alpha u + play((1 - alpha) u; r)``.  ``alpha = 0`` is the
  play operator (rigid stick), ``alpha = 1`` the elastic joint alone.
* :func:`iwan` -- a series Iwan model (elasto-slip elements with a distribution of slip strengths)
  driven by its load: ``alpha u + (1 - alpha) mean_j play(u; r_j)`` with the slip strengths
  ``r_j = R q_j^(1/beta)`` at the mid quantiles ``q_j`` of the power-law distribution
  ``P(r <= s) = (s / R)^beta`` on ``[0, R]``.  It is a Prandtl-Ishlinskii operator, so its loops obey
  the Masing rules; ``beta -> inf`` gives the play operator of width ``R``, ``beta = 1`` (uniform
  strengths) a parabolic virgin curve ``u^2 / (2 R)`` below ``R``.

All start from the state 0 (relaxed at zero load) and act column by column.
"""

from __future__ import annotations

import numpy as np
from numba import njit

IWAN_ELEMENTS = 24  # slip strengths of the discretised Iwan model (error of the loop ~ 1 / N^2 of R)


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


@njit(cache=True)
def _play_sum(u, radii, etas, weights):
    """sum_k weights[k] play(u; radii[k] + etas[k] |u|) on each column of u (n, m), every play from
    state 0: fixed half-widths (etas = 0, the Iwan model) or half-widths proportional to the input
    (radii = 0, the proportional Iwan model); an exact zero term leaves the other bit for bit."""
    n, m = u.shape
    out = np.zeros_like(u)
    nk = radii.size
    state = np.zeros(nk)
    for j in range(m):
        for k in range(nk):
            state[k] = 0.0
        for i in range(n):
            acc = 0.0
            x = u[i, j]
            a = abs(x)
            for k in range(nk):
                p = state[k]
                r = radii[k] + etas[k] * a
                if p < x - r:
                    p = x - r
                elif p > x + r:
                    p = x + r
                state[k] = p
                acc += weights[k] * p
            out[i, j] = acc
    return out


def _as2d(u):
    u = np.asarray(u, dtype=float)
    return u, np.ascontiguousarray(u.reshape(u.shape[0], -1))


def _widths(r, u2) -> np.ndarray:
    """Half-widths >= 0 of every entry of u2 (n, k) from ``r``: one value, or one per column (k,)."""
    r = np.maximum(np.asarray(r, dtype=float), 0.0)
    return np.ascontiguousarray(np.broadcast_to(r, u2.shape)) if r.ndim else np.full_like(u2, float(r))


def play(u, r, p0: float = 0.0) -> np.ndarray:
    """Play operator of half-width ``r`` (unit of ``u``, >= 0; one value, or one per column) on each
    column of ``u`` (n,) or (n, k)."""
    u, u2 = _as2d(u)
    return _play(u2, _widths(r, u2), float(p0)).reshape(u.shape)


def proportional_play(u, eta: float, p0: float = 0.0) -> np.ndarray:
    """Play operator with half-width ``eta |u|`` (eta dimensionless, >= 0) on each column of ``u``."""
    u, u2 = _as2d(u)
    return _play(u2, max(float(eta), 0.0) * np.abs(u2), float(p0)).reshape(u.shape)


def jenkins(u, r, alpha: float) -> np.ndarray:
    """Elastic joint in parallel with a Jenkins element, driven by its load ``u`` (n,) or (n, k).

    Returns the load carried by the elastic joint: ``alpha u + play((1 - alpha) u; r)``.  r : slip
    strength of the slider (unit of u, >= 0); alpha : compliance of the stuck joint relative to the
    slipping one, ``k / (k + k_s)`` in [0, 1] (k the joint's, k_s the Jenkins spring's stiffness).
    While stuck the joint turns by ``alpha du / k``, while slipping by ``du / k``; the slider carries
    ``(1 - alpha) u`` of every load change until it reaches ``+-r``.  alpha = 0: :func:`play`.
    r may be one value per column.
    """
    a = min(max(float(alpha), 0.0), 1.0)
    u, u2 = _as2d(u)
    return (a * u2 + _play(u2 * (1.0 - a), _widths(r, u2), 0.0)).reshape(u.shape)


def iwan_strengths(R: float, beta: float, n: int = IWAN_ELEMENTS) -> np.ndarray:
    """Slip strengths ``R q_j^(1/beta)`` at the mid quantiles ``q_j = (j - 1/2) / n`` (unit of R)."""
    q = (np.arange(n) + 0.5) / n
    return max(float(R), 0.0) * q ** (1.0 / max(float(beta), 1e-6))


def iwan(u, R, beta: float, alpha: float = 0.0, n: int = IWAN_ELEMENTS) -> np.ndarray:
    """Series Iwan model driven by its load ``u`` (n,) or (n, k): the load carried by the elastic part.

    ``alpha u + (1 - alpha) / n sum_j play(u; r_j)``, ``r_j`` from :func:`iwan_strengths`.  R : largest
    slip strength (unit of u, >= 0); beta : shape of the strength distribution ``P(r <= s) = (s/R)^beta``
    (> 0; large: all near R, Coulomb-like; 1: uniform; small: most slip early, nearly elastic);
    alpha : share that never slips, in [0, 1].  R may be one value per column of u.
    """
    if np.ndim(R):
        u, u2 = _as2d(u)
        cols = [iwan(u2[:, j], Rj, beta, alpha, n) for j, Rj in enumerate(np.broadcast_to(R, u2.shape[1:]))]
        return np.column_stack(cols).reshape(u.shape)
    a = min(max(float(alpha), 0.0), 1.0)
    radii = iwan_strengths(R, beta, n)
    u, u2 = _as2d(u)
    w = np.full(radii.size, (1.0 - a) / radii.size)
    return (a * u2 + _play_sum(u2, radii, np.zeros_like(radii), w)).reshape(u.shape)


def proportional_iwan(u, eta: float, beta: float, alpha: float = 0.0, n: int = IWAN_ELEMENTS) -> np.ndarray:
    """Distributed inter-fibre friction of a rope driven by its load ``u`` (n,) or (n, k): the load
    carried by the elastic part, ``alpha u + (1 - alpha) / n sum_j play(u; eta_j |u|)``.

    A parallel bundle of fibre groups whose friction thresholds grow with the tension, each in
    proportion to its own coefficient ``eta_j = eta q_j^(1/beta)`` (mid quantiles ``q_j`` of the
    power-law distribution ``P(e <= s) = (s / eta)^beta`` on ``[0, eta]``, as :func:`iwan_strengths`).
    Every loop closes at zero load; the groups with small ``eta_j`` release first on a return, so
    the return branch is curved (smooth) where :func:`proportional_play` gives a flat part and a
    straight line.  eta : largest relative threshold (in [0, 1)); beta : shape (> 0; large: all at
    eta, the :func:`proportional_play` limit); alpha : share without friction, in [0, 1].
    """
    a = min(max(float(alpha), 0.0), 1.0)
    etas = iwan_strengths(eta, beta, n)
    u, u2 = _as2d(u)
    w = np.full(etas.size, (1.0 - a) / etas.size)
    return (a * u2 + _play_sum(u2, np.zeros_like(etas), etas, w)).reshape(u.shape)
