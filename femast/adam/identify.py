"""Identification of the unknown bay parameters from the 40-bay tip response of Stohlman & Pellegrino, Table 1.

The paper gives the elastic tip response of its 40-bay model under M + F (M = 6.8 N m about z,
F = 14 N along x): x = 1740 um and theta_z = 3030 arcsec.  It does not give the cable EA nor the
longeron section.  :func:`fit_tip_response` finds them by least squares (scipy's trust-region
reflective ``least_squares``, as the project's other fits): each residual evaluation builds the
mast, brings it to its pretensioned equilibrium (stabilised initial step) and applies M + F in
one unstabilised step, exactly as the Table 1 benchmark does; the residuals are the
relative differences of x and theta_z from their targets.  Parameters are fitted in log scale
(both are positive and span decades).  With two parameters and two targets the fit is exact when
it succeeds; ``sensitivity`` (d log response / d log parameter) tells how well each is determined.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.optimize import OptimizeResult, least_squares

from ..analysis import Analysis
from ..errors import ModelError
from .build import build_mast
from .parameters import BayParameters
from .post import ARCSEC
from .steps import CONVERGENCE, TABLE1_F, TABLE1_M, add_initial_steps

#: Table 1 of Stohlman & Pellegrino under M + F: x (m) and theta_z (rad).
TABLE1_TARGET = {"x": 1740e-6, "theta_z": 3030.0 / ARCSEC}

#: Parameters that may be fitted, their units and default bounds (SI).
FIT_BOUNDS = {
    "cable_EA": ("N", 2e3, 2e6),
    "longeron_t": ("m", 2e-4, None),
    "longeron_E": ("Pa", 1e9, 1e12),
    "longeron_d": ("m", 2e-3, 0.1),
    "b": ("m", 0.12, 0.6),
}


def tip_response(
    params: BayParameters,
    n_bays: int = 40,
    M: float = TABLE1_M,
    F: float = TABLE1_F,
    fold: int = 1,
    alternate: bool = True,
    increments: int = 1,
) -> dict:
    """Tip (control node) displacement (m) and rotation (rad) of the pretensioned mast under a tip
    moment M (N m, about z) and force F (N, along x), applied in ``increments`` equal increments,
    relative to the pretensioned state.  Returns dict with ``u`` (3,), ``theta`` (3,), ``iterations``,
    ``wall_time``."""
    am = build_mast(n_bays, params, fold=fold, alternate=alternate)
    add_initial_steps(am)
    am.model.step("M+F", initial_increment=1.0 / increments, max_increment=1.0 / increments).load(
        am.control, mz=M, fx=F
    )
    t0 = time.perf_counter()
    row = am.model.index(am.control)
    rec = []  # (step, U, URA) of the control node per converged increment (no files written)
    an = Analysis(
        am.model,
        None,
        progress=False,
        convergence=CONVERGENCE,
        on_frame=lambda fr: rec.append((str(fr["step"]), fr["U"][row], fr["URA"][row])),
    )
    an.run()
    steps = [r[0] for r in rec]
    i0 = len(steps) - 1 - steps[::-1].index("pretension")
    (_, u0, th0), (_, u1, th1) = rec[i0], rec[-1]
    u = u1 - u0
    th = th1 - th0
    return {"u": u, "theta": th, "iterations": an.summary.iterations, "wall_time": time.perf_counter() - t0}


def fit_tip_response(
    params: BayParameters | None = None,
    names=("cable_EA", "longeron_t"),
    x0=None,
    targets: dict | None = None,
    n_bays: int = 40,
    bounds: dict | None = None,
    verbose: bool = False,
    increments: int = 1,
    **ls_options,
) -> OptimizeResult:
    """Fit ``names`` (fields of :class:`BayParameters`) so that the tip response under M + F
    matches ``targets`` (default Table 1: x = 1740 um, theta_z = 3030 arcsec), M + F applied in
    ``increments`` increments (:func:`tip_response`).

    Returns a :class:`scipy.optimize.OptimizeResult` with ``x`` (fitted values, SI), ``names``,
    ``units``, ``params`` (the fitted :class:`BayParameters`), ``response`` (model x and theta_z
    at the optimum), ``targets``, ``fun`` (relative residuals), ``rel_error``, ``sensitivity``
    ((2, p) d log response / d log parameter), ``success``, ``message``, ``nfev``, ``history``
    (every evaluation: parameters, response, wall time) and ``wall_time``."""
    p0 = params or BayParameters()
    tg = dict(TABLE1_TARGET if targets is None else targets)
    names = tuple(names)
    bd = dict(FIT_BOUNDS)
    if bounds:
        bd.update(bounds)
    for nm in names:
        if nm not in bd:
            raise ModelError(f"fit_tip_response: cannot fit '{nm}'; fittable: {', '.join(bd)}")
    start = np.array(
        [getattr(p0, nm) if x0 is None else x for nm, x in zip(names, x0 if x0 is not None else [None] * len(names))],
        dtype=float,
    )
    lo = []
    hi = []
    for nm in names:
        _, a, b_ = bd[nm]
        if nm == "longeron_t" and b_ is None:
            b_ = 0.5 * p0.longeron_d * 0.999
        lo.append(np.log(a))
        hi.append(np.log(b_))
    history = []

    def model(z):
        vals = dict(zip(names, np.exp(z)))
        r = tip_response(p0.with_(**vals), n_bays=n_bays, increments=increments)
        history.append(
            {
                "params": vals,
                "x": float(r["u"][0]),
                "theta_z": float(r["theta"][2]),
                "iterations": r["iterations"],
                "wall_time": r["wall_time"],
            }
        )
        if verbose:
            print(
                f"  fit: {', '.join(f'{k} = {v:.6g}' for k, v in vals.items())} -> x = {r['u'][0] * 1e6:.1f} um, "
                f"theta_z = {r['theta'][2] * ARCSEC:.1f} arcsec ({r['iterations']} iterations, "
                f"{r['wall_time']:.1f} s)",
                flush=True,
            )
        return r

    def residual(z):
        r = model(z)
        return np.array([r["u"][0] / tg["x"] - 1.0, r["theta"][2] / tg["theta_z"] - 1.0])

    t0 = time.perf_counter()
    opts = dict(method="trf", diff_step=1e-3, xtol=1e-6, ftol=1e-8, gtol=1e-10, max_nfev=40)
    opts.update(ls_options)
    sol = least_squares(residual, np.log(start), bounds=(lo, hi), **opts)
    x = np.exp(sol.x)
    fitted = p0.with_(**dict(zip(names, x)))
    last = next(h for h in reversed(history) if np.allclose([h["params"][n] for n in names], x, rtol=1e-12))
    resp = {"x": last["x"], "theta_z": last["theta_z"]}
    rel = np.array([resp["x"] / tg["x"] - 1.0, resp["theta_z"] / tg["theta_z"] - 1.0])
    return OptimizeResult(
        x=x,
        names=names,
        units=tuple(bd[n][0] for n in names),
        params=fitted,
        response=resp,
        targets=tg,
        fun=sol.fun,
        rel_error=rel,
        sensitivity=sol.jac / (1.0 + sol.fun)[:, None],
        jac=sol.jac,
        success=bool(sol.success),
        status=sol.status,
        message=sol.message,
        nfev=sol.nfev,
        cost=sol.cost,
        history=history,
        x0=start,
        wall_time=time.perf_counter() - t0,
    )
