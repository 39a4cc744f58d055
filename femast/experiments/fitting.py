"""Running and fitting an experiment's model along the measured path.

:func:`run_model` evaluates a model variant (baseline parameters plus switched-on effects)
without fitting; :func:`fit` fits it with :func:`scipy.optimize.least_squares`.  Both return a
scipy-like result (``x``, ``success``, ``message``, ``nfev``, ...; see :func:`fit`).

Weights and uncertainties
-------------------------
The residual of channel c is ``r_c = measured_c - predicted_c`` in the channel's unit; the fit
minimises the sum of the whitened residuals ``(r_c / sigma_c)^2`` with ``sigma_c`` the noise of
the channel (estimated from the residuals, :func:`~femast.experiments.residuals.noise_floor`,
unless given), so channels in different units and with different noise weigh fairly.  Parameter
covariances come from the Jacobian J of the whitened residuals at the solution,
``cov = s^2 (J^T J)^-1`` with ``s^2 = |z|^2 / (n - p)``; directions the data do not determine
(singular values below 1e-10 of the largest) get ``stderr = inf``.

Information criterion
---------------------
``bic = n ln(|z|^2 / n) + p ln(n)`` with n the number of residual values (rows x channels) and
p the number of fitted parameters; the diagnosis compares it between model variants with the same
``sigma_c``.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import OptimizeResult

from ..effects.base import resolve
from ..errors import ModelError
from .core import Experiment, Measured
from .fe_jacobian import LOG_RANGE, POLISH_MIN_DECREASE, _Coords, _FEJacobian, _forward_differences, _polish  # noqa: F401
from .fit_problem import FitProblem
from .prediction import (  # noqa: F401  (predict, MODEL_FAILURES: re-exported, fitting's public names)
    MODEL_FAILURES,
    channel_residuals,
    estimate_noise,
    n_offsets,
    parameter_specs,
    predict,
    split_parameters,
)


def summary_numbers(exp: Experiment, residuals: dict, sigma: dict) -> dict:
    """rms (error unit), per-channel rms, noise_rms (error unit) and ratio (whitened rms)."""
    w = {c: exp.weight(c) for c in residuals}
    e2 = np.concatenate([(w[c] * r) ** 2 for c, r in residuals.items()])
    z2 = np.concatenate([(r / sigma[c]) ** 2 for c, r in residuals.items()])
    noise_rms = math.sqrt(np.mean([(w[c] * sigma[c]) ** 2 for c in residuals]))
    return {
        "rms": float(np.sqrt(e2.mean())),
        "channel_rms": {c: float(np.sqrt(np.mean(r**2))) for c, r in residuals.items()},
        "noise_rms": float(noise_rms),
        "ratio": float(np.sqrt(z2.mean())),
        "rss": float(z2.sum()),
        "n_obs": int(z2.size),
    }


def bic(rss: float, n_obs: int, n_params: int) -> float:
    """Bayesian information criterion ``n ln(rss / n) + p ln(n)`` of whitened residuals."""
    return float(n_obs * math.log(max(rss, 1e-300) / n_obs) + n_params * math.log(n_obs))


def _result(exp, data, specs, x, stderr, cov, sigma, predicted, fitted, success, message, nfev, effects):
    res = channel_residuals(exp, data, predicted)
    nums = summary_numbers(exp, res, sigma)
    base, eff = split_parameters(specs, x)
    p = len(x) + n_offsets(exp, data) if fitted else 0
    z = np.concatenate([res[c] / sigma[c] for c in exp.channels])
    at_bound = [
        full
        for (full, prm, _), v in zip(specs, x)
        if fitted
        and (
            np.isclose(v, prm.lower, rtol=1e-6, atol=1e-12 * prm.typical)
            or np.isclose(v, prm.upper, rtol=1e-6, atol=1e-12 * prm.typical)
        )
    ]
    return OptimizeResult(
        x=np.asarray(x, float),
        names=tuple(s[0] for s in specs),
        units=tuple(s[1].unit for s in specs),
        stderr=np.asarray(stderr, float),
        cov=cov,
        params=base,
        effect_params=eff,
        effects=tuple(effects),
        success=bool(success),
        message=message,
        nfev=int(nfev),
        cost=0.5 * float(z @ z),
        fun=z,
        predicted=predicted,
        residuals=res,
        noise=dict(sigma),
        rms=nums["rms"],
        channel_rms=nums["channel_rms"],
        noise_rms=nums["noise_rms"],
        ratio=nums["ratio"],
        n_obs=nums["n_obs"],
        n_params=p,
        bic=bic(nums["rss"], nums["n_obs"], p),
        fitted=bool(fitted),
        at_bound=at_bound,
        experiment=exp.name,
        error_unit=exp.error_unit,
    )


def run_model(exp: Experiment, data: Measured, params=None, effects=None, noise=None) -> OptimizeResult:
    """Evaluate a model variant without fitting; same result fields as :func:`fit` (stderr NaN).

    effects : names, or ``{name: {param: value}}``; noise : ``{channel: sigma}`` (default: estimated
    from the residuals)."""
    effects = effects or {}
    if not isinstance(effects, dict):
        effects = {name: {} for name in effects}
    impls = resolve(exp, list(effects))
    specs = parameter_specs(exp, impls)
    vals = {**exp.defaults(), **(params or {})}
    for name, impl in impls:
        for prm in impl.parameters:
            vals[f"{name}.{prm.name}"] = effects[name].get(prm.name, prm.default)
    x = [vals[s[0]] for s in specs]
    predicted = predict(exp, data, {k: v for k, v in vals.items() if "." not in k}, effects)
    sigma = noise or estimate_noise(exp, channel_residuals(exp, data, predicted))
    n = len(x)
    return _result(
        exp,
        data,
        specs,
        x,
        np.full(n, np.nan),
        np.full((n, n), np.nan),
        sigma,
        predicted,
        False,
        True,
        "model run with given parameters (not fitted)",
        1,
        [i[0] for i in impls],
    )


def _covariance(J, cost, n, scale):
    p = J.shape[1]
    dof = n - p
    if dof <= 0:
        return np.full(p, np.inf), np.full((p, p), np.inf), "more parameters than residuals"
    s2 = 2.0 * cost / dof
    _, sv, Vt = np.linalg.svd(J, full_matrices=False)
    good = sv > 1e-10 * sv[0] if sv.size and sv[0] > 0 else np.zeros(p, bool)
    inv = (Vt[good].T / sv[good] ** 2) @ Vt[good]
    cov = s2 * scale[:, None] * inv * scale[None, :]
    stderr = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    note = ""
    if not np.all(good):
        null = np.abs(Vt[~good]).max(axis=0) > 1e-6
        stderr = np.where(null, np.inf, stderr)
        note = "not identifiable from these data: " + ", ".join(str(i) for i in np.flatnonzero(null))
    return stderr, cov, note


def fit(
    exp: Experiment,
    data: Measured,
    effects=(),
    *,
    start=None,
    noise=None,
    multistart: bool = True,
    max_nfev: int | None = None,
    given_start_clip: bool = False,
    nfev_per_param: int | None = None,
    start_sensitivity: dict | None = None,
    rows=None,
    screen: dict | None = None,
) -> OptimizeResult:
    """Fit the baseline parameters and those of the switched-on ``effects`` to the data.

    effects : effect names (``femast.effects``) applicable to the experiment.
    start : ``{name: value}`` start values (baseline names, ``"effect.param"`` for effects); the
        default is the experiment's ``initial_guess`` (or its defaults) and the effects' defaults.
    noise : ``{channel: sigma}`` fixed weights, a level or per-row levels (n,) (a heteroscedastic
        noise model); default: estimated from the residuals of a first fit, then refitted with them.
    multistart : also start the effect parameters from their ``starts`` and keep the best fit.
    given_start_clip : clip given starts outside the bounds into them (diagnose passes the values of
        other fits) instead of raising ModelError naming the parameter.
    nfev_per_param : cap of the evaluations per start, ``x (p + 1)`` (the smaller of it and the
        experiment's ``max_nfev_per_param``); diagnose's refits use 25.
    start_sensitivity : ``{name: d(predicted, channels concatenated)/d(parameter)}`` known at the
        start (the ``sensitivity`` of an earlier fit, e.g. the baseline's for diagnose's refits): the
        first Jacobian of an expensive experiment fitted by finite differences takes these
        columns instead of FE runs.  The Jacobian at the solution (covariance) is always computed.
    rows : (n,) bool, the rows the fit sees (default all): the model still runs along the whole path
        -- its state at a row depends on the rows before -- and the other rows are predicted, not
        fitted (held-out validation, :mod:`femast.experiments.heldout`); needs ``noise``.  Such a fit
        is not polished (no finite-difference Jacobian at its solution: its covariance is not needed).
    screen : a candidate's screening in ``diagnose`` (:mod:`femast.experiments.screening`; expensive
        models with a given ``noise``): when its linearisation at every start shows it cannot be
        significant, the fit stops there and the result has ``screened`` True, the parameters and
        residual of the model run where it stopped, and ``screen`` (the linearisations).

    Returns an ``OptimizeResult`` with ``x``, ``names``, ``units``, ``stderr``, ``cov``,
    ``params`` (baseline ``{name: value}``), ``effect_params`` (``{effect: {name: value}}``),
    ``success``, ``message``, ``nfev``, ``cost``, ``fun`` (whitened residuals), ``predicted``,
    ``residuals`` (``{channel: array}``), ``noise``, ``rms`` (error unit), ``channel_rms``,
    ``noise_rms``, ``ratio`` (rms / noise), ``bic``, ``n_obs``, ``n_params``, ``at_bound``,
    ``sensitivity`` (``{name: d predicted / d parameter}`` at the solution, channels concatenated)
    and ``fe_runs`` (model evaluations, Jacobian columns included).

    Experiments whose model evaluations are expensive and fitted by finite differences
    (``fit_options`` with ``expensive`` and ``diff_step``: the FE ones) take Broyden secant updates of the Jacobian between finite-difference ones and a finite-difference
    Jacobian at the solution, from which a Gauss-Newton check restarts the fit when it predicts a
    further decrease beyond ``ftol`` (see :class:`_FEJacobian`, :func:`_polish`).
    """
    exp.require_model("a fit")
    if isinstance(effects, str):
        effects = [e for e in effects.split(",") if e.strip()]
    impls = resolve(exp, list(effects))
    specs = parameter_specs(exp, impls)
    if not specs:
        return run_model(exp, data, effects=[i[0] for i in impls], noise=noise)
    pb = FitProblem(exp, data, specs, start, given_start_clip, max_nfev, nfev_per_param)
    starts = pb.starts(multistart, start or {})
    if noise is None:
        if rows is not None:
            raise ModelError("a fit on some rows (rows=...) needs the noise of every channel (noise=...)")
        sol, sigma = pb.solve_estimating_noise(starts, start_sensitivity)
    else:
        sigma = {c: _sigma_of(noise, c, data.n) for c in exp.channels}
        if rows is not None:  # rows not fitted weigh nothing: an infinite noise
            rows = np.asarray(rows, bool)
            sigma = {c: np.where(rows, np.broadcast_to(v, (data.n,)), np.inf) for c, v in sigma.items()}
        sol = pb.solve(
            sigma,
            starts,
            pb.seed(start_sensitivity, sigma, pb.x0),
            noise_given=True,
            screen=screen,
            polish=rows is None,
        )
        if getattr(sol, "screened", False):
            return _screened(pb, sol, sigma, [i[0] for i in impls])
    return _fitted(pb, sol, sigma, [i[0] for i in impls])


def _screened(pb, sol, sigma, effect_names) -> OptimizeResult:
    """The result of a refit stopped by its screening: the model run where its best start stopped
    (parameters, prediction, residual), without standard errors; ``screened`` True, ``screen``."""
    exp, data, specs = pb.exp, pb.data, pb.specs
    x = pb.co.to_x(sol.u)
    n, p = data.n, len(x)
    r = np.asarray(sol.r, float).reshape(len(exp.channels), n)
    predicted = {c: data[c] - r[i] for i, c in enumerate(exp.channels)}
    msg = "screened out: it cannot be significant (stopped before a full refit)"
    nan = np.full(p, np.nan)
    out = _result(
        exp, data, specs, x, nan, np.full((p, p), np.nan), sigma, predicted, True, True, msg, sol.fe_runs, effect_names
    )
    out.screened, out.screen = True, sol
    out.sensitivity, out.fe_runs, out.skipped = None, int(sol.fe_runs), len(pb.skipped)
    out.fe_reference = exp.options.get("fe_reference")
    return out


def _fitted(pb, sol, sigma, effect_names) -> OptimizeResult:
    """The fit result at the solution ``sol`` of a :class:`FitProblem`: covariance, prediction,
    the parameter sets skipped, the sensitivities (which seed later fits' Jacobians)."""
    exp, data, specs = pb.exp, pb.data, pb.specs
    x = pb.co.to_x(sol.x)
    dxdu = pb.co.dx_du(sol.x)
    stderr, cov, note = _covariance(sol.jac, sol.cost, sol.fun.size, dxdu)
    if note:
        idx = [int(i) for i in note.split(": ")[1].split(", ")]
        note = "not identifiable from these data: " + ", ".join(specs[i][0] for i in idx)
    base, eff = split_parameters(specs, x)
    predicted = predict(exp, data, base, eff)
    msg = sol.message.rstrip(".") + (f"; {note}" if note else "")
    if pb.skipped:
        msg += f"; {len(pb.skipped)} parameter set(s) skipped, the model failed there (first: {pb.skipped[0][1]})"
    out = _result(
        exp, data, specs, x, stderr, cov, sigma, predicted, True, bool(sol.success), msg, sol.nfev_total, effect_names
    )
    sr = pb.sigma_rows(sigma)
    with np.errstate(invalid="ignore"):  # rows not fitted: their columns stay NaN (unknown)
        out.sensitivity = {full: -sol.jac[:, i] * sr / dxdu[i] for i, (full, _, _) in enumerate(specs)}
    out.fe_runs = int(sol.fe_runs)
    out.skipped = len(pb.skipped)
    out.fe_reference = exp.options.get("fe_reference")  # the reference run of the fit's FE runs, or None
    return out


def _sigma_of(noise: dict, channel: str, n: int):
    """A channel's noise: one level (float) or per-row levels ((n,) array, all > 0), checked."""
    v = np.asarray(noise[channel], dtype=float)
    if v.ndim == 0:
        return float(v)
    if v.shape != (n,) or not np.all(np.isfinite(v) & (v > 0)):
        raise ModelError(
            f"noise of {channel}: need one level or {n} finite positive per-row levels, got shape {v.shape}"
        )
    return v


def params_table(result: OptimizeResult) -> dict:
    """``{name: {"value", "stderr", "unit"}}`` of a fit or model run (JSON-ready; inf/NaN -> None)."""
    out = {}
    for name, v, e, u in zip(result.names, result.x, result.stderr, result.units):
        out[name] = {"value": float(v), "stderr": float(e) if np.isfinite(e) else None, "unit": u}
    return out


__all__ = [
    "predict",
    "run_model",
    "fit",
    "estimate_noise",
    "channel_residuals",
    "summary_numbers",
    "bic",
    "params_table",
]
