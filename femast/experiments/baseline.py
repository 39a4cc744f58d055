"""A model variant run or fitted with its noise model: the first stage of ``compare`` and ``diagnose``.

Both commands go through :func:`fit_with_noise`, so a model compared and the baseline of a diagnosis
are the same fit, weighted by the same noise model (:mod:`femast.experiments.noise`), and their
ratios to the noise are the same numbers:

1. the variant is fitted with one noise level per channel -- the given one (``sigma_`` column, the
   user's sensor uncertainty) where there is one, else estimated from its residual;
2. the noise model of that fit, from the experiment's own covariates and without the serial
   correlation test (a structured residual would pass for noise growing with the reading or for
   correlated noise), a varying level kept only where the residual it whitens shows no structure
   (:func:`~femast.experiments.noise.plain_unless_noise`), gives the weights;
3. where they are not one level per channel (a level growing with a covariate, repeatability, a
   level given for some channels only) the variant is refitted with them, from the first fit.

:func:`score_with_noise` then scores a run under the noise model of the residual it is judged by
(:func:`~femast.experiments.noise.noise_model`, all sources and tests): the ratio to the noise
(:func:`~femast.experiments.residuals.robust_rms` of the whitened residual: robust on both sides),
the effective sample size and the at-noise threshold.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import OptimizeResult

from .fitting import fit, run_model
from .noise import check_sigma, given_sigma, noise_model
from .residuals import at_noise_threshold, robust_rms


def _given(exp, data, sigma) -> dict:
    """``{channel: level or (n,) levels}`` given for the channels that have one."""
    user = check_sigma(exp, sigma)
    out = {}
    for c in exp.channels:
        g = given_sigma(data, c)
        if g is not None:
            out[c] = g
        elif c in user:
            out[c] = user[c]
    return out


def fit_with_noise(exp, data, effects=(), *, sigma=None, fitted: bool = True, params=None, start=None):
    """``(result, models)``: the variant fitted (or run with ``params``) under the weights of its noise
    model (module docstring), and that first-stage model ``{channel: ChannelNoise}``.

    sigma : ``{channel: level}`` the user's sensor uncertainties (channel units).  params : for a
    run, ``{name: value}`` of the baseline and ``{"effect.param": value}`` entries.  start : start
    values of the fit."""
    given = _given(exp, data, sigma)
    weights = given if len(given) == len(exp.channels) else None
    if fitted:
        res = fit(exp, data, effects, noise=weights, start=start)
    else:
        res = run_variant(exp, data, effects, params, weights)
    models = noise_model(exp, data, res, correlate=False, generic=False, sigma=sigma)
    if weights is None and any(m.source != "residual" or m.kind.startswith("heteroscedastic") for m in models.values()):
        sig = {c: models[c].sigma for c in exp.channels}
        if fitted:
            res = fit(exp, data, effects, start=dict(zip(res.names, res.x)), noise=sig, given_start_clip=True)
        else:
            res = run_variant(exp, data, effects, params, sig)
    return res, models


def run_variant(exp, data, effects=(), params=None, noise=None):
    """The variant run (not fitted) with ``params`` (baseline names and ``effect.param`` entries) and
    fixed weights ``noise`` (default: estimated from the residual)."""
    params = plain_params(params)
    base = {k: v for k, v in params.items() if "." not in k}
    eff = {e: {} for e in effects}
    for k, v in params.items():
        if "." in k:
            e, p = k.split(".", 1)
            eff.setdefault(e, {})[p] = v
    return run_model(exp, data, base, eff, noise=noise)


def plain_params(params) -> dict:
    """``{name: value}`` from parameter values or a parameter table (``{name: {"value", ...}}``, the
    ``params_table`` of a compare result or the ``params`` of its compare.json)."""
    out = {}
    for k, v in dict(params or {}).items():
        out[k] = float(v["value"]) if isinstance(v, dict) else float(v)
    return out


def score_with_noise(exp, data, res, models: dict) -> OptimizeResult:
    """A model run judged under the noise ``models``: ``noise`` (per channel, (n,)), ``noise_rms``
    (error unit), ``ratio`` (robust RMS of the whitened residual), ``channel_ratio``, ``n_eff``,
    ``at_noise`` (the threshold for that many effective rows)."""
    chans = exp.channels
    sigma = {c: np.asarray(models[c].sigma, float) for c in chans}
    z = {c: res.residuals[c] / sigma[c] for c in chans}
    n_eff = min(m.n_eff for m in models.values())
    return OptimizeResult(
        noise=sigma,
        noise_rms=float(np.sqrt(np.mean([np.mean((exp.weight(c) * sigma[c]) ** 2) for c in chans]))),
        ratio=robust_rms(np.concatenate([z[c] for c in chans])),
        channel_ratio={c: robust_rms(z[c]) for c in chans},
        n_eff=float(n_eff),
        at_noise=at_noise_threshold(int(round(n_eff)), len(chans)),
    )
