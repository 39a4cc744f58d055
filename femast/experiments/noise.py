"""The noise model of each channel, one for ``compare`` and ``diagnose``, reported with its source.

Where the level comes from, in order of preference:

1. **given** -- the user's sensor uncertainty: a ``sigma_<channel>`` column (per row) or a value per
   channel (``sigma={"dx_m": 2e-5}`` in Python, ``--sigma dx_m=2e-5`` on the command line, e.g. from
   the sensor's datasheet); used as it is;
2. **repeatability** -- rows that repeat their inputs in a hold (:func:`repeated_points`: the
   difference of two readings of the same state is noise only), at least 30 pairs; or repeated passes
   of the path (below), which only ever lower the residual's estimate;
3. **residual** -- the fallback: the differences of a model's residual along the path (the
   response changes little from one row to the next, the noise does; see
   :func:`~femast.experiments.residuals.noise_floor`), white, heteroscedastic or serially correlated.

All three are computed where the data allow; the report prints them side by side when they
disagree by more than ``DISAGREE`` = 1.5x (a datasheet value far above the repeatability says the
sensor is better than its specification, or that its error is a bias the residual cannot see; a
residual estimate far above both says the model's error is taken for noise).  The residual-based
estimate, channel by channel:

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
  establish a noise 5x below the typical; Stohlman & Pellegrino, Eq. 15's range on the paper's latch is 0.45).  The model is kept when
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

* **resolution** -- readings recorded to a fixed step carry a rounding error that estimates built on
  differences do not see where readings repeat (:mod:`femast.experiments.resolution`): printed as
  the source ``resolution``, a floor under every level estimated from the data (a given level is
  used as it is).

Fewer than ``MIN_ROWS`` = 8 rows (without ``sigma_`` columns) leave too few differences for any
estimate: a :class:`~femast.errors.ModelError`.  Correlation and heteroscedasticity are only tested
from ``MIN_ROWS_STRUCTURE`` = 60 rows (below that the white estimate is used and the report says so).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import DataFileError, ModelError
from .noise_estimators import (  # noqa: F401  (re-exported: the estimators of the model)
    CYCLE_MIN_PAIRS,
    HETERO_LR,
    MIN_ROWS,
    MIN_ROWS_STRUCTURE,
    VAR_FLOOR,
    ar1_factor,
    ar1_threshold,
    cycle_scatter,
    difference_phi,
    effective_n,
    heteroscedastic_fit,
    informative_rows,
    lag1,
    repeated_points,
    robust_rms,
)
from .residuals import load_path, noise_floor
from .resolution import rounding_floors

HETERO_MIN_RANGE = 1.3
DISAGREE = 1.5  # sources of the level that differ by more than this are printed side by side
CYCLE_MIN_RATIO = 0.05  # repeated passes that agree to below this share of the level are not noise


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
    source: str = "residual"
    levels: dict = field(default_factory=dict)

    @property
    def sigma_rms(self) -> float:
        return float(np.sqrt(np.mean(self.sigma**2)))

    @property
    def disagree(self) -> bool:
        """True if the sources of the level differ by more than ``DISAGREE`` (the resolution is a
        floor: it disagrees only with an estimate below it)."""
        v = [x for k, x in self.levels.items() if x > 0 and k != "resolution"]
        floor = self.levels.get("resolution", 0.0)
        if floor > 0 and (not v or floor > min(v)):
            v.append(floor)
        return len(v) > 1 and max(v) > DISAGREE * min(v)

    def to_json(self) -> dict:
        return {
            "source": self.source,
            "levels": dict(self.levels),
            "disagree": self.disagree,
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


def noise_model(
    exp, data, fit_result, correlate: bool = True, generic: bool = True, pinned=None, sigma=None, judged: bool = True
) -> dict:
    """``{channel: ChannelNoise}`` of a model run or fit (module docstring): the given level, else the
    repeatability, else the residual-based model, with every source's level in ``levels``.

    correlate : test the residual for serial correlation and check it against repeated passes
    (``diagnose`` first estimates the baseline's without them and with the experiment's own
    covariates only -- a structured residual would pass for noise growing with the reading --, for
    the weights of its refits; then the best model's, for the verdict).  generic : also test the
    size of the reading as a covariate.  pinned : ``{channel: (n,) bool}`` rows to leave out besides
    the fit's own pinned rows (:func:`pinned_rows` of another fit).  sigma : ``{channel: level}`` the
    user's sensor uncertainty (channel unit), or None.  judged : the model a run is judged by: a
    varying level or serial correlation estimated from the residual is kept only where the residual
    whitened by it shows no structure (:func:`plain_unless_noise`)."""
    covs = {}
    pred = fit_result.predicted
    for c in exp.channels:
        covs[c] = {"size of the reading": np.abs(pred[c])} if generic else {}
    if getattr(exp, "noise_covariates", None) is not None:
        extra = exp.noise_covariates(data, dict(fit_result.params), exp.options, fit_result) or {}
        for c, d in extra.items():
            covs.setdefault(c, {}).update(d)
    coord = path_coordinate(exp, data) if correlate else None
    inputs = input_matrix(exp, data)
    user = check_sigma(exp, sigma)
    floors = rounding_floors(exp, data, pred, input_names(exp, data))
    out = {}
    for c in exp.channels:
        r = fit_result.residuals[c]
        pin = (pinned or {}).get(c)
        given = given_sigma(data, c)
        if data.n < MIN_ROWS and (given is not None or c in user):  # too few rows to estimate, a level given
            g = given if given is not None else np.full(data.n, user[c])
            out[c] = _fixed(None, c, g, "given", "given; too few rows for any other estimate")
            out[c].levels = {"given": out[c].sigma_rms}
            continue
        model = channel_noise(c, r, data.n, covs.get(c), None, correlate, pin)
        if judged:
            model = plain_unless_noise(model, r, pin)
        if coord is not None:
            model = with_cycles(model, coord, r, pin)
        levels = {"residual": model.sigma_rms}
        if "cycle_ratio" in model.extra:
            rho = model.extra["cycle_ratio"]
            if model.kind.endswith("+cycles"):  # the level was brought down to the passes'
                levels = {"residual": model.sigma_rms / rho, "repeated passes": model.sigma_rms}
            else:
                levels["repeated passes"] = rho * model.sigma_rms
        rep = repeated_points(inputs, r, _keep(r, pin)) if inputs is not None else None
        if rep is not None:
            levels["repeated points"] = rep[0]
        if given is not None:
            model = _fixed(model, c, given, "given", f"sigma_{c} column: the per-row uncertainty given with the data")
            levels["given"] = model.sigma_rms
        elif c in user:
            model = _fixed(model, c, np.full(data.n, user[c]), "given", "the sensor uncertainty given for the channel")
            levels["given"] = user[c]
        elif rep is not None:
            model = _fixed(
                model,
                c,
                np.full(data.n, rep[0]),
                "repeated points",
                f"repeatability: {rep[1]} pairs of rows that repeat their inputs in a hold",
            )
        elif model.kind.endswith("+cycles"):
            model.source = "repeated passes"
        if c in floors:
            levels["resolution"] = floors[c][0]
            model = with_floor(model, *floors[c])
        model.levels = levels
        out[c] = model
    return out


def with_floor(model: ChannelNoise, level: float, reason: str) -> ChannelNoise:
    """``model`` with no row's level below the rounding floor ``level`` (a given level as it is)."""
    if model.kind == "given" or np.all(model.sigma >= level):
        return model
    sigma, source = np.maximum(model.sigma, level), model.source if model.sigma_rms >= level else "resolution"
    if source != "resolution":  # a few rows raised: the estimate stands
        why = f"{model.reason}; no row below {reason}"
    else:  # the estimate is below the rounding: the floor is the level
        why = f"at least {reason} (the estimate from the {model.source}, {model.sigma_rms:.3g}, is below it)"
    return ChannelNoise(
        model.channel, model.kind, sigma, model.phi, model.n_eff, model.covariate, why, dict(model.extra), source
    )


def plain_unless_noise(model: ChannelNoise, r, pinned=None) -> ChannelNoise:
    """``model``, or the white level from the residual's second differences where the residual,
    whitened by ``model``, still shows smooth structure along the path.

    A level growing with a covariate and serial correlation are estimated from the residual of a
    model; where that model misses a mechanism, its error lasts along the path and grows with the
    load, and passes for noise growing with the reading or for correlated noise (a baseline's misfit
    at the largest loads would raise the noise there and lower every ratio).  Smooth structure shows
    as a lag-1 autocorrelation of the whitened residual above the one its differences allow
    (:func:`difference_phi`: nearly blind to smooth structure, not to correlated noise) by more than
    twice their scatter (``2 x 1.9 / sqrt(n)``).  Then the plain level -- second differences, nearly
    blind to the model's error -- is the honest one; otherwise ``model`` stands (on latch-pull data
    without a hidden effect the lag-1 autocorrelation is -0.07 to -0.03 and the difference estimate
    -0.09 to 0.15; with a hidden latch hysteresis or friction 0.64-0.69 against 0.05)."""
    if model.kind in ("white", "given"):
        return model
    r = np.asarray(r, float)
    keep = _keep(r, pinned)
    u = (r / model.sigma)[keep]
    m = u.size
    if m < MIN_ROWS_STRUCTURE:
        return model
    rho, dphi = lag1(u), difference_phi(u)
    if rho <= max(dphi, 0.0) + 2.0 * 1.9 / math.sqrt(m):
        return model
    level = max(noise_floor(r[keep]), 1e-300)
    return ChannelNoise(
        model.channel,
        "white",
        np.full(r.size, level),
        0.0,
        float(r.size),
        None,
        f"constant level: whitened by the {model.kind} model the residual keeps a lag-1 autocorrelation of "
        f"{rho:.2f} where its differences allow {max(dphi, 0.0):.2f}: what that model takes for a varying or "
        "correlated noise is structure the model misses",
    )


def _fixed(model: ChannelNoise, channel: str, sigma, source: str, reason: str) -> ChannelNoise:
    """A model whose level is not estimated from the residual (given, repeatability): white, kept."""
    sigma = np.asarray(sigma, float)
    return ChannelNoise(
        channel, "given" if source == "given" else "white", sigma, 0.0, float(sigma.size), None, reason, {}, source
    )


def check_sigma(exp, sigma) -> dict:
    """``{channel: level > 0}`` of the user's sensor uncertainties, checked (channel names, values)."""
    out = {}
    for c, v in dict(sigma or {}).items():
        if c not in exp.channels:
            raise ModelError(
                f"sensor uncertainty for '{c}': not a compared channel of {exp.name}; its channels: "
                f"{', '.join(exp.channels)}"
            )
        try:
            v = float(v)
        except (TypeError, ValueError):
            raise ModelError(f"sensor uncertainty of {c}: {v!r} is not a number (in {exp.unit_of(c)})") from None
        if not (math.isfinite(v) and v > 0):
            raise ModelError(f"sensor uncertainty of {c}: {v!r} {exp.unit_of(c)}; give a finite value > 0")
        out[c] = v
    return out


def input_names(exp, data) -> list:
    """The experiment's input columns in the data (not channels, time, ``sigma_`` or group)."""
    skip = set(exp.channels) | {"t_s", "group"}
    cols = [c.name for c in exp.columns if c.name not in skip and c.name in data.columns]
    return [c for c in cols if not c.startswith("sigma_")]


def input_matrix(exp, data):
    """(n, k) the experiment's input columns in the data (:func:`input_names`), or None."""
    cols = input_names(exp, data)
    return np.column_stack([data[c] for c in cols]) if cols else None


def path_coordinate(exp, data) -> np.ndarray | None:
    """The quantity the test drives along its passes (``Experiment.path_coordinate``, else the load
    measure of the segmentation), for :func:`cycle_scatter`; None if it cannot be evaluated."""
    try:
        if getattr(exp, "path_coordinate", None) is not None:
            return np.asarray(exp.path_coordinate(data, exp.options), float)
        return np.asarray(load_path(exp, data), float)
    except Exception:  # a coordinate is optional: no repeated-pass check rather than a failed diagnosis
        return None


def pinned_rows(fit_result, channels) -> dict:
    """``{channel: (n,) bool}`` rows of a fit's residual that carry no noise (:func:`informative_rows`)."""
    return {c: ~informative_rows(fit_result.residuals[c]) for c in channels}


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
    if rho < CYCLE_MIN_RATIO:  # the passes agree far better than any noise: rows the model admits exactly
        return model
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
