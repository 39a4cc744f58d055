"""Estimators of a channel's noise from a model's residual along the path (the noise model that
uses them, and why each is what it is: :mod:`femast.experiments.noise`).

* :func:`informative_rows` -- the rows that carry noise (not pinned by a model that admits an interval);
* :func:`difference_phi`, :func:`lag1`, :func:`effective_n` -- serial correlation (AR(1));
* :func:`heteroscedastic_fit` -- a level growing with a covariate, by maximum likelihood on the
  second differences;
* :func:`cycle_scatter` -- the level from repeated passes along the path coordinate;
* :func:`repeated_points` -- the level from rows that repeat their inputs (a hold);
* :func:`robust_rms` -- the RMS of a whitened residual, robust to spikes and heavy tails, with the
  trimming of the noise's own estimate (both sides of every ratio).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import lsq_linear

from .residuals import robust_rms, turning_points  # noqa: F401  (robust_rms: re-exported)

MIN_ROWS = 8
MIN_ROWS_STRUCTURE = 60
HETERO_LR = 18.5
CYCLE_MIN_PAIRS = 30  # fewest rows compared across repeated passes for a level (its scatter then <= 13 %)
# pairs of passes compared at most: a record of more (hundreds of cycles) compares each pass with its
# nearest later passes in the same direction (every shipped example has fewer than 1000)
CYCLE_MAX_PASS_PAIRS = 2000
VAR_FLOOR = 0.04  # smallest variance of a row / the mean variance: sigma >= 0.2 of its RMS (noise.py docstring)
_MAD = 1.482602218505602  # 1 / Phi^-1(3/4): MAD -> standard deviation of a normal variable


def informative_rows(r) -> np.ndarray:
    """(n,) bool: rows of a residual r (n,) that carry noise -- not zero and not repeating a neighbour
    exactly (to 1e-12 of the largest |r|): a noisy measurement never does, a model that admits an
    interval and predicts the measured value inside it (a pinned row) does.  All True when fewer than
    ``MIN_ROWS`` rows would be left."""
    r = np.asarray(r, float)
    tol = 1e-12 * float(np.max(np.abs(r), initial=0.0))
    pinned = np.abs(r) <= tol
    tie = np.abs(np.diff(r)) <= tol
    pinned[1:] |= tie
    pinned[:-1] |= tie
    keep = ~pinned
    return keep if keep.sum() >= MIN_ROWS else np.ones(r.size, bool)


def _mad(x) -> float:
    x = np.asarray(x, float)
    return _MAD * float(np.median(np.abs(x - np.median(x)))) if x.size else 0.0


def lag1(r) -> float:
    """Lag-1 autocorrelation of a series r (n,) (mean removed); 0 for fewer than 3 values."""
    r = np.asarray(r, float)
    if r.size < 3:
        return 0.0
    r = r - r.mean()
    den = float(r @ r)
    return float(np.clip((r[1:] @ r[:-1]) / den, -0.99, 0.99)) if den > 0 else 0.0


def _trimmed_ms(x) -> float:
    s = _mad(x)
    x = np.asarray(x, float)
    k = np.abs(x) < 5.0 * s if s > 0 else np.ones(x.size, bool)
    return float(np.mean(x[k] ** 2)) if k.any() else 0.0


def difference_phi(r) -> float:
    """``3 - Var(d2) / Var(d1)`` of a series r (n,): the AR(1) coefficient of noise, nearly blind to a
    smooth model error (trimmed mean squares; standard error about 1.9 / sqrt(n))."""
    r = np.asarray(r, float)
    m1, m2 = _trimmed_ms(np.diff(r)), _trimmed_ms(np.diff(r, 2))
    return float(np.clip(3.0 - m2 / m1, -0.99, 0.99)) if m1 > 0 else 0.0


def ar1_threshold(n: int) -> float:
    """99th percentile of :func:`lag1` on white noise of ``n`` rows, ``2.33 / sqrt(n)`` (normal limit)."""
    return 2.326 / math.sqrt(max(int(n), 1))


def ar1_factor(phi: float) -> float:
    """``Var(d2) / (6 sigma^2)`` of AR(1) noise: ``(1 - phi)(3 - phi) / 3`` (1 when white)."""
    return (1.0 - phi) * (3.0 - phi) / 3.0


def effective_n(n: int, phi: float) -> float:
    """Effective sample size of n rows of AR(1) noise, ``n (1 - phi) / (1 + phi)`` (n for phi <= 0)."""
    return float(n) * (1.0 - phi) / (1.0 + phi) if phi > 0 else float(n)


def _g3(g2):
    """(g2[i-1] + 4 g2[i] + g2[i+1]) / 6 at the interior rows: the covariate of a second difference."""
    return (g2[:-2] + 4.0 * g2[1:-1] + g2[2:]) / 6.0


def _fit_variance(d2sq, X, iters: int = 10):
    """Maximum-likelihood ``beta`` of ``d2^2 ~ v chi^2_1``, ``v = X beta`` (design X (m, k)), batched over
    the leading axis of ``d2sq`` (draws, m), by Fisher scoring (weighted least squares of d2^2 on X,
    weights 1 / v^2) with ``A, D >= 0`` (a variance at zero covariate, a growth far out); v is kept
    above ``VAR_FLOOR`` of the mean d2^2 and rows beyond 36 v are left out.
    Returns (beta (draws, k), v (draws, m), keep, log-likelihood (draws,))."""
    floor = VAR_FLOOR * np.mean(d2sq, axis=-1, keepdims=True)
    v = np.broadcast_to(np.median(d2sq, axis=-1, keepdims=True) / 0.4549, d2sq.shape)  # median of chi^2_1
    beta = None
    lo = np.array([0.0, -np.inf, 0.0])[: X.shape[1]]
    for _ in range(iters):
        keep = d2sq < 36.0 * v
        w = keep / v**2
        XtW = X.T[None, :, :] * w[:, None, :]
        M = XtW @ X + 1e-12 * np.eye(X.shape[1])
        beta = np.linalg.solve(M, (XtW @ d2sq[..., None]))[..., 0]
        for j in np.flatnonzero(np.any(beta < lo, axis=-1)):  # A, D >= 0: bounded weighted least squares
            sw = np.sqrt(w[j])
            sc = np.sqrt(np.sum((X * sw[:, None]) ** 2, axis=0)) + 1e-300
            beta[j] = lsq_linear(X * sw[:, None] / sc, d2sq[j] * sw, bounds=(lo * sc, np.inf)).x / sc
        v = np.maximum(beta @ X.T, floor)
    keep = d2sq < 36.0 * v
    ll = -0.5 * np.sum(keep * (d2sq / v + np.log(v)), axis=-1)
    return beta, v, keep, ll


def _fit_constant(d2sq, keep):
    A = np.sum(d2sq * keep, axis=-1) / np.maximum(keep.sum(axis=-1), 1)
    ll = -0.5 * np.sum(keep * (d2sq / A[:, None] + np.log(A[:, None])), axis=-1)
    return A, ll


def _design(g):
    """Design of the variance of a second difference for ``v_i = A + B g_i + D g_i^2``: columns
    ``[1, g3(g), g3(g^2)]`` (:func:`_g3`)."""
    return np.column_stack([np.ones(g.size - 2), _g3(g), _g3(g * g)])


def _lr(d2sq, X):
    beta, v, keep, ll1 = _fit_variance(d2sq, X)
    _, ll0 = _fit_constant(d2sq, keep)
    return 2.0 * (ll1 - ll0), beta, v


def heteroscedastic_fit(r, g, phi: float = 0.0) -> dict:
    """Fit ``Var(noise_i) = A + B g_i + D g_i^2`` to a residual r (n,) with covariate g (n,) (signed or
    not; module docstring).  For the latch-pull covariate (the signed slope s of the law) this is
    Stohlman & Pellegrino, Eq. 15's ``sigma_T^2 (1 + s C)^2 + s^2 sigma_d^2``.  Returns ``{coef (A, B, D) in the
    units of r^2 and g, lr, threshold, sigma (n,), range}``; ``range`` is max/min sigma."""
    r, g = np.asarray(r, float), np.asarray(g, float)
    gs = float(np.max(np.abs(g))) or 1.0
    u = g / gs
    c = ar1_factor(phi)  # Var(d2) = 6 c v for AR(1) noise
    d2 = r[2:] - 2.0 * r[1:-1] + r[:-2]
    lr, beta, _ = _lr((d2**2)[None, :], _design(u))
    A, B, D = (float(x) / (6.0 * c) for x in beta[0])
    v = A + B * u + D * u * u
    v = np.maximum(v, VAR_FLOOR * max(float(np.mean(v)), 1e-300))
    sigma = np.sqrt(v)
    return {
        "coef": (A, B / gs, D / gs**2),
        "lr": float(lr[0]),
        "threshold": HETERO_LR,
        "sigma": sigma,
        "range": float(sigma.max() / sigma.min()),
    }


def cycle_scatter(
    coord, r, keep=None, sigma=None, min_pairs: int = CYCLE_MIN_PAIRS, max_pass_pairs: int = CYCLE_MAX_PASS_PAIRS
):
    """Noise level from repeated passes along a path coordinate (module docstring, "repeated cycles").

    coord : (n,) the quantity the test drives (latch-pull: the bead position; mast-top: the load),
    r : (n,) residual (or measurement), keep : (n,) bool rows that carry noise, sigma : (n,) a noise
    model's per-row level (default 1: the level itself is returned).  Passes are the
    monotone runs of coord (turning points confirmed by 5 % of its range); each row of a pass is
    compared with the later passes in the same direction that cover its coordinate: ``d = r_a -
    interp(r_b)`` has variance ``sigma^2 (1 + w^2 + (1 - w)^2)`` for independent noise (w the
    interpolation weight), while anything that repeats with the coordinate -- the model's error,
    a ripple -- cancels.  Rows where the other pass is not sampled (its neighbours further apart
    than 3 of its median steps, or equal) are left out.  A long record of many passes (more than
    ``max_pass_pairs`` pairs of passes in the same direction; the pairs grow as the square of the
    passes) compares each pass with its nearest later passes only (the next one in the same
    direction, then the one after, ... whole rounds until ``max_pass_pairs``): still thousands of
    compared rows, the level's scatter ~ 1/sqrt(2 m) for m of them, and the passes nearest in time
    differ least by what drifts.  Returns ``(level, pairs)`` -- the robust RMS of ``d`` whitened by
    the variance sigma gives it (so the level relative to sigma) -- or ``None`` with fewer than
    ``min_pairs`` compared rows."""
    coord, r = np.asarray(coord, float), np.asarray(r, float)
    n = coord.size
    keep = np.ones(n, bool) if keep is None else np.asarray(keep, bool)
    sg = np.ones(n) if sigma is None else np.broadcast_to(np.asarray(sigma, float), (n,))
    span = float(np.ptp(coord)) if n else 0.0
    if n < MIN_ROWS_STRUCTURE or span <= 0.0:
        return None
    tps, direction = turning_points(coord, 0.05 * span)
    bounds = [0, *(int(t) + 1 for t in tps), n]
    runs = [(np.arange(a, b), float(direction[a])) for a, b in zip(bounds[:-1], bounds[1:]) if b - a >= 3]
    sorted_runs = {}

    def sorted_pass(k):
        """Pass k's kept rows by coordinate: (coordinate, residual, sigma, steps, median step), or None."""
        if k not in sorted_runs:
            rb = runs[k][0]
            rb = rb[keep[rb]]
            sorted_runs[k] = None
            if rb.size >= 3:
                order = np.argsort(coord[rb], kind="stable")
                cb = coord[rb][order]
                step = np.diff(cb)
                med = float(np.median(step[step > 0])) if np.any(step > 0) else 0.0
                if med > 0.0:
                    sorted_runs[k] = (cb, r[rb][order], sg[rb][order], step, med)
        return sorted_runs[k]

    out = []
    for i, k in _pass_pairs([d for _, d in runs], max_pass_pairs):
        other = sorted_pass(k)
        if other is None:
            continue
        cb, vb, sb, step, med = other
        ra = runs[i][0]
        rows = ra[keep[ra] & (coord[ra] > cb[0]) & (coord[ra] < cb[-1])]
        j = np.clip(np.searchsorted(cb, coord[rows]) - 1, 0, cb.size - 2)
        h = step[j]
        ok = (h > 0) & (h <= 3.0 * med)
        rows, j, h = rows[ok], j[ok], h[ok]
        w = (coord[rows] - cb[j]) / h
        d = r[rows] - ((1.0 - w) * vb[j] + w * vb[j + 1])
        out.append(d / np.sqrt(sg[rows] ** 2 + (w * sb[j + 1]) ** 2 + ((1.0 - w) * sb[j]) ** 2))
    d = np.concatenate(out) if out else np.zeros(0)
    if d.size < min_pairs:
        return None
    return math.sqrt(_trimmed_ms(d)), int(d.size)


def _pass_pairs(directions, limit: int) -> list:
    """(i, k), i < k, of the passes :func:`cycle_scatter` compares, in the order i, then k: every
    later pass in the same direction; with more than ``limit`` such pairs, the nearest ones: the next
    pass in the same direction, then the one after, ... (whole rounds) until ``limit`` is reached."""
    pairs = [
        (i, k) for i in range(len(directions)) for k in range(i + 1, len(directions)) if directions[k] == directions[i]
    ]
    if len(pairs) <= limit:
        return pairs
    same = {}
    for i, d in enumerate(directions):
        same.setdefault(d, []).append(i)
    nearest, lag = [], 1
    while len(nearest) < limit:
        round_ = [(idx[m], idx[m + lag]) for idx in same.values() for m in range(len(idx) - lag)]
        if not round_:
            break
        nearest += round_
        lag += 1
    return sorted(nearest)


REPEAT_MIN_PAIRS = 30  # fewest pairs of repeated rows for a level (the MAD's scatter is then about 20 %)


def repeated_points(inputs, r, keep=None, min_pairs: int = REPEAT_MIN_PAIRS):
    """Noise level from rows that repeat the row before exactly in every input (a hold: the same
    load measured again): the difference of their residuals ``r`` (n,) is noise only (whatever the
    model misses at that state is the same in both), of variance ``2 sigma^2`` for white noise.

    inputs : (n, k) the experiment's input columns; keep : (n,) bool rows that carry noise.
    Returns ``(sigma, pairs)`` -- ``1.4826 median|d| / sqrt(2)``, robust to a spike in a hold --
    or ``None`` with fewer than ``min_pairs`` pairs.  Rows repeated elsewhere in the test (not in a
    row) are not used: where the response depends on the path (friction, hysteresis) the same
    inputs reached another way give another state."""
    X = np.asarray(inputs, float).reshape(len(r), -1)
    r = np.asarray(r, float)
    keep = np.ones(r.size, bool) if keep is None else np.asarray(keep, bool)
    if r.size < 2 or X.shape[1] == 0:
        return None
    scale = np.maximum(np.max(np.abs(X), axis=0), 1e-300)
    same = np.all(np.abs(np.diff(X, axis=0)) <= 1e-12 * scale, axis=1) & keep[1:] & keep[:-1]
    d = np.diff(r)[same]
    if d.size < min_pairs:
        return None
    return _MAD * float(np.median(np.abs(d))) / math.sqrt(2.0), int(d.size)
