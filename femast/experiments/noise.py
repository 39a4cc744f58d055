"""Noise model of each channel for ``diagnose``: white, heteroscedastic, serially correlated or given.

The noise is estimated from the differences of a model's residual along the path (the response
changes little from one row to the next, the noise does; see
:func:`~femast.experiments.residuals.noise_floor`), one channel at a time:

* **serial correlation** -- ``phi`` is the lag-1 autocorrelation of the (standardised) residual
  of the *best* model of the diagnosis (a smooth model error would pass for correlated noise in
  the baseline's residual; once an effect explains it, what is left is the noise).  It counts
  when it exceeds ``2.33 / sqrt(n)``, the 99th percentile of the estimate on white noise; the
  channel then has ``n_eff = n (1 - phi) / (1 + phi)`` effective samples (the variance of a mean
  of AR(1) noise is ``(1 + phi) / (1 - phi)`` times that of white noise), used in the
  information criterion and the at-noise threshold of ``diagnose``.  A smooth model error left in
  that residual would also raise the lag-1 autocorrelation; the differences are nearly blind to it:
  for AR(1) noise ``phi = 3 - Var(d2) / Var(d1)`` (first and second differences, trimmed mean
  squares, standard error ``1.9 / sqrt(n)`` by Monte Carlo), so ``phi`` is capped at that estimate
  (from the baseline's residual) plus two standard errors.  For AR(1) noise of marginal
  standard deviation ``sigma`` the second differences have variance ``2 sigma^2 (1 - phi)(3 - phi)``
  (``6 sigma^2`` when white), which gives the level from their robust scale.
* **heteroscedastic** -- the variance of row i is ``A + B g_i + D g_i^2`` for a covariate ``g`` the
  experiment names (``Experiment.noise_covariates``: for latch-pull the signed slope ``s`` of the
  latch law, since Eq. 15 removes the cable stretch with the measured force, so the residual of a
  row is ``e_T (1 + s C) - s e_d`` with variance ``sigma_T^2 (1 + s C)^2 + s^2 sigma_d^2``, a
  quadratic in s; for every experiment the size of the reading).  ``A, B, D`` are the Gaussian
  maximum-likelihood fit (Fisher scoring) of the second differences, whose variance is
  ``(1 - phi)(3 - phi) / 3 x (v_{i-1} + 4 v_i + v_{i+1})`` (exact for independent noise), with
  rows beyond 6 standard deviations left out (jumps of the model error), ``A >= 0`` and ``D >= 0``
  (the variance at zero covariate and its growth far out cannot be negative; unconstrained, a
  negative ``A`` put the noise of the rows near zero load at a tenth of its true value and a
  3-sigma row at 20 "sigma"), and no row's variance below ``VAR_FLOOR`` = 0.04 of the mean (sigma
  at least 0.2 of its RMS: a few second differences near the end of the covariate's range cannot
  establish a noise 5x below the typical; seed 001 Eq. 15's range on the seed's latch is 0.45).  The model is kept when
  its likelihood-ratio statistic against one level exceeds ``HETERO_LR`` = 18.5, the 99th
  percentile of that statistic on white noise (Monte Carlo, 2000 draws of 100-1500 rows along
  signed and unsigned covariates: 16.0-19.8; the second differences are correlated, so it exceeds
  the chi-square value 9.2 for two parameters) and the standard deviation it gives varies by at
  least ``HETERO_MIN_RANGE`` = 1.3 over the data (smaller variations change no verdict).
* **given** -- a ``sigma_<channel>`` column (same unit as the channel) gives the standard
  uncertainty of every row; it is used as it is.

* **pinned rows** -- a model that admits an interval at some rows (latch-pull: the static band of a
  bead at rest, Eq. 9 third case; the backstop; a slack cable) predicts the measured value itself
  there, so those residuals are exactly zero (or one constant along a hold): they carry no noise.
  Left in, they pull every difference-based estimate down (15 % of the rows of a latch-pull test
  with its holds: the level by up to 25 %, the verdict "not explained" on pure noise).  Rows whose
  residual is zero or repeats its neighbour's exactly (:func:`informative_rows`) are left out of
  the estimates, which use the remaining rows in path order; the level then applies to every row.

Fewer than ``MIN_ROWS`` = 8 rows (without ``sigma_`` columns) leave too few differences for any
estimate: a :class:`~femast.errors.ModelError`.  Correlation and heteroscedasticity are only tested
from ``MIN_ROWS_STRUCTURE`` = 60 rows (below that the white estimate is used and the report says so).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import lsq_linear

from ..errors import DataFileError, ModelError

MIN_ROWS = 8
MIN_ROWS_STRUCTURE = 60
HETERO_MIN_RANGE = 1.3
HETERO_LR = 18.5
CYCLE_MIN_PAIRS = 30  # fewest rows compared across repeated passes for a level (its scatter then <= 13 %)
VAR_FLOOR = 0.04  # smallest variance of a row / the mean variance: sigma >= 0.2 of its RMS (module docstring)
QUANTILE = 0.99
_MAD = 1.482602218505602  # 1 / Phi^-1(3/4): MAD -> standard deviation of a normal variable
_SEED = 20241124


@dataclass
class ChannelNoise:
    """Noise model of one channel (see the module docstring); ``sigma`` (n,) in the channel's unit."""

    channel: str
    kind: str
    sigma: np.ndarray
    phi: float = 0.0
    n_eff: float = 0.0
    covariate: str | None = None
    reason: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def sigma_rms(self) -> float:
        return float(np.sqrt(np.mean(self.sigma**2)))

    def to_json(self) -> dict:
        return {
            "kind": self.kind,
            "sigma_rms": self.sigma_rms,
            "sigma_min": float(np.min(self.sigma)),
            "sigma_max": float(np.max(self.sigma)),
            "phi": float(self.phi),
            "n_eff": float(self.n_eff),
            "covariate": self.covariate,
            "reason": self.reason,
            **{k: v for k, v in self.extra.items() if k != "level_reason"},
        }


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
    seed 001 Eq. 15's ``sigma_T^2 (1 + s C)^2 + s^2 sigma_d^2``.  Returns ``{coef (A, B, D) in the
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


def given_sigma(data, channel: str) -> np.ndarray | None:
    """The ``sigma_<channel>`` column of the data (checked: finite and > 0), or None."""
    name = f"sigma_{channel}"
    if name not in data:
        return None
    s = np.asarray(data[name], float)
    bad = np.flatnonzero(~np.isfinite(s) | (s <= 0.0))
    if bad.size:
        i = int(bad[0])
        line = int(data.lines[i]) if data.lines is not None else i + 2
        raise DataFileError(
            f"{data.path} line {line}: column '{name}' = {float(s[i])!r}: a standard uncertainty must be "
            f"finite and > 0 ({bad.size} row(s) are not); remove the column to let femast estimate "
            "the noise, or give every row its uncertainty"
        )
    return s


def channel_noise(
    channel: str, r, n_channel_rows: int, covariates=None, given=None, correlate: bool = True, pinned=None
) -> ChannelNoise:
    """Noise model of one channel from its residual r (n,) (module docstring).

    correlate : also test r for serial correlation (:func:`with_correlation`).
    covariates : ``{name: (n,) array}`` heteroscedasticity candidates (>= 0, any unit).
    given : (n,) per-row standard uncertainty (``sigma_`` column), or None.
    pinned : (n,) bool, rows to leave out besides those :func:`informative_rows` finds (diagnose
        passes the baseline's pinned rows when it estimates from a variant whose effect unpins them).
    """
    r = np.asarray(r, float)
    n = r.size
    if given is not None:
        return ChannelNoise(
            channel,
            "given",
            np.asarray(given, float),
            0.0,
            float(n),
            None,
            f"sigma_{channel} column: the per-row uncertainty given with the data",
        )
    if n < MIN_ROWS:
        raise ModelError(
            f"channel {channel}: {n} rows are too few for the noise model (at least {MIN_ROWS} rows, "
            f"or a sigma_{channel} column giving each row's standard uncertainty)"
        )
    from .residuals import noise_floor

    if n < MIN_ROWS_STRUCTURE:
        return ChannelNoise(
            channel,
            "white",
            np.full(n, max(noise_floor(r), 1e-300)),
            0.0,
            float(n),
            None,
            f"white: {n} rows are too few (< {MIN_ROWS_STRUCTURE}) to test for serial correlation "
            "or a varying noise level",
        )
    keep = _keep(r, pinned)
    rk = r[keep]
    pinned = int(n - keep.sum())
    note = f"; {pinned} pinned rows (residual exactly zero or repeated: no noise) left out" if pinned else ""
    best = None
    for name, g in (covariates or {}).items():
        g = np.asarray(g, float)
        if g.shape != (n,) or not np.all(np.isfinite(g)) or np.ptp(g[keep]) <= 0.0:
            continue
        h = heteroscedastic_fit(rk, g[keep])
        if h["lr"] > h["threshold"] and h["range"] >= HETERO_MIN_RANGE and (best is None or h["lr"] > best[2]["lr"]):
            best = (name, g, h)
    if best is None:
        model = ChannelNoise(
            channel,
            "white",
            np.full(n, max(noise_floor(rk), 1e-300)),
            0.0,
            float(n),
            None,
            "constant level (no covariate explains a varying level)" + note,
        )
    else:
        name, g, h = best
        A, B, D = h["coef"]
        v = A + B * g + D * g * g
        sigma = np.sqrt(np.maximum(v, VAR_FLOOR * max(float(np.mean(v[keep])), 1e-300)))
        model = ChannelNoise(
            channel,
            "heteroscedastic",
            np.maximum(sigma, 1e-300),
            0.0,
            float(n),
            name,
            f"level varies with {name}: sigma^2 = A + B g + D g^2, A = {A:.3g}, B = {B:.3g}, D = {D:.3g} "
            f"(likelihood ratio {h['lr']:.0f} > {h['threshold']:.0f}, the 99th percentile on white noise; sigma "
            f"from {h['sigma'].min():.3g} to {h['sigma'].max():.3g}){note}",
            {"variance_coefficients": [A, B, D]},
        )
    return with_correlation(model, r, pinned) if correlate else model


def _keep(r, pinned=None) -> np.ndarray:
    keep = informative_rows(r)
    if pinned is not None and (both := keep & ~np.asarray(pinned, bool)).sum() >= MIN_ROWS:
        keep = both
    return keep


def with_correlation(model: ChannelNoise, r, pinned=None) -> ChannelNoise:
    """``model`` with its AR(1) coefficient from the residual r (n,) of a (better) model: phi, n_eff,
    kind and reason updated, the level corrected from the white-noise estimate (module docstring)."""
    r = np.asarray(r, float)
    if model.kind == "given" or r.size < MIN_ROWS_STRUCTURE:
        return model
    base_kind = model.kind.replace("+ar1", "").replace("ar1", "white")
    phi0 = model.phi
    reason = model.extra.get("level_reason", model.reason)
    keep = _keep(r, pinned)
    u = (r / model.sigma)[keep]
    m = u.size
    phi_hat = lag1(u)
    thr = ar1_threshold(m)
    cap = difference_phi(u) + 2.0 * 1.9 / math.sqrt(m)
    if phi_hat > thr and cap > thr:
        phi = min(phi_hat, cap, 0.95)
        why = (
            f"serially correlated: AR(1) phi = {phi:.2f} (lag-1 autocorrelation {phi_hat:.2f} > {thr:.2f}, the 99th "
            f"percentile on white noise; differences allow up to {cap:.2f}), {effective_n(r.size, phi):.0f} "
            f"effective samples of {r.size}"
        )
        kind = "ar1" if base_kind == "white" else base_kind + "+ar1"
    else:
        phi = 0.0
        if phi_hat > thr:  # the residual is correlated, its differences are not: a slow model error
            why = f"no serial correlation in the noise: the residual's lag-1 autocorrelation {phi_hat:.2f} is above {thr:.2f} (the 99th percentile on white noise), but its differences allow at most {cap:.2f}: a slowly varying model error, not correlated noise"  # noqa: E501
        else:
            why = f"no serial correlation (lag-1 autocorrelation {phi_hat:.2f} <= {thr:.2f}, the 99th percentile on white noise)"
        kind = base_kind
    sigma = model.sigma * math.sqrt(ar1_factor(phi0) / ar1_factor(phi))
    return ChannelNoise(
        model.channel,
        kind,
        sigma,
        phi,
        effective_n(r.size, phi),
        model.covariate,
        f"{why}; {reason}",
        {**model.extra, "level_reason": reason},
    )


def noise_model(exp, data, fit_result, correlate: bool = True, generic: bool = True, pinned=None) -> dict:
    """``{channel: ChannelNoise}`` from a fit's residuals (``diagnose``: first the baseline's without the
    correlation test and with the experiment's own covariates only -- a structured residual would pass
    for noise growing with the reading --, for the weights of the refits; then the best model's, for
    the verdict).  generic : also test the size of the reading as a covariate.  pinned :
    ``{channel: (n,) bool}`` rows to leave out besides the fit's own pinned rows (:func:`pinned_rows`
    of another fit)."""
    covs = {}
    pred = fit_result.predicted
    for c in exp.channels:
        covs[c] = {"size of the reading": np.abs(pred[c])} if generic else {}
    if getattr(exp, "noise_covariates", None) is not None:
        extra = exp.noise_covariates(data, dict(fit_result.params), exp.options, fit_result) or {}
        for c, d in extra.items():
            covs.setdefault(c, {}).update(d)
    coord = path_coordinate(exp, data) if correlate else None
    out = {}
    for c in exp.channels:
        out[c] = channel_noise(
            c, fit_result.residuals[c], data.n, covs.get(c), given_sigma(data, c), correlate, (pinned or {}).get(c)
        )
        if coord is not None:
            out[c] = with_cycles(out[c], coord, fit_result.residuals[c], (pinned or {}).get(c))
    return out


def path_coordinate(exp, data) -> np.ndarray | None:
    """The quantity the test drives along its passes (``Experiment.path_coordinate``, else the load
    measure of the segmentation), for :func:`cycle_scatter`; None if it cannot be evaluated."""
    try:
        if getattr(exp, "path_coordinate", None) is not None:
            return np.asarray(exp.path_coordinate(data, exp.options), float)
        from .compare import load_path

        return np.asarray(load_path(exp, data), float)
    except Exception:  # a coordinate is optional: no repeated-pass check rather than a failed diagnosis
        return None


def pinned_rows(fit_result, channels) -> dict:
    """``{channel: (n,) bool}`` rows of a fit's residual that carry no noise (:func:`informative_rows`)."""
    return {c: ~informative_rows(fit_result.residuals[c]) for c in channels}


def cycle_scatter(coord, r, keep=None, sigma=None, min_pairs: int = CYCLE_MIN_PAIRS):
    """Noise level from repeated passes along a path coordinate (module docstring, "repeated cycles").

    coord : (n,) the quantity the test drives (latch-pull: the bead position; mast-top: the load),
    r : (n,) residual (or measurement), keep : (n,) bool rows that carry noise, sigma : (n,) a noise
    model's per-row level (default 1: the level itself is returned).  Passes are the
    monotone runs of coord (turning points confirmed by 5 % of its range); each row of a pass is
    compared with the later passes in the same direction that cover its coordinate: ``d = r_a -
    interp(r_b)`` has variance ``sigma^2 (1 + w^2 + (1 - w)^2)`` for independent noise (w the
    interpolation weight), while anything that repeats with the coordinate -- the model's error,
    a ripple -- cancels.  Rows where the other pass is not sampled (its neighbours further apart
    than 3 of its median steps, or equal) are left out.  Returns ``(level, pairs)`` -- the robust RMS
    of ``d`` whitened by the variance sigma gives it (so the level relative to sigma) -- or ``None``
    with fewer than ``min_pairs`` compared rows."""
    from .residuals import turning_points

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
    out = []
    for i, (ra, da) in enumerate(runs):
        for rb, db in runs[i + 1 :]:
            if db != da:
                continue
            rb = rb[keep[rb]]
            if rb.size < 3:
                continue
            order = np.argsort(coord[rb], kind="stable")
            cb, vb, sb = coord[rb][order], r[rb][order], sg[rb][order]
            step = np.diff(cb)
            med = float(np.median(step[step > 0])) if np.any(step > 0) else 0.0
            if med <= 0.0:
                continue
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


def with_cycles(model: ChannelNoise, coord, r, pinned=None) -> ChannelNoise:
    """``model`` checked against the level of the repeated passes (:func:`cycle_scatter`): where its
    RMS level exceeds that level beyond the estimate's scatter (``1 + 3 / sqrt(2 m)`` for m compared
    rows), the excess is structure that repeats with the path (a ripple with the position, a model
    error taken for correlated or growing noise), not noise: the level is scaled down to it and an
    AR(1) coefficient dropped (kind ``+cycles``).  A lower estimate than the repeated passes' is kept:
    passes differ also by model errors that do not repeat (hysteresis of other amplitudes, drift)."""
    if model.kind == "given":
        return model
    r = np.asarray(r, float)
    keep = _keep(r, pinned)
    cyc = cycle_scatter(coord, r, keep, model.sigma)
    if cyc is None:
        return model
    rho, m = cyc
    # scatter of the two estimates: 1 / (2 m) for the passes' RMS, ~2 / n for the difference estimate
    # (the MAD's relative variance 1.36 / n on n - 2 correlated second differences)
    limit = 1.0 + 3.0 * math.sqrt(1.0 / (2.0 * m) + 2.0 / max(int(keep.sum()), 1))
    extra = {**model.extra, "cycle_ratio": rho, "cycle_pairs": m}
    if rho * limit >= 1.0:
        return ChannelNoise(
            model.channel,
            model.kind,
            model.sigma,
            model.phi,
            model.n_eff,
            model.covariate,
            model.reason + f"; repeated passes agree ({rho:.2f}x this level from {m} compared rows)",
            extra,
        )
    n = r.size
    kind = model.kind.replace("+ar1", "").replace("ar1", "white") + "+cycles"
    return ChannelNoise(
        model.channel,
        kind,
        model.sigma * rho,
        0.0,
        float(n),
        model.covariate,
        f"level from repeated passes: {rho:.2f}x the difference estimate ({m} rows compared at the "
        f"same path position in passes of the same direction; below it beyond the scatter of the "
        f"two, 1/{limit:.2f}): what that estimate took for noise"
        f"{' (serial correlation)' if model.phi > 0 else ''} repeats with the path; "
        f"{model.extra.get('level_reason', model.reason)}",
        extra,
    )


def information_criterion(fun, n_rows: int, models: dict, n_params: int) -> float:
    """BIC of whitened residuals ``fun`` (channels stacked, n_rows each) with effective sample sizes:
    ``N ln(RSS / N) + p ln N`` with ``RSS = sum_c (n_eff_c / n) |z_c|^2`` and ``N = sum_c n_eff_c``
    (white noise: the plain BIC of :func:`~femast.experiments.fitting.bic`)."""
    z = np.asarray(fun, float).reshape(len(models), n_rows)
    f = np.array([m.n_eff / n_rows for m in models.values()])
    N = float(np.sum(f) * n_rows)
    rss = float(np.sum(f * np.sum(z**2, axis=1)))
    return float(N * math.log(max(rss, 1e-300) / N) + n_params * math.log(N))
