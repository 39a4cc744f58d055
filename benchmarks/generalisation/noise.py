"""Measurement noise models (numpy only): white, AR(1), heteroscedastic, and Stohlman & Pellegrino, Eq. 15.

* ``white(rng, n, sigma)``: independent N(0, sigma^2).
* ``ar1(rng, n, sigma, phi)``: stationary AR(1), ``e_t = phi e_{t-1} + sqrt(1 - phi^2) sigma w_t``
  with ``e_0 ~ N(0, sigma^2)``: variance sigma^2 at every t, lag-k autocorrelation ``phi^k``
  (slow drift of a tracker or a load cell between samples).
* ``heteroscedastic(rng, scale, sigma)``: N(0, (sigma scale_t)^2), a per-sample standard deviation.
* ``eq15_measurement(rng, x, dT, ...)``: the latch pull procedure of Stohlman & Pellegrino, Sec. III.B: the
  machine measures the end-to-end distance ``d = x + C T + d0`` and the tension ``T``, each with
  its own noise, and the bead position is recovered by Eq. 15, ``x = d - C T - d0``.  The
  recovered position therefore carries ``e_d - C e_T``, correlated with the force noise ``e_T``:
  to first order the residual of the force against a law ``f(x)`` of slope ``s`` is
  ``e_T (1 + s C) - s e_d``, of variance ``sigma_T^2 (1 + s C)^2 + s^2 sigma_d^2``
  (``eq15_residual_variance``), larger on the steep branches.

The tension that the Eq. 15 rig measures is the pulling cable's, ``T = |dT|`` with the distance
taken along the pull; both directions give the same ``x`` noise ``e_d - C e_T`` with ``e_T`` the
noise of ``dT`` (derivation in ``docs/diagnose_generalisation.md``).
"""

from __future__ import annotations

import numpy as np


def white(rng, n: int, sigma: float) -> np.ndarray:
    """Independent normal noise, standard deviation sigma."""
    return sigma * rng.standard_normal(n)


def ar1(rng, n: int, sigma: float, phi: float) -> np.ndarray:
    """Stationary AR(1) noise with standard deviation sigma and lag-1 autocorrelation phi."""
    if not -1.0 < phi < 1.0:
        raise ValueError(f"AR(1) coefficient phi = {phi} must lie in (-1, 1)")
    w = rng.standard_normal(n)
    e = np.empty(n)
    e[0] = sigma * w[0]
    c = sigma * np.sqrt(1.0 - phi * phi)
    for t in range(1, n):
        e[t] = phi * e[t - 1] + c * w[t]
    return e


def heteroscedastic(rng, scale, sigma: float) -> np.ndarray:
    """Normal noise whose standard deviation is ``sigma * scale`` per sample."""
    scale = np.asarray(scale, float)
    return sigma * scale * rng.standard_normal(scale.size)


def eq15_measurement(rng, x, dT, C: float, sigma_T: float, sigma_d: float, d0: float = 0.0):
    """Measured (x, dT) of a latch pull test through the Eq. 15 stretch removal.

    x : true bead positions (m); dT : true force jumps (N); C : cable compliance of Eq. 15
    ``(L10 + L30) / k_cable`` (m/N); sigma_T : load-cell noise (N); sigma_d : end-to-end distance
    noise (m).  Returns ``(x_measured, dT_measured)``."""
    x = np.asarray(x, float)
    dT = np.asarray(dT, float)
    e_T = sigma_T * rng.standard_normal(x.size)
    e_d = sigma_d * rng.standard_normal(x.size)
    d = x + C * dT + d0 + e_d  # distance along the pull, cable stretched by the pulling tension
    T = dT + e_T
    return d - C * T - d0, T


def eq15_residual_variance(slope, C: float, sigma_T: float, sigma_d: float) -> np.ndarray:
    """First-order variance (N^2) of ``dT_measured - f(x_measured)`` for a law of slope ``slope``
    (N/m) under :func:`eq15_measurement`."""
    s = np.asarray(slope, float)
    return sigma_T**2 * (1.0 + s * C) ** 2 + (s * sigma_d) ** 2


def student_t(rng, n: int, sigma: float, nu: float) -> np.ndarray:
    """Heavy-tailed noise: Student's t with ``nu > 2`` degrees of freedom scaled to the standard
    deviation sigma (``t sigma sqrt((nu - 2) / nu)``)."""
    if not nu > 2:
        raise ValueError(f"Student-t noise needs nu > 2 for a finite variance, got {nu}")
    return sigma * np.sqrt((nu - 2.0) / nu) * rng.standard_t(nu, n)


def spikes(rng, n: int, count: int, size: float) -> np.ndarray:
    """``count`` single-sample spikes at distinct random rows (none in the first and last 5), each of
    random sign and a size drawn uniformly in [size / 2, size]; zero elsewhere (a loose connector,
    electrical interference)."""
    e = np.zeros(n)
    rows = rng.choice(np.arange(5, n - 5), size=count, replace=False)
    e[rows] = rng.choice([-1.0, 1.0], count) * rng.uniform(0.5 * size, size, count)
    return e
