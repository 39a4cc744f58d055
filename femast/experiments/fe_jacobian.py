"""Derivatives and coordinates of the fits of expensive models (the FE experiments).

Every evaluation of such a model is an FE run (0.1-2 s), so a fit's cost is its number of runs.
:class:`_FEJacobian` takes forward differences with a floor on the step and Broyden secant updates
between them; :func:`_polish` makes sure the fit ends where a finite-difference Jacobian agrees
(and gives the covariance); :class:`_Coords` fits positive parameters spanning decades in log scale
and gives registered starts back bit for bit (so the run cache answers them).  Used by
:func:`femast.experiments.fitting.fit`.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares


class _FEJacobian:
    """(fun, jac) for least_squares on an expensive model (an FE run per evaluation): forward
    differences of ``step x max(1, |u_i|)`` in the scaled parameters u (the ``diff_step`` of
    ``Experiment.fit_options``), and between them Broyden's rank-one secant updates.

    scipy's own ``diff_step`` is relative to ``|u_i|`` and falls back to 1.5e-8 at ``u_i = 0``, the
    start of an effect whose default is "absent" (a pretension error dT0 = 0): an FE model resolves
    that step no better than its Newton tolerance, and the derivative comes out with the wrong sign.
    Here the step never drops below ``step``; it is taken backwards where it would leave the upper
    bound.  The value at the point itself is reused from the last call of ``fun`` (scipy evaluates
    it just before asking for the Jacobian).

    ``secant``: after the first Jacobian, an accepted step s with residual change y updates it as
    J + (y - J s) s^T / (s^T s) (Broyden 1965; Dennis & Schnabel 1996, Sec. 8.1) instead of p more
    FE runs; a step the trust region rejected (the model did not follow the linearisation) makes
    the next Jacobian a finite-difference one again.  ``J0``: columns known at the start (NaN where
    not), e.g. the baseline's finite differences handed to a refit.
    ``runs`` counts the evaluations of ``fun`` (cache hits included); ``fd_at`` is the point of the
    last finite-difference Jacobian and ``fd_J`` that Jacobian."""

    def __init__(self, fun, step: float, lo, hi, secant: bool = True, J0=None):
        self.fun, self.step, self.lo, self.hi, self.secant = fun, float(step), lo, hi, secant
        self.last = {}
        self.J = self.u = self.f = None
        self.J0 = None if J0 is None else np.array(J0, float)
        self.since = 0  # evaluations since the last Jacobian (> 1: a rejected step)
        self.runs = 0
        self.fd_at = self.fd_J = None
        self.futile = None  # check(u, f, J) run at every iterate; raises to stop the fit (screening)

    def value(self, u):
        key = np.asarray(u, float).tobytes()
        if key not in self.last:
            self.last.clear()
            self.runs += 1
            self.last[key] = self.fun(u)
        self.since += 1
        return self.last[key]

    def differences(self, u, f0, known=None):
        J = np.empty((f0.size, u.size))
        todo, points, steps = [], [], []
        for i in range(u.size):
            if known is not None and np.all(np.isfinite(known[:, i])):
                J[:, i] = known[:, i]
                continue
            h = self.step * max(1.0, abs(u[i]))
            if u[i] + h > self.hi[i]:
                h = -h
            up = u.copy()
            up[i] += h
            todo.append(i)
            points.append(up)
            steps.append(h)
        self.runs += len(points)
        for i, h, f in zip(todo, steps, [self.fun(p) for p in points]):
            J[:, i] = (f - f0) / h
        if known is None or not np.all(np.isfinite(known)):
            self.fd_at, self.fd_J = u.copy(), J.copy()
        return J

    def jac(self, u, *args):
        u = np.asarray(u, float)
        f0 = self.value(u)
        self.since -= 1  # scipy's value call before the Jacobian is not a trial step
        if self.J is None:
            known = self.J0 if self.J0 is not None and self.J0.shape == (f0.size, u.size) else None
            J = self.differences(u, f0, known)
        elif not self.secant or self.since > 1:
            J = self.differences(u, f0)
        else:
            s = u - self.u
            ss = float(s @ s)
            J = self.J if ss == 0.0 else self.J + np.outer((f0 - self.f) - self.J @ s, s) / ss
        self.J, self.u, self.f, self.since = J, u.copy(), f0, 0
        if self.futile is not None:
            self.futile(u, f0, J)
        return J

    def at_solution(self, u):
        """(J by finite differences at ``u``, whether it had to be computed)."""
        u = np.asarray(u, float)
        if self.fd_at is not None and np.array_equal(self.fd_at, u):
            return self.fd_J, False
        return self.differences(u, self.value(u)), True


def _forward_differences(fun, step: float, lo, hi):
    """(fun, jac) with forward differences at every Jacobian (no secant updates); see :class:`_FEJacobian`."""
    j = _FEJacobian(fun, step, lo, hi, secant=False)
    return j.value, j.jac


LOG_RANGE = 100.0  # a positive parameter whose bounds span this factor or more is fitted in log scale


class _Coords:
    """The fit's coordinates u of the parameters x: ``x / scale`` (linear), or ``ln(x / scale)`` for
    the parameters flagged ``log`` (expensive fits of positive parameters spanning decades: a
    stiffness or an axial rigidity, whose effect goes as 1/x: Gauss-Newton steps in ln x reach
    the minimum in fewer FE runs than steps in x).  ``start`` registers a start value so
    that ``to_x`` gives it back bit for bit (the run cache then answers it)."""

    def __init__(self, scale, log):
        self.scale, self.log = np.asarray(scale, float), np.asarray(log, bool)
        self.exact = {}

    def to_u(self, x):
        x = np.asarray(x, float)
        u = x / self.scale
        with np.errstate(divide="ignore", invalid="ignore"):
            u[self.log] = np.log(x[self.log] / self.scale[self.log])
        return u

    def to_x(self, u):
        u = np.asarray(u, float)
        hit = self.exact.get(u.tobytes())
        if hit is not None:
            return hit.copy()
        x = u * self.scale
        x[self.log] = self.scale[self.log] * np.exp(u[self.log])
        return x

    def dx_du(self, u):
        """dx/du at ``u`` (the chain rule of the Jacobian and the covariance)."""
        d = self.scale.copy()
        d[self.log] = self.scale[self.log] * np.exp(np.asarray(u, float)[self.log])
        return d

    def start(self, x, lo, hi):
        """The coordinates of start ``x`` (clipped into the bounds), remembered so that ``to_x`` returns
        exactly ``x``: a refit started from another fit's values asks the FE model for those values."""
        x = np.asarray(x, float)
        u = np.clip(self.to_u(x), lo, hi)
        if np.array_equal(np.clip(x, self.to_x(lo), self.to_x(hi)), x):
            self.exact[u.tobytes()] = x.copy()
        return u


POLISH_ROUNDS = 2
POLISH_MIN_DECREASE = 0.01  # half chi-square: a restart must promise more (0.14 standard errors of a parameter)


def _polish(sol, fj, fun, lo, hi, kw, min_decrease: float = 0.0):
    """The Jacobian at the solution by finite differences (for the covariance), and a restart of the fit
    from there, with that Jacobian, when its Gauss-Newton step (within the bounds) predicts a decrease
    of the cost beyond ``ftol`` of it and beyond ``min_decrease``: a secant Jacobian may have stopped
    the fit early.  With residuals whitened by the noise (a given noise model), the cost is half the
    chi-square, and a decrease d moves the parameters by about sqrt(2 d) standard errors
    (``POLISH_MIN_DECREASE`` = 0.01: 0.14 of one); a smaller predicted gain is not worth a restart."""
    extra = 0
    ftol = float(kw.get("ftol", 1e-8))
    for rnd in range(POLISH_ROUNDS + 1):
        J, _ = fj.at_solution(sol.x)
        f = fj.value(sol.x)
        step = np.linalg.lstsq(J, -f, rcond=None)[0]
        u_new = np.clip(sol.x + step, lo, hi)
        r = f + J @ (u_new - sol.x)
        predicted = sol.cost - 0.5 * float(r @ r)
        if rnd == POLISH_ROUNDS or not predicted > max(ftol * sol.cost, min_decrease):
            break
        fj.J, fj.J0 = None, J
        with np.errstate(all="ignore"):
            again = least_squares(fun, sol.x, bounds=(lo, hi), **kw)
        extra += again.nfev
        if again.cost <= sol.cost:
            sol = again
        else:
            break
    J, _ = fj.at_solution(sol.x)
    sol.jac = J
    sol.fun = fj.value(sol.x)
    sol.nfev_polish = extra
    return sol
