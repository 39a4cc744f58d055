"""Identification of the latch law from pull tests (Stohlman & Pellegrino, Section III.B-C, Eq. 15).

A pull test (Stohlman & Pellegrino, Fig. 8) pulls the bead into (latching) or out of (unlatching) the
latch with one cable while the cable on the other side of the latch is slack, and
records the cable end-to-end distance ``d_i`` (m) and the tension ``T_i`` (N).

1. Remove the cable stretch (Eq. 15) to get the bead position::

       x_i = sign * (d_i - T_i L_cable / EA - d0)

   The paper prints ``x_i = d_i - T_i / k_cable (L10 + L30) - d0``: ``k_cable`` is the
   cable's stiffness per unit strain, i.e. its axial rigidity EA (N), and
   ``L10 + L30`` the unstretched length of the cables in the load path (``L_cable``).
   ``sign`` is +1 when ``d`` grows as the bead moves out (unlatching rig, Fig. 8b,
   the paper's form) and -1 when it grows as the bead moves in (latching rig, Fig.
   8a); ``d0`` is the zero-tension distance with the bead on the roller axis.  The
   measured force jump is ``dT_i = direction * T_i`` (direction +1 unlatching, -1
   latching; see :mod:`femast.elements.latch_law` for the signs).
2. Fit r, x_backstop, k, mu (h and R measured) by ``scipy.optimize.least_squares``.
   Each point is compared with the *graph* of its branch of Eq. 14: the curve
   ``dT_sigma(x)`` for ``x > -x_backstop`` and the vertical segment of the backstop,
   ``x = -x_backstop, dT <= dT_sigma(-x_backstop)``.  The residual is the smaller of
   the vertical distance to the curve, weighted by the effective variance
   ``sigma_T^2 + (dT'(x) sigma_x)^2``, and the horizontal distance to the backstop
   segment over ``sigma_x``.  Uncertainties come from the Jacobian at the optimum,
   ``cov = s^2 (J^T J)^-1`` with ``s^2`` the reduced chi-square.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import OptimizeResult, least_squares

from .elements.cable_latch import CableLatchFamily
from .elements.latch_law import LATCHING, UNLATCHING, LatchParameters, contact_half_width, latch_force
from .errors import ModelError

FIT_NAMES = ("r", "x_backstop", "k", "mu")
_REF = np.array([1e-3, 1e-3, 1e5, 0.1])  # scales of the fitted parameters (m, m, N/m, -)


@dataclass
class PullTest:
    """One pull test (Stohlman & Pellegrino, Fig. 8): arrays d (m) and T (N) and the constants of Eq. 15.

    direction : +1 unlatching (bead pulled out, dT = +T) or -1 latching (dT = -T).
    EA : axial rigidity of the loaded cable, N (the paper's k_cable).
    L_cable : unstretched length of the loaded cable(s), m (the paper's L10 + L30).
    d0 : distance d at zero tension with the bead on the roller axis, m.
    sign : +1 if d grows when the bead moves out, -1 if it grows when it moves in.
    x_true : bead positions, m, when known (simulated tests).
    """

    d: np.ndarray
    T: np.ndarray
    direction: int
    EA: float
    L_cable: float
    d0: float
    sign: int = 1
    x_true: np.ndarray | None = None

    def bead_position(self) -> np.ndarray:
        """Bead position x_i (m) with the cable stretch removed (Eq. 15)."""
        return remove_cable_stretch(self.d, self.T, self.EA, self.L_cable, self.d0, self.sign)

    def dT(self) -> np.ndarray:
        """Force jump across the latch dT_i = direction * T_i, N (Eq. 5)."""
        return self.direction * np.asarray(self.T, dtype=float)


def remove_cable_stretch(d, T, EA, L_cable, d0=0.0, sign=1):
    """Bead position from the cable end distance, Stohlman & Pellegrino, Eq. 15 (m).

    d : cable end-to-end distance, m.  T : tension, N.  EA : axial rigidity, N.
    L_cable : unstretched length of the loaded cable, m.  d0 : offset, m.
    sign : +1 (d grows as the bead moves out) or -1.
    """
    if not EA > 0:
        raise ModelError(f"remove_cable_stretch: EA = {EA!r} N must be > 0")
    if not L_cable > 0:
        raise ModelError(f"remove_cable_stretch: L_cable = {L_cable!r} m must be > 0")
    d = np.asarray(d, dtype=float)
    T = np.asarray(T, dtype=float)
    return sign * (d - T * L_cable / EA - d0)


def simulate_pull_test(
    params=None,
    direction=UNLATCHING,
    *,
    EA=2.0e5,
    L_cable=0.5,
    L_other=0.3,
    slack=0.02,
    n_steps=300,
    x_far=4e-3,
    T_max=None,
) -> PullTest:
    """Quasi-static pull test computed with the cable/latch element (exact, noise-free).

    The loaded cable (unstretched length L_cable, m, rigidity EA, N) is pulled by a grip
    while the other side (L_other, m) hangs with ``slack`` (m) so that it stays slack.
    Unlatching starts with the bead on the backstop and ends ``x_far`` (m) outside;
    latching starts at ``x_far`` and ends with the bead on the backstop pulled to
    ``T_max`` (N, default 1.2 x the largest |dT| of the law).  Returns a :class:`PullTest`
    with the Eq. 15 constants of the rig (so that ``bead_position`` inverts it up to the
    length change of the loaded cable, T (x - x_start) / EA).
    """
    p = (
        params
        if isinstance(params, LatchParameters)
        else LatchParameters.adam_fit()
        if params is None
        else LatchParameters(*np.asarray(params, float))
    )
    p.validate("simulate_pull_test")
    xg = np.linspace(-p.x_backstop, contact_half_width(p), 2001)
    peak = max(np.abs(latch_force(xg, LATCHING, p)).max(), np.abs(latch_force(xg, UNLATCHING, p)).max())
    if T_max is None:
        T_max = 1.2 * peak
    if direction == UNLATCHING:
        x0 = -p.x_backstop
        s0 = L_other
        L0 = s0 + L_cable
        Lb = s0 + x0
        X = np.array([[-(s0 - slack), 0.0, 0.0], [0.0, 0.0, 0.0], [L_cable - 1e-4, 0.0, 0.0]])
        grip, d_end = 2, L_cable + (x_far - x0) + 1e-3
    elif direction == LATCHING:
        x0 = x_far
        s0 = L_cable
        L0 = s0 + L_other
        Lb = s0 + x0
        X = np.array([[-(s0 - 1e-4), 0.0, 0.0], [0.0, 0.0, 0.0], [L_other - slack, 0.0, 0.0]])
        grip, d_end = 0, L_cable + (x0 + p.x_backstop) + T_max * L_cable / EA + 1e-3
    else:
        raise ModelError("simulate_pull_test: direction must be +1 (unlatching) or -1 (latching)")
    fam = CableLatchFamily(np.array([[0, 1, 2]]), EA=EA, L0=L0, latch_node=1, bead=Lb, latch=p, x0=x0, name="pull_test")
    st = fam.initial_state()
    sec = 1 if direction == UNLATCHING else 0
    d_all = np.linspace(abs(X[grip, 0]), d_end, n_steps)
    d_out, T_out, x_out = [], [], []
    for d in d_all:
        X[grip, 0] = d if grip == 2 else -d
        r = fam.evaluate(X, None, st)
        st = r.state
        T = r.output["tension"][0, sec]
        d_out.append(d)
        T_out.append(T)
        x_out.append(st[0, 0])
        if direction == LATCHING and T >= T_max:
            break
    d0 = L0 - Lb if direction == UNLATCHING else Lb
    return PullTest(
        d=np.array(d_out),
        T=np.array(T_out),
        direction=int(direction),
        EA=EA,
        L_cable=L_cable,
        d0=d0,
        sign=int(direction),
        x_true=np.array(x_out),
    )


def _graph_residuals(theta, x, dT, sig, h, R, sigma_T, sigma_x):
    r, xb, k, mu = theta
    p = np.array([r, xb, k, mu, h, R])
    xc = np.maximum(x, -xb)
    D, dD = latch_force(xc, sig, p, derivative=True)
    # one cable pulls, the other is slack: the test cannot show dT of the wrong sign
    clipped = sig * D < 0.0
    D = np.where(clipped, 0.0, D)
    dD = np.where(clipped, 0.0, dD)
    res_curve = (dT - D) / np.sqrt(sigma_T**2 + (dD * sigma_x) ** 2)
    Dstop = latch_force(-xb, sig, p)
    Dstop = np.where(sig * Dstop < 0.0, 0.0, Dstop)
    hx = (x + xb) / sigma_x
    above = dT > Dstop
    res_stop = np.where(above, np.hypot(hx, (dT - Dstop) / sigma_T) * np.sign(hx + (hx == 0)), hx)
    return np.where(np.abs(res_curve) <= np.abs(res_stop), res_curve, res_stop)


def initial_guess(x, dT, h, R, noise_T=1.0):
    """Data-driven start [r, x_backstop, k, mu] (SI) for :func:`fit_latch`.

    x_backstop from the smallest bead position; r from the largest |x| with a force above
    the noise (the contact half-width, Eq. 6 with delta = 0); k from the peak force by
    the ratio to the paper's fit; mu = 0.05."""
    x = np.asarray(x, float)
    dT = np.asarray(dT, float)
    xb = max(-np.min(x), 1e-5)
    loaded = x[np.abs(dT) > 5 * noise_T]
    xct = np.max(np.abs(loaded)) if loaded.size else 2.0e-3
    r = (xct**2 - R**2 + h**2) / (2 * (R - h))
    r = float(np.clip(r, 0.1 * R, 5 * R))
    ref = LatchParameters(r=r, x_backstop=xb, k=1e5, mu=0.05, h=h, R=R)
    xg = np.linspace(-xb, contact_half_width(ref), 501)
    peak_ref = np.abs(latch_force(xg, UNLATCHING, ref)).max()
    k = 1e5 * np.max(np.abs(dT)) / peak_ref if peak_ref > 0 else 1e5
    return np.array([r, xb, k, 0.05])


def fit_latch(
    x, dT, direction, *, h, R, p0=None, sigma_T=0.5, sigma_x=1e-5, bounds=None, **least_squares_kw
) -> OptimizeResult:
    """Fit r, x_backstop, k, mu of the latch law (Eq. 14) to (x_i, dT_i) data.

    x : bead positions, m (stretch removed, Eq. 15).  dT : force jumps, N.
    direction : +1 (unlatching) / -1 (latching) per point or for all.
    h, R : measured half roller gap and bead radius, m.
    p0 : start [r, x_backstop, k, mu] (m, m, N/m, -); default :func:`initial_guess`.
    sigma_T, sigma_x : noise of dT (N) and x (m) used to weight the residuals.
    bounds : (lower, upper) for [r, x_backstop, k, mu]; default r in [1e-3 R, 10 R],
        x_backstop in [1e-6, 0.1] m, k in [1, 1e10] N/m, mu in [0, 0.5].

    Returns a ``scipy.optimize.OptimizeResult`` with ``x`` (fitted [r, x_backstop, k, mu],
    SI), ``stderr`` (same units), ``cov``, ``corr``, ``params`` (:class:`LatchParameters`),
    ``names``, ``success``, ``status``, ``message``, ``nfev``, ``cost``, ``fun`` (weighted
    residuals), ``chi2_reduced``, ``n_points``.
    """
    x = np.asarray(x, float).ravel()
    dT = np.asarray(dT, float).ravel()
    sig = np.broadcast_to(np.asarray(direction, float), x.shape).astype(float)
    if x.shape != dT.shape:
        raise ModelError(f"fit_latch: x ({x.size}) and dT ({dT.size}) must have the same length")
    if x.size < 5:
        raise ModelError(f"fit_latch: {x.size} points are too few to fit 4 parameters")
    if not np.all(np.isfinite(x)) or not np.all(np.isfinite(dT)):
        raise ModelError("fit_latch: x and dT must be finite (remove NaN rows)")
    if np.any(np.abs(sig) != 1):
        raise ModelError("fit_latch: direction must be +1 (unlatching) or -1 (latching)")
    LatchParameters(h=h, R=R).validate("fit_latch (measured h, R)")
    if p0 is None:
        p0 = initial_guess(x, dT, h, R, noise_T=sigma_T)
    p0 = np.asarray(p0, float)
    if bounds is None:
        bounds = (np.array([1e-3 * R, 1e-6, 1.0, 0.0]), np.array([10 * R, 0.1, 1e10, 0.5]))
    lo, hi = (np.asarray(b, float) for b in bounds)
    z0 = np.clip(p0, lo, hi) / _REF

    def fun(z):
        return _graph_residuals(z * _REF, x, dT, sig, h, R, sigma_T, sigma_x)

    kw = dict(method="trf", x_scale=1.0, diff_step=1e-7, xtol=1e-12, ftol=1e-12, gtol=1e-12)
    kw.update(least_squares_kw)
    sol = least_squares(fun, z0, bounds=(lo / _REF, hi / _REF), **kw)
    theta = sol.x * _REF
    m, n = x.size, theta.size
    dof = max(m - n, 1)
    chi2 = 2 * sol.cost / dof
    J = sol.jac
    try:
        cov_z = np.linalg.inv(J.T @ J) * chi2
        cov = cov_z * np.outer(_REF, _REF)
        stderr = np.sqrt(np.diag(cov))
        msg_cov = ""
    except np.linalg.LinAlgError:
        cov = np.full((n, n), np.inf)
        stderr = np.full(n, np.inf)
        msg_cov = " (J^T J singular: a parameter is not identified by these data)"
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(stderr, stderr)
    return OptimizeResult(
        x=theta,
        stderr=stderr,
        cov=cov,
        corr=corr,
        names=FIT_NAMES,
        params=LatchParameters(r=theta[0], x_backstop=theta[1], k=theta[2], mu=theta[3], h=h, R=R),
        success=bool(sol.success),
        status=sol.status,
        message=sol.message + msg_cov,
        nfev=sol.nfev,
        cost=sol.cost,
        fun=sol.fun,
        jac=J,
        chi2_reduced=chi2,
        n_points=m,
        p0=p0,
        active_mask=sol.active_mask,
    )


def fit_pull_tests(tests, *, h, R, min_tension=None, **kw) -> OptimizeResult:
    """Remove the cable stretch of each :class:`PullTest` (Eq. 15) and fit them together
    with :func:`fit_latch` (keyword arguments are passed on).

    Points with T <= ``min_tension`` (N, default 3 sigma_T) are left out: with a slack
    cable, d no longer locates the bead, so Eq. 15 gives a meaningless x (a snapping bead
    runs ahead of the grip).  The result also carries ``x_data`` (m), ``dT_data`` (N),
    ``direction`` and ``used`` (mask of the points fitted)."""
    tests = list(tests)
    if not tests:
        raise ModelError("fit_pull_tests: no pull tests given")
    if min_tension is None:
        min_tension = 3.0 * kw.get("sigma_T", 0.5)
    x = np.concatenate([t.bead_position() for t in tests])
    T = np.concatenate([np.asarray(t.T, float) for t in tests])
    dT = np.concatenate([t.dT() for t in tests])
    sig = np.concatenate([np.full(len(t.d), t.direction) for t in tests])
    used = T > min_tension
    res = fit_latch(x[used], dT[used], sig[used], h=h, R=R, **kw)
    res.x_data, res.dT_data, res.direction, res.used = x, dT, sig, used
    return res
