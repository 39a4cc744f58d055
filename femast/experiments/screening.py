"""Screening of candidate effects during their refits (the expensive experiments): a refit that cannot
make its candidate significant stops.

A refit of an expensive model (every evaluation an FE run or a platform-pose solve) costs 10-40
model runs; most candidates of a diagnosis gain nothing, and a full refit only shows it.  Every
iterate of such a refit has a Jacobian (finite differences at the start -- the baseline's columns
known from its fit, one run per new parameter -- and secant updates after), and with it the
Gauss-Newton prediction of what the rest of the refit can gain.  Within the parameters' bounds,

    rss_lin = min over du within the bounds of  sum_i w_i (f_i + J_i du)^2

with ``f`` the whitened residual at the iterate and ``w`` the effective-sample weights of the
information criterion (:func:`~femast.experiments.noise.information_criterion`); at the start of a
refit this is a score test of the new parameters in its Gauss-Newton form (Seber & Wild 1989,
Sec. 5.9).  The decrease it predicts, ``rss - rss_lin``, is amplified by ``SCREEN_MARGIN`` = 3 --
the whole descent from an iterate may gain more than its first Gauss-Newton step predicts, as a
nonlinear model bends towards the data -- and the refit goes on only while that could still make
the candidate significant against the baseline's ``rss0``:

    dIC = N ln((rss - 3 (rss - rss_lin)) / rss0) + p_new ln N  <  SIGNIFICANT_DBIC (-10)

Otherwise that start of the refit stops (a futility stop).  A start the model cannot be run at (an
FE run that does not converge there) is left out when another start can be run: its fit would
only grope its way out of the failures.  A start that converged is judged so at
its solution before it is polished (the finite-difference Jacobian there, for the covariance, is
not needed for a candidate that cannot be significant).  Every start of a multistart refit is run
so; a candidate is *screened out* when every start stopped -- at its first iterate when nothing is
to be gained (``1 + p_new`` runs per start instead of a full fit) -- and reported with the figures of
the model run where its best start stopped (its ``significant`` always False, its parameters
without standard errors).  A start that stops cannot have been the best of a significant refit (it
could not reach significance), so a candidate that is significant is fitted as without the screen,
but for the starts the model cannot be run at.

The screen is judged again under the final noise model of the diagnosis (from the residual of its
best model, :mod:`femast.experiments.diagnose`), by which every refit is scored: the linearisations
are kept (raw residual and Jacobian), each stop's Gauss-Newton step (weighted as the refit was)
is scored with the final noise against the baseline's chi-square under it, and a candidate that
could now be significant is refitted in full (:func:`refit_unscreened`).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import OptimizeResult, lsq_linear

from .verdict import SIGNIFICANT_DBIC

SCREEN_MARGIN = 3.0  # the decrease a Gauss-Newton step predicts, times this, must be able to reach significance


class Futile(Exception):
    """Raised inside a refit at an iterate from which it cannot make its candidate significant;
    ``lin`` is the linearisation there ``(r, Jr, dlo, dhi)`` (raw residual and Jacobian, channel units)."""

    def __init__(self, lin):
        super().__init__("futile")
        self.lin = lin


def spec(d) -> dict:
    """What a refit needs to screen itself, from a :class:`~femast.experiments.diagnosis.Diagnosis`
    after its baseline stage: the effective-sample weights ``w`` of every residual (channels stacked),
    their sum ``N``, the baseline's weighted chi-square ``rss0``, its number of fitted values ``p0``, the
    significance ``threshold`` of the information criterion."""
    n = d.data.n
    f = np.array([d.models[c].n_eff / n for c in d.channels])
    w = np.repeat(f, n)
    z0 = np.asarray(d.s0["z"], float)
    rss0 = float(np.sum(w * z0**2))
    return {"w": w, "N": float(f.sum() * n), "rss0": rss0, "p0": len(d.baseline.x), "threshold": SIGNIFICANT_DBIC}


def linearised_rss(f0, J, dlo, dhi, w) -> tuple:
    """``(rss_lin, du)``: the least-squares Gauss-Newton step ``du`` of ``f0 + J du`` within ``[dlo, dhi]``
    and the weighted chi-square ``sum w (f0 + J du)^2`` there."""
    f0, J = np.asarray(f0, float), np.asarray(J, float)
    lo, hi = np.minimum(dlo, 0.0), np.maximum(dhi, 0.0)
    free = hi > lo
    du = np.zeros(J.shape[1])
    if free.any():
        sol = lsq_linear(J[:, free], -f0, bounds=(lo[free], hi[free]), method="bvls")
        du[free] = sol.x
    r = f0 + J @ du
    return float(np.sum(w * r**2)), du


def could_be_significant(rss: float, rss_lin: float, s: dict, p_new: int) -> bool:
    """True if an iterate with chi-square ``rss`` whose Gauss-Newton step predicts ``rss_lin`` could
    still make the candidate significant: ``SCREEN_MARGIN`` times the predicted decrease."""
    rss0, N = s["rss0"], s["N"]
    reach = max(rss - SCREEN_MARGIN * max(rss - rss_lin, 0.0), 1e-12 * rss0)
    return N * math.log(reach / rss0) + p_new * math.log(N) < s["threshold"]


def judge(lin, s: dict, p_new: int, sigma_rows, fitted_with=None) -> tuple:
    """``(could be significant, rss_lin, du)`` of a linearisation ``(r, Jr, dlo, dhi)`` (raw residual and
    Jacobian) scored with the noise ``sigma_rows``; the step ``du`` is that of a refit weighted by
    ``fitted_with`` (default the same noise; the refits of a diagnosis are weighted by the first noise
    model and scored by the final one)."""
    r, Jr, dlo, dhi = lin
    fw = sigma_rows if fitted_with is None else fitted_with
    _, du = linearised_rss(r / fw, Jr / fw[:, None], dlo, dhi, s["w"])
    f0 = r / sigma_rows
    rss, rss_lin = float(np.sum(s["w"] * f0**2)), float(np.sum(s["w"] * ((r + Jr @ du) / sigma_rows) ** 2))
    return could_be_significant(rss, rss_lin, s, p_new), rss_lin, du


def futility_check(s: dict, p_new: int, sigma_rows, lo, hi, bad: float):
    """The check an expensive refit's Jacobian runs at every iterate (:class:`~.fe_jacobian._FEJacobian`):
    raises :class:`Futile` where the refit cannot make its candidate significant.  An iterate where the
    model failed (a whitened residual of ``bad``: a skipped parameter set) is not judged."""

    def check(u, f0, J):
        if not (np.all(np.abs(f0) < bad) and np.all(np.isfinite(J)) and np.all(np.isfinite(sigma_rows))):
            return
        lin = (f0 * sigma_rows, J * sigma_rows[:, None], lo - u, hi - u)
        if not judge(lin, s, p_new, sigma_rows)[0]:
            raise Futile(lin)

    return check


def screened_out(stops, s: dict, p_new: int, sigma_rows) -> OptimizeResult:
    """What a refit whose every start stopped reports: the stop with the lowest chi-square, ``k``, its
    point ``u`` and raw residual ``r`` (a model run there: the figures of the screened candidate are
    those of a real run), its Gauss-Newton prediction ``rss_lin``, and ``lins`` (every stop's
    linearisation, for the judgement under the final noise model).  ``stops``: ``[(u, lin)]``."""
    w = s["w"]
    chi2 = [float(np.sum(w * (lin[0] / sigma_rows) ** 2)) for _, lin in stops]
    k = int(np.argmin(chi2))
    u, lin = stops[k]
    return OptimizeResult(
        k=k, u=u, r=lin[0], rss=chi2[k], rss_lin=judge(lin, s, p_new, sigma_rows)[1], lins=[x for _, x in stops]
    )


def refit_unscreened(d) -> bool:
    """Under the diagnosis's current noise model, fit in full every screened candidate that could now be
    significant (module docstring); True if any was."""
    s = spec(d)
    sr, fw = (
        np.concatenate([np.broadcast_to(np.asarray(sig[c], float), (d.data.n,)) for c in d.channels])
        for sig in (d.weights, d.payload["noise"])
    )
    todo = []
    for i, ((*_, effects, start), res) in enumerate(zip(d.jobs, d.fits_list)):
        if not getattr(res, "screened", False):
            continue
        p_new = len(res.x) - s["p0"]
        if any(judge(lin, s, p_new, sr, fw)[0] for lin in res.screen.lins):
            todo.append((i, effects, start))
    if not todo:
        return False
    fits = d.refit([{"effects": effects, "start": start, "screen": None} for _, effects, start in todo])
    for (i, _, _), res in zip(todo, fits):
        d.fits_list[i] = res
    return True
