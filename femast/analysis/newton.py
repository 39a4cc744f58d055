"""The one incremental-iterative solution algorithm: Newton-Raphson, with its options.

:meth:`Newton.solve` solves one increment for every control strategy.  The control (through the
:class:`Increment` it proposes) supplies what differs between strategies:

* the loads: fixed for the increment (load control), or ``P_start + lambda P_ref`` with the load
  factor lambda an unknown (displacement control, arc length);
* the predictor: nothing, a linear extrapolation of the previous increment, or the arc-length
  tangent predictor (``predict``);
* the constraint on the load factor: ``dlambda(du_r, du_p, Du)`` picks the load-factor correction
  of every iteration from the two solutions K du_r = r and K du_p = P_ref;
* the prescribed-value increment ``dpres`` and the viscous term of a stabilised step.

Options of the algorithm: a secant line search (``line_search``) and the tangent update
(``tangent``):

* ``"full"``: a new tangent every iteration (Newton-Raphson);
* ``"modified"``: a tangent at the start of each increment attempt, formed again after
  ``refactor_every`` iterations on it or as soon as convergence slows (the residual ratio falls
  by less than the factor ``slow`` in an iteration);
* ``"quasi-newton"``: as ``"modified"``, and between two factorisations Broyden's update of the
  inverse (the "good" Broyden method in product form, Kelley 1995 sec. 7.3; Engelman, Strang &
  Bathe 1981 for finite elements): after a step s that changed the residual by y, the inverse H
  becomes H + (s - H y) s^T H / (s^T H y), stored as vector pairs, so each iteration costs one
  triangular solve and one dot product per pair.  Unsymmetric tangents (friction) are handled:
  Broyden's update, unlike BFGS, does not assume symmetry.  Under a control whose load factor is
  an unknown (displacement control, arc length) it acts as ``"modified"``.
* ``"initial"``: one per step, formed again only where an increment needs its own (prescribed
  values or a viscous term);
* ``"auto"`` (the default): ``"full"``, except that the first iteration of an increment reuses
  the factorisation of the previous increment's last iteration (the tangent one correction away
  from the converged configuration, of the order of the tolerance), when nothing else may have
  changed the tangent: the same step, load control without a predictor, no prescribed values, no
  viscous term, every element family path-independent (its response a function of the
  configuration alone) and the previous increment converged in at least one iteration.  On the
  peer masts that saves one factorisation in four or five with the same iterations
  (docs/performance.md).  A restart point keeps the configuration that factorisation was formed at
  (:meth:`Newton.reuse_configuration`), and a restarted run forms it again there, so that it
  continues bit for bit as the uninterrupted run (tests/analysis/test_restart.py).
  ``"modified"`` and ``"quasi-newton"`` are not chosen
  automatically: on the peer masts (40-1000 bays) and the ADAM bay they need more iterations
  than they save factorisations, and they do not beat full Newton's time
  (``python benchmarks/newton_variants.py``, docs/performance.md).  Full Newton converges where
  they do and more (friction, latches, limit points).

Every Newton iteration: tangent (if due), solve, correct the load factor, update the
configuration, evaluate the residual, test convergence.  On convergence the state is committed,
on failure rolled back (both one call).  Under full Newton and fixed loads an iteration whose force
test passes may also be accepted on its predicted next correction, one more solve with the
factorisation in hand (``Convergence(predicted=True)``, :mod:`~femast.analysis.solvers.convergence`).
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass

import numpy as np

from ..elements.base import IncrementContext
from ..errors import ModelError, SingularModelError
from .deadline import check as check_deadline
from .solvers.convergence import Convergence, all_finite


@dataclass
class Increment:
    """One increment as a control strategy proposes it to :meth:`Newton.solve`.

    time, dtime, total_time : step time at its end, its size and the analysis time at its end (s),
    passed to the elements.  step_name : for messages.  lam : load factor at its start (load
    control: its fixed value).  P : the loads (n, 6), N and N m, if fixed for the increment; else
    ``P_start + lam * P_ref`` with P_ref the reference pattern (n, 6).  dpres : increment of the
    constrained DOFs' values (prescribed displacements, rad for rotations), or None.
    predictor : (du, dlam) added before the first iteration (linear extrapolation), or None.
    whole : the predictor is the whole increment of the free DOFs (a reference run's, see
    :mod:`femast.analysis.reference`; fixed loads or prescribed motion only): the prescribed motion
    is applied with it, and the first iteration is not taken as a linear solve.
    predict : ``predict(du_p) -> dlam``, the tangent predictor of the load factor from
    K du_p = P_ref (arc length), or None.  dlambda : ``dlambda(du_r, du_p, Du) -> dlam or None``,
    the load-factor correction of an iteration (None: the constraint has no solution).
    viscous : a :class:`~femast.analysis.viscous.ViscousTerm` (stabilised step), or None.
    direct : assemble straight into the solver's matrix where possible (off for arc length, whose
    verified results were computed through the CSR tangent; the two differ at round-off).
    """

    time: float
    dtime: float
    total_time: float
    step_name: str
    lam: float
    P: np.ndarray | None = None
    P_start: np.ndarray | None = None
    P_ref: np.ndarray | None = None
    dpres: np.ndarray | None = None
    predictor: tuple | None = None
    predict: object = None
    dlambda: object = None
    viscous: object = None
    direct: bool = True
    whole: bool = False

    def loads(self, lam):
        return self.P if self.P_ref is None else self.P_start + lam * self.P_ref


@dataclass
class Outcome:
    """What :meth:`Newton.solve` did: ``ok``; ``iterations``; ``note`` (why it failed); the converged
    element ``responses``; the converged increment ``Du`` (free DOFs) and load-factor change ``dlam``."""

    ok: bool
    iterations: int
    note: str = ""
    responses: list | None = None
    Du: np.ndarray | None = None
    dlam: float = 0.0


TANGENTS = ("auto", "full", "modified", "quasi-newton", "initial")


class Newton:
    """Newton-Raphson iterations on one increment (see module docstring).

    convergence : :class:`~femast.analysis.solvers.convergence.Convergence`.
    line_search : secant line search when a step overshoots (fixed loads only): True, False, or
        "auto": only when retrying an increment that failed.
    tangent : "auto", "full", "modified", "quasi-newton" or "initial" (see module docstring).
    refactor_every : "modified" / "quasi-newton": iterations on one factorisation before a new one.
    slow : "modified" / "quasi-newton": a new factorisation when an iteration reduces the residual
        ratio by less than this factor (dimensionless, 0 < slow < 1).
    """

    def __init__(
        self,
        convergence: Convergence | None = None,
        line_search="auto",
        tangent="auto",
        refactor_every: int = 6,
        slow: float = 0.25,
    ):
        if tangent not in TANGENTS:
            raise ModelError(f"Newton: tangent='{tangent}' is not one of {', '.join(repr(t) for t in TANGENTS)}")
        if not (isinstance(refactor_every, int) and refactor_every >= 1):
            raise ModelError(f"Newton: refactor_every={refactor_every!r} must be a whole number >= 1")
        if not 0.0 < float(slow) < 1.0:
            raise ModelError(f"Newton: slow={slow!r} must be between 0 and 1 (e.g. 0.25)")
        self.convergence = convergence or Convergence()
        self.line_search = line_search
        self.tangent = tangent
        self.refactor_every = refactor_every
        self.slow = float(slow)
        self.factorized = False  # a usable factorisation exists (modified / initial Newton)
        # "auto": [state version, x, R, formed] of the factorisation kept for the next increment's
        # first iteration (x, R: the configuration it was formed at; formed False after a restart)
        self._reuse = None

    def new_step(self):
        """Called at the start of every step (the initial-stiffness tangent is formed again; "auto"
        reuses no factorisation across steps)."""
        self.factorized = False
        self._reuse = None

    def reuse_configuration(self):
        """(x, R) at which the factorisation that the next increment's first iteration reuses was
        formed, or None: what a restart point keeps so that a restarted run can form it again."""
        return None if self._reuse is None else (self._reuse[1], self._reuse[2])

    def resume_reuse(self, version, x, R):
        """A restarted run at configuration ``version``: the factorisation to reuse is to be formed
        again at configuration (x, R) (the restart point's :meth:`reuse_configuration`)."""
        self._reuse = [version, x, R, False]

    def _reusable(self, system, state, inc, has_dpres, uses_lam, it):
        """The kept factorisation serves this increment's first iteration ("auto" only)."""
        r = self._reuse
        return (
            self.tangent == "auto"
            and it == 0
            and r is not None
            and r[0] == state.version
            and not has_dpres
            and not uses_lam
            and inc.predictor is None
            and inc.viscous is None
            and inc.direct
            and all(f.path_independent for f in system.families)
        )

    def _form_again(self, system, state, ctx):
        """Form the kept factorisation again at the configuration it was formed at (a restarted run)."""
        keep = state.x, state.R
        state.x, state.R = self._reuse[1].copy(), self._reuse[2].copy()
        try:
            system.factorize_tangent(system.evaluate(ctx), False)
        finally:
            state.x, state.R = keep
        self._reuse[3] = True

    def method(self):
        """The tangent update used ("auto" resolved)."""
        return "full" if self.tangent == "auto" else self.tangent

    def _refactor(self, method, it, inc, has_dpres, since, ratios, steps):
        """A new factorisation due?  ``ratios``: the residual ratios of this attempt, the first one
        before any iteration; ``steps``: the largest |correction| of each iteration (modified and
        quasi-Newton only).  Slow: either fell by less than the factor ``slow`` in the last
        iteration (the residual only while above round-off, 1e-2 of its tolerance)."""
        if not self.factorized:
            return True
        if method == "full":
            return True
        if method == "initial":
            return it == 0 and (has_dpres or inc.viscous is not None)
        # modified / quasi-Newton: each attempt starts on its own tangent; a new one when the last
        # iteration reduced the residual ratio by less than the factor `slow` (unless the residual
        # already meets its tolerance: the iterations left are for the displacement test)
        if it == 0 or since >= self.refactor_every:
            return True
        slow_r = ratios[-1] > 1e-2 * self.convergence.force_tol and ratios[-1] > self.slow * ratios[-2]
        slow_d = len(steps) >= 2 and steps[-1] > self.slow * steps[-2]
        return slow_r or slow_d

    def _predicted(self, system, conv, r, Du, sizes):
        """Accept the current iterate on its predicted next correction: the simplified Newton
        correction K^-1 r with the factorisation in hand (formed at the previous iterate), one solve
        (:meth:`Convergence.accept_predicted`); no solve unless the last correction contracted."""
        if not sizes[-1] <= conv.max_contraction * sizes[-2]:
            return False
        ts = _time.perf_counter()
        try:
            c = system.solver.solve(r)
        except SingularModelError:
            return False
        finally:
            system.summary.solve_time += _time.perf_counter() - ts
        return conv.accept_predicted(sizes[-2], sizes[-1], system.scaled_size(c, Du))

    def solve(self, system, state, inc: Increment, attempt: int = 1) -> Outcome:
        """Solve increment ``inc`` from the committed ``state``: commit it and return
        ``Outcome(ok=True, ...)``, or roll back and return why it failed."""
        x0, R0 = state.checkpoint()
        ctx = IncrementContext(
            time=inc.time,
            dtime=inc.dtime,
            total_time=inc.total_time,
            x_committed=x0,
            R_committed=R0,
            step_name=inc.step_name,
        )
        summary = system.summary
        uses_lam = inc.P_ref is not None
        lam = inc.lam
        dpres = inc.dpres
        has_dpres = dpres is not None and bool(np.any(dpres))
        nf = system.n_free
        Du = np.zeros(nf)
        iters = 0
        rnorm_hist = []
        responses = None
        visc = inc.viscous
        dt = inc.dtime
        line_search = self.line_search is True or (self.line_search == "auto" and attempt > 1)
        conv = self.convergence
        method = self.method()
        broyden = Broyden() if method == "quasi-newton" and not uses_lam else None
        since = 0  # iterations on the current factorisation
        ratios = []  # residual ratios, the first before any iteration (modified / quasi-Newton)
        steps = []  # largest |correction| of each iteration (modified / quasi-Newton)
        keep = self.tangent == "auto" and all(f.path_independent for f in system.families)
        # the predicted-correction acceptance: full Newton (the factorisation in hand formed at the
        # previous iterate), fixed loads, no line search (its steps are not Newton's corrections)
        predict = conv.predicted and method == "full" and not uses_lam and not line_search
        sizes = []  # scaled size of each correction of this attempt (Convergence.measure)
        formed_at = None  # (x, R) of this attempt's last factorisation ("auto", path-independent)

        def fail(why):
            state.rollback()
            return Outcome(False, iters, why)

        def evaluate(P, Dtrial=None, reuse=False):
            ta = _time.perf_counter()
            resp = system.evaluate(ctx, reuse=reuse)
            res_ = system.residual(resp, P)
            summary.assembly_time += _time.perf_counter() - ta
            if not all_finite(res_):
                raise FloatingPointError("non-finite residual")
            r_ = res_[:nf]
            if visc is not None and visc.C is not None:
                r_ = r_ - visc.C / dt * (Du if Dtrial is None else Dtrial)
            return resp, res_, r_

        whole = 1 if inc.whole and inc.predictor is not None and not uses_lam else 0
        if inc.predictor is not None:
            pdu, pdlam = inc.predictor
            Du += pdu
            if whole:
                # a predictor of the whole increment (a reference run's converged increment, issue 21):
                # the prescribed motion goes in with it, not again in the first iteration, and the
                # first iteration is no linear solve from the committed state (no linear-increment rule)
                system.update(pdu, dpres if has_dpres else None)
                dpres, has_dpres = None, False
            else:
                system.update(pdu)
            lam += pdlam if uses_lam else 0.0
        lam_start = state.lam
        try:
            P = inc.loads(lam)
            responses, F, r = evaluate(P, reuse=True)
            du = None  # the last correction: set by iteration 0, read by the convergence test from iteration 1
            for it in range(conv.max_iterations + 1):
                check_deadline()  # Study(timeout_s=) in threads (femast/analysis/deadline.py)
                if (
                    it == 0
                    and not uses_lam
                    and not has_dpres
                    and not whole
                    and not np.any(Du)
                    and visc is None
                    and state.at_equilibrium
                    and np.array_equal(P, state.loads)
                ):
                    # nothing changes (e.g. a step that repeats the previous loads): the committed
                    # state is the converged solution
                    system.commit(responses, P, F, lam)
                    return Outcome(True, 0, "", responses, Du, 0.0)
                if it > 0:
                    ok, ratio, forces_ok, size = system.converged(conv, r, du, Du, responses, P, iters + whole)
                    sizes.append(size)
                    # (k >= 3: the first iteration is the increment's step, then two corrections of iterates)
                    early = not ok and forces_ok and predict and iters >= 3
                    if (ok or early) and any(q.provisional for q in responses):
                        ok = early = False  # an element answered with a predictor, not its law (ElementResponse)
                    if early:  # the predicted next correction (convergence.py)
                        ok = self._predicted(system, conv, r, Du, sizes)
                    rnorm_hist.append(ratio)
                    ratios.append(ratio)
                    if ok:
                        if visc is not None:
                            visc.converged(state, Du, dt, responses)
                        state.last_increment, state.last_size, state.last_dlam = Du.copy(), dt, lam - lam_start
                        system.commit(responses, P, F, lam, equilibrium=visc is None)
                        if formed_at is not None:  # kept for the next increment's first iteration
                            self._reuse = [state.version, formed_at[0], formed_at[1], True]
                        return Outcome(True, iters, "", responses, Du, lam - lam_start)
                    if it == conv.max_iterations:
                        return fail(
                            f"no convergence in {iters} iterations "
                            f"(residual ratio {ratio:.3g}, worst at {system.worst(r)})"
                        )
                    if it >= 8 and rnorm_hist[-1] > rnorm_hist[-2] > rnorm_hist[-3] > rnorm_hist[-4]:
                        return fail(f"residual diverging (ratio {ratio:.3g}, worst at {system.worst(r)})")
                # the tangent only when another iteration is needed
                K = Kfc = None
                with_fc = it == 0 and has_dpres
                if self._reusable(system, state, inc, has_dpres, uses_lam, it):
                    if not self._reuse[3]:
                        self._form_again(system, state, ctx)
                    self._reuse = None
                    self.factorized = True
                elif self._refactor(method, it, inc, has_dpres, since, ratios, steps):
                    since = 0
                    self._reuse = None
                    formed_at = (state.x.copy(), state.R.copy()) if keep else None
                    if broyden is not None:
                        broyden.reset()
                    try:
                        if visc is not None:
                            K, Kfc = system.factorize_csr(responses, with_fc, adjust=lambda K_: visc.tangent(K_, dt))
                        elif inc.direct:
                            K, Kfc = system.factorize_tangent(responses, with_fc)
                        else:
                            K, Kfc = system.factorize_csr(responses, with_fc)
                        self.factorized = True
                    except SingularModelError:
                        bad = system.nonfinite_tangent(responses)
                        if bad:
                            return fail(bad)
                        if summary.increments == 0 and it == 0:
                            if K is None:
                                K, _ = system.tangent(responses, with_fc=False)
                            raise SingularModelError(system.singular_message(K, f"step '{inc.step_name}'")) from None
                        return fail("singular tangent (bifurcation or mechanism)")
                elif with_fc:
                    Kfc = system.assembler.coupling([q.k for q in responses])
                if it == 0 and method in ("modified", "quasi-newton"):  # (after the first tangent's floors)
                    ratios.append(system.converged(conv, r, None, Du, responses, P, 0)[1])
                ts = _time.perf_counter()
                if it == 0 and inc.predict is not None:
                    du_p = system.solver.solve(system.reduce_load(inc.P_ref))
                    dlam = inc.predict(du_p)
                    du = dlam * du_p
                    lam += dlam
                elif broyden is not None and not with_fc:
                    du = broyden.direction(system.solver.solve, r)
                else:
                    rhs = r if Kfc is None else r - Kfc @ dpres
                    du = system.solver.solve(rhs)
                    if uses_lam:
                        du_p = system.solver.solve(system.reduce_load(inc.P_ref))
                        dlam = inc.dlambda(du, du_p, Du)
                        if dlam is None:
                            summary.solve_time += _time.perf_counter() - ts
                            return fail("arc-length constraint has no real root")
                        du = du + dlam * du_p
                        lam += dlam
                summary.solve_time += _time.perf_counter() - ts
                iters += 1
                since += 1
                if method in ("modified", "quasi-newton"):
                    steps.append(float(np.abs(du).max(initial=0.0)))
                # the trial states of this iterate, for elements that look at their last iteration
                ctx.previous = {id(f_): q.state for f_, q in zip(system.families, responses)}
                search = line_search and not uses_lam and not (it == 0 and has_dpres)
                before = (state.x.copy(), state.R.copy(), state.spin.copy()) if search else None
                system.update(du, dpres if it == 0 else None)
                if uses_lam:  # under load control the loads are those of the increment's end
                    P = inc.loads(lam)
                Du_before = Du.copy()
                Du += du
                responses, F, r_new = evaluate(P)
                if search:
                    du, responses, F, r_new = line_search_step(
                        system, state, du, r, r_new, responses, F, before, evaluate, P, Du_before
                    )
                    Du = Du_before + du
                if broyden is not None:  # the secant pair of this step (none across prescribed motion)
                    broyden.step(du, None if with_fc else r_new)
                r = r_new
        except (FloatingPointError, SingularModelError, ValueError) as exc:
            bad = system.bad_tangent(exc, responses)
            if bad:
                return fail(bad)
            if isinstance(exc, SingularModelError) and summary.increments == 0 and iters == 0:
                raise
            if isinstance(exc, ModelError):
                raise
            return fail(str(exc))
        return fail("no convergence")


def line_search_step(system, state, du, r0, r1, responses, F, before, evaluate, P, Du_before, eta=0.8, max_steps=5):
    """Secant line search on g(s) = du . r(u + s du) (Crisfield 1991, sec. 9.3): only when the
    full step leaves |g(1)| > eta |g(0)|.  Returns the accepted step and its evaluation (``F``: the
    residual on the independent DOFs of the trial point, kept for the commit)."""
    g0 = float(du @ r0)
    g1 = float(du @ r1)
    if g0 == 0.0 or abs(g1) <= eta * abs(g0):
        return du, responses, F, r1
    s_prev, g_prev, s, g = 0.0, g0, 1.0, g1
    best = (abs(g1), 1.0, responses, F, r1)
    for _ in range(max_steps):
        s_new = s - g * (s - s_prev) / (g - g_prev) if g != g_prev else 0.5 * s
        s_new = min(max(s_new, 0.05), 1.0)
        state.x, state.R, state.spin = before[0].copy(), before[1].copy(), before[2].copy()
        system.update(s_new * du)
        resp, F_, r_ = evaluate(P, Du_before + s_new * du)
        g_new = float(du @ r_)
        if abs(g_new) < best[0]:
            best = (abs(g_new), s_new, resp, F_, r_)
        if abs(g_new) <= eta * abs(g0):
            break
        s_prev, g_prev, s, g = s, g, s_new, g_new
    _, s_best, resp, F_, r_ = best
    if s_best != s_new:
        state.x, state.R, state.spin = before[0].copy(), before[1].copy(), before[2].copy()
        system.update(s_best * du)
    system.summary.line_searches += 1
    return s_best * du, resp, F_, r_


class Broyden:
    """The inverse of the factorised tangent with Broyden's ("good") rank-one updates, in product
    form (Kelley 1995, Iterative Methods for Linear and Nonlinear Equations, alg. 7.3.1 brsol):
    H_(k+1) = (I + w_k s_k^T) H_k with w_k = (s_k - H_k y_k) / (s_k^T H_k y_k), y_k = r_k - r_(k+1)
    (the residual r = P - F falls by K s along a step s).  ``direction(solve, r)`` returns H r
    (one solve with the factorisation, one dot product per stored pair); the pending pair of the
    last step is completed there from the same solve: H_k y_k = h_k - H_k r_(k+1), with h_k the
    direction that gave the step."""

    def __init__(self):
        self.reset()

    def reset(self):
        """A new factorisation: H = K^-1, no pairs."""
        self.w, self.s = [], []
        self._h = None  # H_k r_k, the last direction
        self._pending = None  # (s_k, h_k) waiting for r_(k+1)

    def _apply(self, solve, v):
        x = solve(v)
        for w, s in zip(self.w, self.s):
            x += w * (s @ x)
        return x

    def direction(self, solve, r):
        q = self._apply(solve, r)  # H_k r_(k+1)
        if self._pending is not None:
            s, h = self._pending
            self._pending = None
            z = h - q  # H_k y_k
            sz = float(s @ z)
            if abs(sz) > 1e-12 * float(np.linalg.norm(s) * np.linalg.norm(z)) and np.isfinite(sz):
                w = (s - z) / sz
                self.w.append(w)
                self.s.append(s)
                q += w * (s @ q)  # H_(k+1) r_(k+1)
        self._h = q
        return q

    def step(self, s, r_new):
        """The step s taken along the last direction (scaled by a line search or not); r_new None:
        no secant pair from this step (it also moved prescribed values)."""
        self._pending = (s.copy(), self._h) if (r_new is not None and self._h is not None) else None
