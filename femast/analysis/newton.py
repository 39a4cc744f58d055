"""The one incremental-iterative solution algorithm: Newton-Raphson, with its options.

:meth:`Newton.solve` solves one increment for every control strategy.  The control (through the
:class:`~femast.analysis.control.plan.Increment` its plan proposes) supplies what differs between strategies:

* the loads: fixed for the increment (load control), or ``P_start + lambda P_ref`` with the load
  factor lambda an unknown (displacement control, arc length);
* the predictor: nothing, a linear extrapolation of the previous increment, a reference run's whole
  increment, or the arc-length tangent predictor (``predict``);
* the constraint on the load factor: ``dlambda(du_r, du_p, Du)`` picks the load-factor correction
  of every iteration from the two solutions K du_r = r and K du_p = P_ref;
* the prescribed-value increment ``dpres`` and the viscous term of a stabilised step.

Options of the algorithm: the convergence test (:mod:`~femast.analysis.convergence`, or a test of
your own), a secant line search (``line_search``) and the tangent update (``tangent``, the
strategies of :mod:`~femast.analysis.tangent_update`: ``"auto"`` (the default: full Newton whose
increments may start on the previous increment's last factorisation), ``"full"``, ``"modified"``,
``"quasi-newton"`` (Broyden's update between factorisations), ``"initial"``).  ``"modified"`` and
``"quasi-newton"`` are not chosen automatically: on the peer masts (40-1000 bays) and the ADAM bay
they need more iterations than they save factorisations, and they do not beat full Newton's time
(``python benchmarks/newton_variants.py``, docs/performance.md).  Full Newton converges where they
do and more (friction, latches, limit points).

One attempt at an increment (:class:`Attempt`) is a sequence of named steps: :meth:`~Attempt.start`
(the predictor and the first residual), then every iteration :meth:`~Attempt.converged` (the
convergence test; on success :meth:`~Attempt.commit`), :meth:`~Attempt.form_tangent` (when the
tangent update says so), :meth:`~Attempt.correction` (the solve, with the load-factor correction
under displacement and arc-length control) and :meth:`~Attempt.advance` (update the configuration,
evaluate the residual, line search).  On convergence the state is committed, on failure rolled
back (both one call).  Under full Newton and fixed loads an iteration whose force test passes may
also be accepted on its predicted next correction, one more solve with the factorisation in hand
(``Convergence(predicted=True)``, :mod:`~femast.analysis.convergence`).  A restarted run continues
bit for bit as the uninterrupted one (tests/analysis/test_restart.py).
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass

import numpy as np

from ..elements.base import IncrementContext
from ..errors import ModelError, SingularModelError
from .control.plan import Increment
from .convergence import Convergence, all_finite, predicts
from .deadline import check as check_deadline
from .tangent_update import UPDATES


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


TANGENTS = tuple(UPDATES)


class Newton:
    """Newton-Raphson iterations on one increment (see module docstring).

    convergence : :class:`~femast.analysis.convergence.Convergence`, or a test of your own.
    line_search : secant line search when a step overshoots (fixed loads only): True, False, or
        "auto": only when retrying an increment that failed.
    tangent : "auto", "full", "modified", "quasi-newton" or "initial" (:mod:`.tangent_update`).
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
        self.tangent_update = UPDATES[tangent](refactor_every, self.slow)
        self.factorized = False  # a usable factorisation exists (modified / initial Newton)

    def new_step(self):
        """Called at the start of every step (the initial-stiffness tangent is formed again; "auto"
        reuses no factorisation across steps)."""
        self.factorized = False
        self.tangent_update.new_step()

    def reuse_configuration(self):
        """(x, R) at which the factorisation that the next increment's first iteration reuses was
        formed, or None: what a restart point keeps so that a restarted run can form it again."""
        return self.tangent_update.configuration()

    def resume_reuse(self, version, x, R):
        """A restarted run at configuration ``version``: the factorisation to reuse is to be formed
        again at configuration (x, R) (the restart point's :meth:`reuse_configuration`)."""
        self.tangent_update.resume(version, x, R)

    def method(self):
        """The tangent update used ("auto" resolved)."""
        return self.tangent_update.method

    def solve(self, system, state, inc: Increment, attempt: int = 1) -> Outcome:
        """Solve increment ``inc`` from the committed ``state``: commit it and return
        ``Outcome(ok=True, ...)``, or roll back and return why it failed."""
        a = Attempt(self, system, state, inc, attempt)
        try:
            a.start()
            for it in range(self.convergence.max_iterations + 1):
                check_deadline()  # Study(timeout_s=) in threads (femast/analysis/deadline.py)
                if it == 0 and a.unchanged():
                    return a.keep_committed()
                if it > 0:
                    done = a.converged(it)
                    if done is not None:
                        return done
                failure = a.form_tangent(it)
                if failure is not None:
                    return a.fail(failure)
                failure = a.correction(it)
                if failure is not None:
                    return a.fail(failure)
                a.advance(it)
        except (FloatingPointError, SingularModelError, ValueError) as exc:
            bad = system.bad_tangent(exc, a.responses)
            if bad:
                return a.fail(bad)
            if isinstance(exc, SingularModelError) and system.summary.increments == 0 and a.iters == 0:
                raise
            if isinstance(exc, ModelError):
                raise
            return a.fail(str(exc))
        return a.fail("no convergence")


class Attempt:
    """One attempt of :meth:`Newton.solve` at an increment: its working set (the increment so far
    ``Du``, the load factor, the residual, the histories the options read) and its named steps."""

    def __init__(self, newton, system, state, inc, attempt):
        self.newton, self.system, self.state, self.inc = newton, system, state, inc
        self.x0, self.R0 = state.checkpoint()
        self.ctx = IncrementContext(
            time=inc.time,
            dtime=inc.dtime,
            total_time=inc.total_time,
            x_committed=self.x0,
            R_committed=self.R0,
            step_name=inc.step_name,
        )
        self.summary = system.summary
        self.uses_lam = uses_lam = inc.P_ref is not None
        self.lam = inc.lam
        self.dpres = dpres = inc.dpres
        self.has_dpres = dpres is not None and bool(np.any(dpres))
        self.nf = system.n_free
        self.Du = np.zeros(self.nf)
        self.iters = 0
        self.rnorm_hist = []
        self.responses = None
        self.visc = inc.viscous
        self.dt = inc.dtime
        self.conv = conv = newton.convergence
        self.tangent_update = update = newton.tangent_update
        self.line_search = line_search = newton.line_search is True or (newton.line_search == "auto" and attempt > 1)
        self.broyden = update.secant(uses_lam)
        self.since = 0  # iterations on the current factorisation
        self.ratios = []  # residual ratios, the first before any iteration (modified / quasi-Newton)
        self.steps = []  # largest |correction| of each iteration (modified / quasi-Newton)
        self.keep = update.keeps(system)
        # the predicted-correction acceptance: full Newton (the factorisation in hand formed at the
        # previous iterate), fixed loads, no line search (its steps are not Newton's corrections)
        self.predict = predicts(conv) and update.exact and not uses_lam and not line_search
        self.sizes = []  # scaled size of each correction of this attempt (Convergence.measure)
        self.formed_at = None  # (x, R) of this attempt's last factorisation ("auto", path-independent)
        self.whole = 0
        self.Kfc = None
        self.with_fc = False
        self.du = None  # the last correction: set by iteration 0, read by the convergence test from iteration 1

    def fail(self, why):
        self.state.rollback()
        return Outcome(False, self.iters, why)

    def evaluate(self, P, Dtrial=None, reuse=False):
        """Element responses, the residual of every DOF and that of the free DOFs (with the viscous
        term of a stabilised step) at the current configuration."""
        system = self.system
        ta = _time.perf_counter()
        resp = system.evaluate(self.ctx, reuse=reuse)
        res_ = system.residual(resp, P)
        self.summary.assembly_time += _time.perf_counter() - ta
        if not all_finite(res_):
            raise FloatingPointError("non-finite residual")
        r_ = res_[: self.nf]
        visc = self.visc
        if visc is not None and visc.C is not None:
            r_ = r_ - visc.C / self.dt * (self.Du if Dtrial is None else Dtrial)
        return resp, res_, r_

    def start(self):
        """Apply the increment's predictor, and evaluate the first residual."""
        inc, system = self.inc, self.system
        self.whole = 1 if inc.whole and inc.predictor is not None and not self.uses_lam else 0
        if inc.predictor is not None:
            pdu, pdlam = inc.predictor
            self.Du += pdu
            if self.whole:
                # a predictor of the whole increment (a reference run's converged increment):
                # the prescribed motion goes in with it, not again in the first iteration, and the
                # first iteration is no linear solve from the committed state (no linear-increment rule)
                system.update(pdu, self.dpres if self.has_dpres else None)
                self.dpres, self.has_dpres = None, False
            else:
                system.update(pdu)
            self.lam += pdlam if self.uses_lam else 0.0
        self.lam_start = self.state.lam
        self.P = inc.loads(self.lam)
        self.responses, self.F, self.r = self.evaluate(self.P, reuse=True)

    def unchanged(self) -> bool:
        """Nothing changes (e.g. a step that repeats the previous loads): the committed state is the
        converged solution."""
        st = self.state
        return (
            not self.uses_lam
            and not self.has_dpres
            and not self.whole
            and not np.any(self.Du)
            and self.visc is None
            and st.at_equilibrium
            and np.array_equal(self.P, st.loads)
        )

    def keep_committed(self):
        self.system.commit(self.responses, self.P, self.F, self.lam)
        return Outcome(True, 0, "", self.responses, self.Du, 0.0)

    def converged(self, it):
        """The convergence test after iteration ``it``: the committed :class:`Outcome`, a failed one
        (iterations used up, residual diverging), or None to iterate again."""
        system, conv, responses = self.system, self.conv, self.responses
        ok, ratio, forces_ok, size = system.converged(
            conv, self.r, self.du, self.Du, responses, self.P, self.iters + self.whole
        )
        self.sizes.append(size)
        # (k >= 3: the first iteration is the increment's step, then two corrections of iterates)
        early = not ok and forces_ok and self.predict and self.iters >= 3
        if (ok or early) and any(q.provisional for q in responses):
            ok = early = False  # an element answered with a predictor, not its law (ElementResponse)
        if early:  # the predicted next correction (convergence.py)
            ok = accept_predicted(system, conv, self.r, self.Du, self.sizes)
        hist = self.rnorm_hist
        hist.append(ratio)
        self.ratios.append(ratio)
        if ok:
            return self.commit()
        if it == conv.max_iterations:
            return self.fail(
                f"no convergence in {self.iters} iterations (residual ratio {ratio:.3g}, worst at {system.worst(self.r)})"
            )
        if it >= 8 and hist[-1] > hist[-2] > hist[-3] > hist[-4]:
            return self.fail(f"residual diverging (ratio {ratio:.3g}, worst at {system.worst(self.r)})")
        return None

    def commit(self):
        """Commit the converged increment (and keep its last factorisation for the next one)."""
        state, Du, visc = self.state, self.Du, self.visc
        if visc is not None:
            visc.converged(state, Du, self.dt, self.responses)
        state.last_increment, state.last_size, state.last_dlam = Du.copy(), self.dt, self.lam - self.lam_start
        self.system.commit(self.responses, self.P, self.F, self.lam, equilibrium=visc is None)
        if self.formed_at is not None:  # kept for the next increment's first iteration
            self.tangent_update.keep(state.version, self.formed_at)
        return Outcome(True, self.iters, "", self.responses, Du, self.lam - self.lam_start)

    def form_tangent(self, it):
        """Form and factorise the tangent when the tangent update says so (or reuse the kept one);
        returns why the attempt fails, or None."""
        system, state, inc, update, newton = self.system, self.state, self.inc, self.tangent_update, self.newton
        responses = self.responses
        K = Kfc = None
        self.with_fc = with_fc = it == 0 and self.has_dpres
        if update.reusable(system, state, inc, self.has_dpres, self.uses_lam, it):
            if not update.kept[3]:
                update.form_again(system, state, self.ctx)
            update.drop()
            newton.factorized = True
        elif not newton.factorized or update.due(
            it, inc, self.has_dpres, self.since, self.ratios, self.steps, getattr(self.conv, "force_tol", 0.0)
        ):
            self.since = 0
            update.drop()
            self.formed_at = (state.x.copy(), state.R.copy()) if self.keep else None
            if self.broyden is not None:
                self.broyden.reset()
            visc = self.visc
            try:
                if visc is not None:
                    dt = self.dt
                    K, Kfc = system.factorize_csr(responses, with_fc, adjust=lambda K_: visc.tangent(K_, dt))
                elif inc.direct:
                    K, Kfc = system.factorize_tangent(responses, with_fc)
                else:
                    K, Kfc = system.factorize_csr(responses, with_fc)
                newton.factorized = True
            except SingularModelError:
                bad = system.nonfinite_tangent(responses)
                if bad:
                    return bad
                if self.summary.increments == 0 and it == 0:
                    if K is None:
                        K, _ = system.tangent(responses, with_fc=False)
                    raise SingularModelError(system.singular_message(K, f"step '{inc.step_name}'")) from None
                return "singular tangent (bifurcation or mechanism)"
        elif with_fc:
            Kfc = system.assembler.coupling([q.k for q in responses])
        self.Kfc = Kfc
        if it == 0 and update.watches_progress:  # (after the first tangent's floors)
            self.ratios.append(system.converged(self.conv, self.r, None, self.Du, responses, self.P, 0)[1])
        return None

    def correction(self, it):
        """The correction ``du`` of iteration ``it`` (and the load factor's, when it is an unknown);
        returns why the attempt fails, or None."""
        system, inc, solve = self.system, self.inc, self.system.solver.solve
        ts = _time.perf_counter()
        if it == 0 and inc.predict is not None:  # the arc-length tangent predictor
            du_p = solve(system.reduce_load(inc.P_ref))
            dlam = inc.predict(du_p)
            du = dlam * du_p
            self.lam += dlam
        elif self.broyden is not None and not self.with_fc:
            du = self.broyden.direction(solve, self.r)
        else:
            Kfc = self.Kfc
            rhs = self.r if Kfc is None else self.r - Kfc @ self.dpres
            du = solve(rhs)
            if self.uses_lam:
                du_p = solve(system.reduce_load(inc.P_ref))
                dlam = inc.dlambda(du, du_p, self.Du)
                if dlam is None:
                    self.summary.solve_time += _time.perf_counter() - ts
                    return "arc-length constraint has no real root"
                du = du + dlam * du_p
                self.lam += dlam
        self.summary.solve_time += _time.perf_counter() - ts
        self.du = du
        self.iters += 1
        self.since += 1
        if self.tangent_update.watches_progress:
            self.steps.append(float(np.abs(du).max(initial=0.0)))
        return None

    def advance(self, it):
        """Move the configuration by the correction and evaluate the new residual (with a line
        search where the options ask for one)."""
        system, state, du = self.system, self.state, self.du
        # the trial states of this iterate, for elements that look at their last iteration
        self.ctx.previous = {id(f_): q.state for f_, q in zip(system.families, self.responses)}
        search = self.line_search and not self.uses_lam and not (it == 0 and self.has_dpres)
        before = (state.x.copy(), state.R.copy(), state.spin.copy()) if search else None
        system.update(du, self.dpres if it == 0 else None)
        if self.uses_lam:  # under load control the loads are those of the increment's end
            self.P = self.inc.loads(self.lam)
        P = self.P
        Du_before = self.Du.copy()
        self.Du += du
        self.responses, self.F, r_new = self.evaluate(P)
        if search:
            du, self.responses, self.F, r_new = line_search_step(
                system, state, du, self.r, r_new, self.responses, self.F, before, self.evaluate, P, Du_before
            )
            self.Du = Du_before + du
            self.du = du
        if self.broyden is not None:  # the secant pair of this step (none across prescribed motion)
            self.broyden.step(du, None if self.with_fc else r_new)
        self.r = r_new


def accept_predicted(system, conv, r, Du, sizes) -> bool:
    """Accept the current iterate on its predicted next correction: the simplified Newton
    correction K^-1 r with the factorisation in hand (formed at the previous iterate), one solve
    (:meth:`Convergence.accept_predicted`); no solve unless the last correction contracted.
    ``sizes``: the scaled sizes of the attempt's corrections so far."""
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
