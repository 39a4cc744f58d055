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
from scipy.optimize import OptimizeResult, least_squares

from .. import progress
from ..effects.base import resolve
from ..errors import ModelError
from .core import EffectStack, Experiment, Measured, effect_context
from .fe_jacobian import LOG_RANGE, POLISH_MIN_DECREASE, _Coords, _FEJacobian, _forward_differences, _polish  # noqa: F401
from .residuals import noise_floor

_BAD = 1e6  # whitened residual given to a non-finite prediction (a parameter set the model rejects)


def _specs(exp: Experiment, impls):
    """[(full name, Parameter, owner effect or None)] of the baseline and the effects."""
    specs = [(p.name, p, None) for p in exp.parameters]
    for name, impl in impls:
        specs += [(f"{name}.{p.name}", p, name) for p in impl.parameters]
    return specs


def _split(specs, values):
    base, eff = {}, {}
    for (_full, p, owner), v in zip(specs, values):
        if owner is None:
            base[p.name] = float(v)
        else:
            eff.setdefault(owner, {})[p.name] = float(v)
    return base, eff


def predict(exp: Experiment, data: Measured, params=None, effects=None) -> dict:
    """Predicted channels ``{channel: (n,) array}`` of a model variant.

    params : baseline parameters (defaults for those not given), SI.
    effects : ``{effect name: {param: value}}`` (missing effect parameters take their defaults)
        or a sequence of effect names (all defaults).
    """
    exp.require_model("the model")
    effects = effects or {}
    if not isinstance(effects, dict):
        effects = {name: {} for name in effects}
    impls = resolve(exp, list(effects))
    items = []
    for name, impl in impls:
        vals = {p.name: float(p.default) for p in impl.parameters}
        unknown = set(effects[name]) - set(vals)
        if unknown:
            raise ModelError(
                f"effect {name} on {exp.name} has no parameter(s) {', '.join(sorted(unknown))}; "
                f"its parameters: {', '.join(vals) or '(none)'}"
            )
        vals.update(effects[name])
        items.append((name, impl, vals))
    p = exp.defaults()
    unknown = set(params or {}) - set(p)
    if unknown:
        raise ModelError(f"{exp.name} has no parameter(s) {', '.join(sorted(unknown))}; its parameters: {', '.join(p)}")
    p.update(params or {})
    parts = data.group_subsets() or [(slice(None), data)]  # group by group: each starts from rest
    out = {c: np.empty(data.n) for c in exp.channels}
    for rows, part in parts:
        o = exp.model(p, part, EffectStack(items, effect_context(exp, part)), exp.options)
        missing = [c for c in exp.channels if c not in o]
        if missing:
            raise ModelError(f"the model of {exp.name} did not return channel(s) {', '.join(missing)}")
        for c in exp.channels:
            out[c][rows] = np.asarray(o[c], dtype=float).reshape(part.n)
    progress.tick()
    if data.offsets:
        out = with_offsets(exp, data, out)
    return out


def with_offsets(exp: Experiment, data: Measured, predicted: dict) -> dict:
    """``predicted`` plus a zero of its own for every group and channel (``data.offsets``): the mean
    of the channel's residual over the group -- each station re-zeroed, fitted in closed form."""
    out = {}
    groups = data.group_rows() or [("all", np.ones(data.n, bool))]
    for c in exp.channels:
        y = np.array(predicted[c], float)
        for _, rows in groups:
            y[rows] += np.mean(data[c][rows] - y[rows])
        out[c] = y
    return out


def n_offsets(exp: Experiment, data: Measured) -> int:
    """Parameters the offsets add (one per group and channel), counted in the information criterion."""
    return data.n_groups * len(exp.channels) if data.offsets else 0


def channel_residuals(exp: Experiment, data: Measured, predicted: dict) -> dict:
    """``{channel: measured - predicted}`` in the channel units."""
    return {c: data[c] - predicted[c] for c in exp.channels}


def estimate_noise(exp: Experiment, residuals: dict) -> dict:
    """Noise floor of every channel from its residual (:func:`~.residuals.noise_floor`), channel units.

    A channel whose estimate vanishes (noise-free data) gets 1e-9 of its residual scale (or 1e-12)
    so that whitening stays finite."""
    out = {}
    for c, r in residuals.items():
        s = noise_floor(r)
        floor = 1e-9 * max(float(np.max(np.abs(r))), 1e-3) if r.size else 1e-12
        out[c] = max(s, floor, 1e-300)
    return out


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
    base, eff = _split(specs, x)
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
    specs = _specs(exp, impls)
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
        fitted (held-out validation, :mod:`femast.experiments.heldout`); needs ``noise``.

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
    specs = _specs(exp, impls)
    if not specs:
        return run_model(exp, data, effects=[i[0] for i in impls], noise=noise)
    start = dict(start or {})
    unknown = set(start) - {s[0] for s in specs}
    if unknown:
        raise ModelError(
            f"fit start: unknown parameter(s) {', '.join(sorted(unknown))}; accepted: {', '.join(s[0] for s in specs)}"
        )
    guess = exp.initial_guess(data, exp.options) if exp.initial_guess else {}
    x0 = []
    for full, p, owner in specs:
        if full in start:
            v = float(start[full])
            if not (p.lower <= v <= p.upper) and not given_start_clip:
                raise ModelError(
                    f"fit start: {full} = {v!r} {p.unit} lies outside its bounds [{p.lower!r}, "
                    f"{p.upper!r}]; give a start within the bounds"
                )
        else:
            v = guess.get(full, p.default) if owner is None else p.default
        x0.append(float(np.clip(v, p.lower, p.upper)))
    x0 = np.array(x0)
    scale = np.array([p.typical for _, p, _ in specs])
    fo = dict(exp.fit_options)
    # a hint for diagnose, not a least_squares option; with finite differences it also turns on the
    # run-saving Jacobians (secant updates, seeded starts, log scaling): every model
    # evaluation is an FE run
    secant = bool(fo.pop("expensive", None)) and bool(fo.get("diff_step"))
    co = _Coords(scale, np.array([secant and p.lower > 0 and p.upper >= LOG_RANGE * p.lower for _, p, _ in specs]))
    if secant and "fe_reference" in exp.options and exp.options["fe_reference"] is None:
        # every FE run of the fit starts its increments from those of the baseline model at the start
        # (femast.experiments.fe_reference): about half the Newton iterations
        exp = exp.with_options(fe_reference=_split(specs, x0)[0])
    lo = co.to_u(np.array([p.lower for _, p, _ in specs]))
    hi = co.to_u(np.array([p.upper for _, p, _ in specs]))

    def make_fun(sigma):
        def fun(u):
            base, eff = _split(specs, co.to_x(u))
            try:
                pred = predict(exp, data, base, eff)
            except (FloatingPointError, ZeroDivisionError, ValueError):
                return np.full(data.n * len(exp.channels), _BAD)
            z = np.concatenate([(data[c] - pred[c]) / sigma[c] for c in exp.channels])
            return np.where(np.isfinite(z), z, _BAD)

        return fun

    # start candidates: the given/default start, then each effect's extra starts (zipped)
    starts = [x0]
    if multistart:
        extra = [
            (i, p.starts)
            for i, (_, p, owner) in enumerate(specs)
            if owner is not None and p.starts and specs[i][0] not in start
        ]
        for k in range(max((len(st) for _, st in extra), default=0)):
            x = x0.copy()
            for i, st in extra:
                x[i] = np.clip(st[min(k, len(st) - 1)], specs[i][1].lower, specs[i][1].upper)
            starts.append(x)
    per_param = int(fo.pop("max_nfev_per_param", 100))
    if nfev_per_param:
        per_param = min(per_param, int(nfev_per_param))
    fd_step = fo.pop("diff_step", None)
    kw = dict(method="trf", xtol=1e-10, ftol=1e-10, gtol=1e-10, x_scale=1.0)
    kw.update(fo)
    kw["max_nfev"] = max_nfev or kw.get("max_nfev") or per_param * (len(specs) + 1)

    n_res = data.n * len(exp.channels)

    def sigma_rows(sigma):
        return np.concatenate([np.broadcast_to(np.asarray(sigma[c], float), (data.n,)) for c in exp.channels])

    def seed(sens, sigma, x):
        """Whitened, scaled start Jacobian from known sensitivities d(predicted)/d(parameter) (NaN: unknown)."""
        if not secant or not sens:
            return None
        J0 = np.full((n_res, len(specs)), np.nan)
        dxdu = co.dx_du(co.to_u(np.asarray(x, float)))
        rows = sigma_rows(sigma)
        for i, (full, _, _) in enumerate(specs):
            col = sens.get(full)
            if col is not None and np.shape(col) == (n_res,):
                J0[:, i] = -np.asarray(col, float) * dxdu[i] / rows
        return J0 if np.isfinite(J0).any() else None

    def solve(sigma, candidates, J0=None):
        best = None
        fun0 = make_fun(sigma)
        nfev = runs = 0
        for k, x in enumerate(candidates):
            u0 = co.start(x, lo, hi) if secant else np.clip(x / scale, lo, hi)
            fj = None
            fun = fun0
            if fd_step:
                fj = _FEJacobian(fun0, float(fd_step), lo, hi, secant=secant, J0=J0 if k == 0 and secant else None)
                fun, kw["jac"] = fj.value, fj.jac
            kw_k = kw
            min_dec = POLISH_MIN_DECREASE if secant and noise is not None else 0.0
            if min_dec:
                # a noise model given: the cost is half the chi-square, and a decrease below min_dec is no
                # reason for more FE runs (see _polish); scipy's ftol is relative to the current cost,
                # bounded here by the start's (the start's run is the fit's first evaluation anyway)
                f0 = fun(u0)
                kw_k = {**kw, "ftol": max(float(kw.get("ftol", 1e-8)), min_dec / max(0.5 * float(f0 @ f0), 1e-300))}
            with np.errstate(all="ignore"):
                sol = least_squares(fun, u0, bounds=(lo, hi), **kw_k)
            nfev += sol.nfev
            if fj is not None:
                if secant:
                    sol = _polish(sol, fj, fun, lo, hi, kw, min_dec)
                nfev += getattr(sol, "nfev_polish", 0)
                runs += fj.runs
            if best is None or sol.cost < best.cost:
                best = sol
        best.nfev_total = nfev
        best.fe_runs = runs if fd_step else nfev
        return best

    if noise is None:
        if rows is not None:
            raise ModelError("a fit on some rows (rows=...) needs the noise of every channel (noise=...)")
        base, eff = _split(specs, x0)
        sigma0 = estimate_noise(exp, channel_residuals(exp, data, predict(exp, data, base, eff)))
        sol = solve(sigma0, starts, seed(start_sensitivity, sigma0, x0))
        base, eff = _split(specs, co.to_x(sol.x))
        sigma = estimate_noise(exp, channel_residuals(exp, data, predict(exp, data, base, eff)))
        if secant and len(exp.channels) == 1:
            # one channel, one noise level: the whitened residual only changes by a constant factor, so
            # the minimiser and the covariance are the same; rescale instead of refitting
            f = sigma0[exp.channels[0]] / sigma[exp.channels[0]]
            sol.fun, sol.jac, sol.cost = sol.fun * f, sol.jac * f, sol.cost * f * f
        else:
            ratio = sigma_rows(sigma0) / sigma_rows(sigma)  # warm start: the last Jacobian, rows re-weighted
            sol2 = solve(sigma, [co.to_x(sol.x)], sol.jac * ratio[:, None] if secant else None)
            sol2.nfev_total += sol.nfev_total
            sol2.fe_runs += sol.fe_runs
            sol = sol2
    else:
        sigma = {c: _sigma_of(noise, c, data.n) for c in exp.channels}
        if rows is not None:  # rows not fitted weigh nothing: an infinite noise
            rows = np.asarray(rows, bool)
            sigma = {c: np.where(rows, np.broadcast_to(v, (data.n,)), np.inf) for c, v in sigma.items()}
        sol = solve(sigma, starts, seed(start_sensitivity, sigma, x0))
    x = co.to_x(sol.x)
    dxdu = co.dx_du(sol.x)
    stderr, cov, note = _covariance(sol.jac, sol.cost, sol.fun.size, dxdu)
    if note:
        idx = [int(i) for i in note.split(": ")[1].split(", ")]
        note = "not identifiable from these data: " + ", ".join(specs[i][0] for i in idx)
    base, eff = _split(specs, x)
    predicted = predict(exp, data, base, eff)
    msg = sol.message.rstrip(".") + (f"; {note}" if note else "")
    out = _result(
        exp,
        data,
        specs,
        x,
        stderr,
        cov,
        sigma,
        predicted,
        True,
        bool(sol.success),
        msg,
        sol.nfev_total,
        [i[0] for i in impls],
    )
    sr = sigma_rows(sigma)
    with np.errstate(invalid="ignore"):  # rows not fitted: their columns stay NaN (unknown)
        out.sensitivity = {full: -sol.jac[:, i] * sr / dxdu[i] for i, (full, _, _) in enumerate(specs)}
    out.fe_runs = int(sol.fe_runs)
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
