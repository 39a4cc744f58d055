"""The least-squares problem of a fit (:func:`~femast.experiments.fitting.fit`): parameters, starts,
scaling, the whitened residual, the solver settings and the solve itself.

* **parameters** -- the baseline's and the effects', scaled by their typical size (in log scale for
  a positive parameter spanning two decades, on the expensive experiments); bounded;
* **starts** -- the given values, else the experiment's ``initial_guess`` and the effects'
  defaults; with multistart, also each effect parameter's ``starts`` (zipped), the best fit kept;
* **residual** -- ``(measured - predicted) / sigma`` per channel, stacked; a parameter set the model
  cannot be evaluated at (:data:`~femast.experiments.prediction.MODEL_FAILURES`) is skipped (a large
  residual) and counted, and the fit goes on;
* **solve** -- :func:`scipy.optimize.least_squares` (trust-region reflective) with the experiment's
  ``fit_options``; an expensive model fitted by finite differences gets secant Jacobians, a seeded
  first Jacobian and a Gauss-Newton polish (:mod:`femast.experiments.fe_jacobian`);
* **noise** -- given, or estimated from the residual of a first fit and the fit repeated with it.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from ..errors import ModelError
from .fe_jacobian import LOG_RANGE, POLISH_MIN_DECREASE, _Coords, _FEJacobian, _polish
from .prediction import MODEL_FAILURES, channel_residuals, estimate_noise, predict, split_parameters
from .screening import Futile, futility_check, screened_out

_BAD = 1e6  # whitened residual given to a parameter set the model rejects


class FitProblem:
    """One fit's problem (module docstring); ``skipped`` lists ``(x, error)`` of the sets skipped."""

    def __init__(self, exp, data, specs, start, given_start_clip, max_nfev, nfev_per_param):
        self.data, self.specs = data, specs
        self.x0 = self._start(exp, data, specs, dict(start or {}), given_start_clip)
        self.scale = np.array([p.typical for _, p, _ in specs])
        fo = dict(exp.fit_options)
        # a hint for diagnose, not a least_squares option; with finite differences it also turns on the
        # run-saving Jacobians (secant updates, seeded starts, log scaling): every model
        # evaluation is an FE run
        self.secant = bool(fo.pop("expensive", None)) and bool(fo.get("diff_step"))
        log = np.array([self.secant and p.lower > 0 and p.upper >= LOG_RANGE * p.lower for _, p, _ in specs])
        self.co = _Coords(self.scale, log)
        if self.secant and "fe_reference" in exp.options and exp.options["fe_reference"] is None:
            # every FE run of the fit starts its increments from those of the baseline model at the start
            # (femast.experiments.fe_reference): about half the Newton iterations
            exp = exp.with_options(fe_reference=split_parameters(specs, self.x0)[0])
        self.exp = exp
        self.lo = self.co.to_u(np.array([p.lower for _, p, _ in specs]))
        self.hi = self.co.to_u(np.array([p.upper for _, p, _ in specs]))
        per_param = int(fo.pop("max_nfev_per_param", 100))
        if nfev_per_param:
            per_param = min(per_param, int(nfev_per_param))
        self.fd_step = fo.pop("diff_step", None)
        self.kw = dict(method="trf", xtol=1e-10, ftol=1e-10, gtol=1e-10, x_scale=1.0)
        self.kw.update(fo)
        self.kw["max_nfev"] = max_nfev or self.kw.get("max_nfev") or per_param * (len(specs) + 1)
        self.n_res = data.n * len(exp.channels)
        self.skipped = []

    @staticmethod
    def _start(exp, data, specs, start, clip) -> np.ndarray:
        unknown = set(start) - {s[0] for s in specs}
        if unknown:
            raise ModelError(
                f"fit start: unknown parameter(s) {', '.join(sorted(unknown))}; accepted: "
                f"{', '.join(s[0] for s in specs)}"
            )
        guess = exp.initial_guess(data, exp.options) if exp.initial_guess else {}
        x0 = []
        for full, p, owner in specs:
            if full in start:
                v = float(start[full])
                if not (p.lower <= v <= p.upper) and not clip:
                    raise ModelError(
                        f"fit start: {full} = {v!r} {p.unit} lies outside its bounds [{p.lower!r}, "
                        f"{p.upper!r}]; give a start within the bounds"
                    )
            else:
                v = guess.get(full, p.default) if owner is None else p.default
            x0.append(float(np.clip(v, p.lower, p.upper)))
        return np.array(x0)

    def starts(self, multistart: bool, given: dict) -> list:
        """The start vectors: the start, then each effect parameter's extra starts (zipped)."""
        out = [self.x0]
        if multistart:
            specs = self.specs
            extra = [
                (i, p.starts)
                for i, (_, p, owner) in enumerate(specs)
                if owner is not None and p.starts and specs[i][0] not in given
            ]
            for k in range(max((len(st) for _, st in extra), default=0)):
                x = self.x0.copy()
                for i, st in extra:
                    x[i] = np.clip(st[min(k, len(st) - 1)], specs[i][1].lower, specs[i][1].upper)
                out.append(x)
        return out

    def fun(self, sigma):
        """The whitened residual as a function of the scaled parameters u."""
        exp, data, specs = self.exp, self.data, self.specs

        def fun(u):
            x = self.co.to_x(u)
            base, eff = split_parameters(specs, x)
            try:
                pred = predict(exp, data, base, eff)
            except MODEL_FAILURES as e:
                self.skipped.append((x, f"{type(e).__name__}: {e}"))
                return np.full(self.n_res, _BAD)
            z = np.concatenate([(data[c] - pred[c]) / sigma[c] for c in exp.channels])
            return np.where(np.isfinite(z), z, _BAD)

        return fun

    def sigma_rows(self, sigma) -> np.ndarray:
        """The noise of every residual, channels stacked."""
        n = self.data.n
        return np.concatenate([np.broadcast_to(np.asarray(sigma[c], float), (n,)) for c in self.exp.channels])

    def seed(self, sens, sigma, x):
        """Whitened, scaled start Jacobian from known sensitivities d(predicted)/d(parameter) (NaN: unknown)."""
        if not self.secant or not sens:
            return None
        J0 = np.full((self.n_res, len(self.specs)), np.nan)
        dxdu = self.co.dx_du(self.co.to_u(np.asarray(x, float)))
        rows = self.sigma_rows(sigma)
        for i, (full, _, _) in enumerate(self.specs):
            col = sens.get(full)
            if col is not None and np.shape(col) == (self.n_res,):
                J0[:, i] = -np.asarray(col, float) * dxdu[i] / rows
        return J0 if np.isfinite(J0).any() else None

    def solve(self, sigma, candidates, J0=None, noise_given: bool = False, screen=None, polish: bool = True):
        """The best least-squares solution from the ``candidates`` start vectors, weighted by ``sigma``.

        An expensive model (secant Jacobians) polishes only the best of the starts' solutions
        (:func:`_polish`: a finite-difference Jacobian there, for the covariance, and a restart where
        it promises more): the others are discarded anyway; ``polish=False`` skips it (a held-out
        fold, whose covariance nobody reads).  ``J0``, the columns known at the first
        start, seeds every start's first Jacobian (the starts differ in the effect parameters,
        whose columns are not known and are computed).  ``screen`` (an expensive model's candidate
        refit in ``diagnose``, :mod:`femast.experiments.screening`): a start the model fails at is left
        out when another start can be run, and a start stops at the first iterate from which it
        cannot make the candidate significant; when every start stopped, the result is the screening
        (``screened`` True)."""
        co, lo, hi, kw, secant, fd_step = self.co, self.lo, self.hi, self.kw, self.secant, self.fd_step
        best = best_fj = None
        fun0 = self.fun(sigma)
        nfev = 0
        jacobians, stops = [], []
        min_dec = POLISH_MIN_DECREASE if secant and noise_given else 0.0
        sr = self.sigma_rows(sigma)
        p_new = len(self.specs) - int(screen["p0"]) if screen else 0
        starts = []
        for x in candidates:
            u0 = co.start(x, lo, hi) if secant else np.clip(x / self.scale, lo, hi)
            fj = None
            if fd_step:
                fj = _FEJacobian(fun0, float(fd_step), lo, hi, secant=secant, J0=J0 if secant else None)
                jacobians.append(fj)
            starts.append((u0, fj))
        if screen and secant and len(starts) > 1:
            # a start the model fails at is left out when another can be run (its first evaluation is the
            # one its fit would make first, kept by its _FEJacobian)
            runnable = [(u0, fj) for u0, fj in starts if np.all(np.abs(fj.value(u0)) < _BAD)]
            starts = runnable or starts
        for u0, fj in starts:
            fun = fun0
            if fj is not None:
                fun, kw["jac"] = fj.value, fj.jac
                if screen and secant:
                    fj.futile = futility_check(screen, p_new, sr, lo, hi, _BAD)
            kw_k = kw
            if min_dec:
                # a noise model given: the cost is half the chi-square, and a decrease below min_dec is no
                # reason for more FE runs (see _polish); scipy's ftol is relative to the current cost,
                # bounded here by the start's (the start's run is the fit's first evaluation anyway)
                f0 = fun(u0)
                kw_k = {**kw, "ftol": max(float(kw.get("ftol", 1e-8)), min_dec / max(0.5 * float(f0 @ f0), 1e-300))}
            try:
                with np.errstate(all="ignore"):
                    sol = least_squares(fun, u0, bounds=(lo, hi), **kw_k)
            except Futile as stop:  # this start cannot make the candidate significant
                stops.append((fj.u, stop.lin))
                continue
            finally:
                if fj is not None:
                    fj.futile = None
            nfev += sol.nfev
            if best is None or sol.cost < best.cost:
                best, best_fj = sol, fj
        if best is not None and stops and min(0.5 * float(np.sum((lin[0] / sr) ** 2)) for _, lin in stops) < best.cost:
            best = None  # the starts that converged ended above where a stopped one stopped: no better than it
        if best is not None and screen and secant:  # a start that converged: is it worth its polish?
            try:
                futility_check(screen, p_new, sr, lo, hi, _BAD)(best.x, best.fun, best_fj.J)
            except Futile as stop:
                stops.append((best.x, stop.lin))
                best = None
        runs = sum(fj.runs for fj in jacobians)
        if best is None:  # every start stopped: screened out
            out = screened_out(stops, screen, p_new, sr)
            out.screened, out.fe_runs = True, runs
            return out
        if secant and polish:
            kw["jac"] = best_fj.jac
            best = _polish(best, best_fj, best_fj.value, lo, hi, kw, min_dec)
            nfev += getattr(best, "nfev_polish", 0)
        runs = sum(fj.runs for fj in jacobians)
        best.nfev_total = nfev
        best.fe_runs = runs if fd_step else nfev
        return best

    def solve_estimating_noise(self, starts, start_sensitivity):
        """A first fit with the noise of the start's residual, then the fit with the noise of the
        first fit's residual: ``(solution, sigma)``."""
        exp, data, specs, co = self.exp, self.data, self.specs, self.co
        base, eff = split_parameters(specs, self.x0)
        sigma0 = estimate_noise(exp, channel_residuals(exp, data, predict(exp, data, base, eff)))
        sol = self.solve(sigma0, starts, self.seed(start_sensitivity, sigma0, self.x0))
        base, eff = split_parameters(specs, co.to_x(sol.x))
        sigma = estimate_noise(exp, channel_residuals(exp, data, predict(exp, data, base, eff)))
        if self.secant and len(exp.channels) == 1:
            # one channel, one noise level: the whitened residual only changes by a constant factor, so
            # the minimiser and the covariance are the same; rescale instead of refitting
            f = sigma0[exp.channels[0]] / sigma[exp.channels[0]]
            sol.fun, sol.jac, sol.cost = sol.fun * f, sol.jac * f, sol.cost * f * f
        else:
            ratio = self.sigma_rows(sigma0) / self.sigma_rows(sigma)  # warm start: the last Jacobian re-weighted
            sol2 = self.solve(sigma, [co.to_x(sol.x)], sol.jac * ratio[:, None] if self.secant else None)
            sol2.nfev_total += sol.nfev_total
            sol2.fe_runs += sol.fe_runs
            sol = sol2
        return sol, sigma
