"""How each control strategy walks a step: the increment plans.

A control strategy (femast/analysis/solvers/control.py, arclength.py: the user's parameters) gets a *plan*
for each step (:func:`plan_for`; a control of your own makes it with its ``plan(analysis, step)``
method, see docs/architecture.md).  The plan is all that differs between
strategies in the step loop (stepping.py): it proposes each increment (times, loads, predictor,
load-factor constraint: a :class:`~femast.analysis.newton.Increment`), shrinks it after a failure
(cutback) and sizes the next one after a success.  The Newton loop and the output are shared.

* :class:`TimeIncrements`: load and displacement control.  The step time runs from 0 to the step's
  period; loads and prescribed values follow it (or, under displacement control, the loads are
  ``P_start + lambda P_ref`` with lambda fixed by the controlled DOF).  A failed increment is
  retried with ``cutback`` x its size (Abaqus: 0.25); after two easy increments the size grows by
  ``growth`` (1.5); the increment lands on the step's hit times and amplitude breakpoints.
* :class:`ArcIncrements`: arc length.  The size is the arc length dl, adapted as
  dl sqrt(I_d / I) (femast/analysis/solvers/arclength.py); the step ends at the load factor or monitor.

A plan keeps what it carries from increment to increment in the analysis :class:`State`
(``step_time``, ``size``, ``first_size``, ``easy``, ``last_increment``...), so a saved state holds it.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from tqdm.auto import tqdm

from ..errors import ConvergenceError, ModelError
from ..model.gravity import step_gravity, unit_gravity_loads
from .newton import Increment
from .summary import StabilizationWarning
from .viscous import ViscousTerm


def step_values(model, conds, start, frac_time, period):
    """Loads or prescribed values (n, 6) at step time ``frac_time * period`` (s), from ``start``."""
    return _values(_rows(model, conds), start, frac_time, period)


def _rows(model, conds):
    """(node row, dof, amplitude, magnitude) of each condition (looked up once per step)."""
    return [(model.index(c.node), c.dof, c.amplitude, c.magnitude) for c in conds]


def _values(rows, start, frac_time, period):
    """:func:`step_values` of conditions given by :func:`_rows`."""
    out = start.copy()
    for i, dof, amplitude, magnitude in rows:
        if amplitude is not None:
            out[i, dof] = amplitude(frac_time * period) * magnitude
        else:
            out[i, dof] = start[i, dof] + frac_time * (magnitude - start[i, dof])
    return out


def gravity_of(analysis, step):
    """(G at the step's start, G at its end, amplitude) of the step's gravity, (n, 6) N and N m
    (:mod:`femast.model.gravity`), or None when no step up to this one has gravity."""

    def unit():
        cached = getattr(analysis, "_unit_gravity", None)
        if cached is None:
            X0 = analysis.X0
            cached = unit_gravity_loads(analysis.model, analysis.families, X0, np.tile(np.eye(3), (len(X0), 1, 1)))
            try:
                analysis._unit_gravity = cached
            except AttributeError:  # an analysis object that takes no new attributes: no cache
                pass
        return cached

    return step_gravity(analysis.model, step, unit)


def with_gravity(P, gravity, frac, period):
    """Concentrated loads P (n, 6) plus the step's gravity at step-time fraction ``frac``."""
    if gravity is None:
        return P
    G0, G1, amplitude = gravity
    return P + (amplitude(frac * period) * G1 if amplitude is not None else G0 + frac * (G1 - G0))


def plan_for(analysis, step, control):
    """The plan of ``step`` under ``control``: the control's own (its ``plan`` method) if it has one."""
    if hasattr(control, "plan"):
        return control.plan(analysis, step)
    if getattr(control, "arc_length", False):
        return ArcIncrements(analysis, step, control)
    return TimeIncrements(analysis, step, control)


class Plan:
    """What the step loop asks of a plan; the base has the defaults a simple plan keeps.

    done() : is the step over?  next_increment() : size the coming increment (once per increment).
    propose(attempt) : the :class:`Increment` to solve (attempt 1, 2, ... after cutbacks).
    trial() : (step time, total time, size, load factor) of the increment tried, for status lines.
    cutback(note) : shrink the increment after a failure, or raise ConvergenceError.
    accept(outcome) : advance past a converged increment; returns (step time, size, last, note).
    grow(outcome, bar) : size the next increment, move the progress bar.  finish(info) : the step's
    summary dict.  ``analysis.state.increment`` counts the step's converged increments.
    """

    def __init__(self, analysis, step, control=None):
        self.an, self.step, self.control = analysis, step, control
        self.state = analysis.state

    def bar(self, disable):
        return tqdm(total=self.step.period, desc=f"step {self.step.name}", unit="s", disable=disable, leave=False)

    def next_increment(self):
        pass

    def trial(self):
        st = self.state
        return st.step_time + (st.size or 0.0), st.total_time + (st.size or 0.0), st.size or 0.0, st.lam

    def grow(self, outcome, bar):
        bar.n = self.state.step_time
        bar.refresh()

    def finish(self, info):
        return info


class TimeIncrements(Plan):
    """The increments of a load- or displacement-controlled step (see module docstring)."""

    def __init__(self, analysis, step, control):
        super().__init__(analysis, step, control)
        st = self.state
        period = self.period = step.period
        self.dt_min = step.min_increment or period * 1e-5
        self.dt_max = step.max_increment or period
        self.uses_lam = control.solves_for_load_factor
        self.gravity = gravity_of(analysis, step)
        g_amp = None if self.gravity is None else self.gravity[2]
        if self.uses_lam and (g_amp is not None or any(c.amplitude is not None for c in step.loads)):
            raise ModelError(
                f"step '{step.name}': amplitudes cannot be used with {type(control).__name__}; "
                "the load factor is an unknown"
            )
        self.hit = sorted(
            {float(h) for h in step.hit_times}
            | {
                float(t)
                for c in step.loads + step.prescribed
                if c.amplitude is not None
                for t in c.amplitude.times
                if 0 < t < period
            }
            | {
                float(t)
                for _, _, amp in getattr(step, "temperatures", ())
                if amp is not None
                for t in amp.times
                if 0 < t < period
            }
            | {float(t) for t in (g_amp.times if g_amp is not None else ()) if 0 < t < period}
        )  # temperature and gravity amplitudes
        # the concentrated loads at the step's start (the applied loads less the gravity)
        self.load_start = st.loads.copy() if self.gravity is None else st.loads - self.gravity[0]
        self.pres_start = st.prescribed.copy()
        self.load_rows, self.pres_rows = _rows(analysis.model, step.loads), _rows(analysis.model, step.prescribed)
        sys_ = analysis.system
        # the constrained DOFs that are not fixed (prescribed in some step); none: every increment's
        # dpres is zero, and passed as None (nothing to apply, no coupling term)
        self.moving = ~sys_.fixed[sys_.cons_node, sys_.cons_dof]
        self.any_moving = bool(self.moving.any())
        st.size = st.first_size = step.initial_increment or min(period, step.max_increment or period)
        st.step_time, st.easy, st.lam = 0.0, 0, 0.0
        st.last_increment = None
        st.damping = None
        st.stabilization_energy = 0.0
        self.viscous = (
            ViscousTerm(step.stabilize, st, sys_.is_rot, st.first_size, sys_.plus_diagonal)
            if step.stabilize is not None
            else None
        )

    def bar(self, disable):
        return tqdm(
            total=self.period,
            desc=f"step {self.step.name}",
            unit="s",
            disable=disable,
            leave=False,
            bar_format="{desc}: {percentage:3.0f}%|{bar}| t={n:.4g}/{total:.4g} [{elapsed}<{remaining}]",
        )

    def done(self) -> bool:
        st, step = self.state, self.step
        if not st.step_time < self.period * (1 - 1e-12):
            return True
        if st.increment >= step.max_increments:
            raise ConvergenceError(
                f"step '{step.name}': reached max_increments={step.max_increments} at step "
                f"time {st.step_time:.6g} of {self.period:g} s; raise max_increments or "
                "max_increment"
            )
        return False

    def next_increment(self):
        """Size the coming increment: not beyond the step's end, its maximum or the next hit time."""
        st, period = self.state, self.period
        t = st.step_time
        dt = min(st.size, self.dt_max, period - t)
        for h in self.hit:
            if t + 1e-12 * period < h < t + dt - 1e-12 * period:
                dt = h - t
                break
        st.size = dt

    def propose(self, attempt) -> Increment:
        an, st, step, period = self.an, self.state, self.step, self.period
        sys_ = an.system
        t, dt = st.step_time, st.size
        frac = (t + dt) / period
        fields = getattr(an, "fields", None)
        if fields is not None and fields.set(st.step, frac):
            # the element properties changed (temperature): the committed response is not this one's
            sys_.last_converged = None
            st.at_equilibrium = False
        inc = Increment(
            time=t + dt, dtime=dt, total_time=st.total_time + dt, step_name=step.name, lam=frac, viscous=self.viscous
        )
        if self.uses_lam:
            inc.lam = st.lam
            P_end = with_gravity(_values(self.load_rows, self.load_start, 1.0, period), self.gravity, 1.0, period)
            P_start = with_gravity(self.load_start, self.gravity, 0.0, period)
            inc.P_start, inc.P_ref = P_start, P_end - P_start
            eq, control = self.control.eq, self.control
            node, dof = sys_.free_node[eq], sys_.free_dof[eq]
            inc.dlambda = lambda du_r, du_p, Du: control.dlambda(du_r, du_p, sys_.dof_value(node, dof), frac)
        else:
            inc.P = with_gravity(_values(self.load_rows, self.load_start, frac, period), self.gravity, frac, period)
        dpres = None
        if self.any_moving:
            pres = _values(self.pres_rows, self.pres_start, frac, period)
            cn, cd = sys_.cons_node, sys_.cons_dof
            dpres = pres[cn, cd] - st.prescribed[cn, cd]
            dpres[~self.moving] = 0.0
        inc.dpres = dpres
        ref = getattr(an, "reference", None)
        pdu = None if ref is None or self.uses_lam else ref.predictor(st.step, st.total_time, st.total_time + dt)
        if pdu is not None and pdu.shape == (
            sys_.n_free,
        ):  # a reference run's converged increment (femast.analysis.reference)
            inc.predictor, inc.whole = (pdu, 0.0), True
        elif an.extrapolate and st.last_increment is not None and (dpres is None or not dpres.any()):
            # Abaqus' linear extrapolation: start from the previous increment's solution, scaled
            scale = dt / st.last_size
            inc.predictor = (scale * st.last_increment, scale * st.last_dlam)
        return inc

    def trial(self):
        """(step time, total time, size, load factor) of the increment being tried, for status lines."""
        st = self.state
        return st.step_time + st.size, st.total_time + st.size, st.size, st.lam

    def cutback(self, note):
        an, st, step = self.an, self.state, self.step
        st.size *= an.cutback
        st.easy = 0
        if st.size < self.dt_min:
            raise ConvergenceError(
                f"step '{step.name}': increment fell below the minimum {self.dt_min:.3g} s at step time "
                f"{st.step_time:.6g} s (total time {st.total_time:.6g} s): {note}. The {an.summary.increments} "
                f"converged increments are {an.kept()}."
            )

    def accept(self, outcome):
        """Advance past a converged increment; returns (step time, size, last of the step, status note)."""
        st, dt = self.state, self.state.size
        st.step_time += dt
        st.total_time += dt
        last = not st.step_time < self.period * (1 - 1e-12)
        note = ""
        if self.step.stabilize is not None:
            note = (
                f"stabilisation/strain energy {self.stabilization_ratio:.3g}, largest viscous force "
                f"{st.stabilization_force:.3g} N, moment {st.stabilization_moment:.3g} N m"
            )
        return st.step_time, dt, last, note

    def grow(self, outcome, bar):
        st = self.state
        bar.update(st.size)
        st.easy = st.easy + 1 if outcome.iterations <= self.an.easy_iterations else 0
        if st.easy >= 2:
            st.size *= self.an.growth

    @property
    def stabilization_ratio(self) -> float:
        st = self.state
        return (
            st.stabilization_energy / st.strain_energy
            if st.strain_energy > 0
            else (0.0 if st.stabilization_energy == 0 else float("inf"))
        )

    def finish(self, info):
        st, step = self.state, self.step
        if step.stabilize is not None:
            info["stabilization_energy"] = st.stabilization_energy
            info["stabilization_ratio"] = ratio = self.stabilization_ratio
            # viscous forces left in the last increment: how far from equilibrium the end state is
            info["stabilization_force"], info["stabilization_moment"] = (
                st.stabilization_force,
                st.stabilization_moment,
            )
            if ratio > step.stabilize.warn_ratio:
                msg = (
                    f"step '{step.name}': stabilisation energy is {100 * ratio:.1f}% of the strain "
                    f"energy (above {100 * step.stabilize.warn_ratio:.0f}%): the stabilised solution may be "
                    "far from equilibrium; lower the damping factor or the energy fraction"
                )
                warnings.warn(msg, StabilizationWarning, stacklevel=4)
                if self.an.progress:
                    tqdm.write("femast: warning: " + msg)
        return info


class ArcIncrements(Plan):
    """The increments of an arc-length step (:class:`~femast.analysis.solvers.arclength.ArcLength`)."""

    def __init__(self, analysis, step, control):
        super().__init__(analysis, step, control)
        st = self.state
        self.load_start = st.loads.copy()
        gravity = gravity_of(analysis, step)
        if gravity is not None and gravity[2] is not None:
            raise ModelError(f"step '{step.name}': a gravity amplitude cannot be used with arc length")
        user_start = self.load_start if gravity is None else self.load_start - gravity[0]
        P_end = with_gravity(step_values(analysis.model, step.loads, user_start, 1.0, step.period), gravity, 1.0, 1.0)
        self.P_ref = P_end - self.load_start
        st.lam = 0.0
        st.size = st.first_size = None  # the first arc length comes from the first predictor
        st.step_time = 0.0
        st.last_increment = None
        self.finished = False

    def bar(self, disable):
        return tqdm(
            total=1.0,
            desc=f"step {self.step.name} (arc length)",
            disable=disable,
            leave=False,
            bar_format="{desc}: {percentage:3.0f}%|{bar}| [{elapsed}<{remaining}]",
        )

    def done(self) -> bool:
        return self.finished

    def _predict(self, du_p):
        """Load-factor predictor: the arc length along the tangent, in the previous increment's direction."""
        st, control = self.state, self.control
        norm_p = math.sqrt(control.norm2(du_p))
        if st.size is None:
            st.size = control.initial_load_factor * norm_p
        sign = 1.0
        if st.last_increment is not None:
            sign = 1.0 if float(st.last_increment @ (control.weights * du_p)) >= 0 else -1.0
        return sign * st.size / norm_p

    def _correct(self, du_r, du_p, Du):
        return self.control.correction(Du, du_r, du_p, self.state.size)

    def propose(self, attempt) -> Increment:
        st = self.state
        return Increment(
            time=st.lam,
            dtime=0.0,
            total_time=st.total_time,
            step_name=self.step.name,
            lam=st.lam,
            P_start=self.load_start,
            P_ref=self.P_ref,
            predict=self._predict,
            dlambda=self._correct,
            direct=False,
        )

    def trial(self):
        st = self.state
        return st.lam, st.total_time, st.size, st.lam

    def cutback(self, note):
        an, st, control = self.an, self.state, self.control
        if st.first_size is None:
            st.first_size = st.size
        st.size *= an.cutback
        if st.size < control.min_arc * st.first_size:
            raise ConvergenceError(
                f"step '{self.step.name}': arc length fell below the minimum ({control.min_arc:g} of the first) "
                f"at load factor {st.lam:.6g}: {note}. The {an.summary.increments} converged "
                f"increments are {an.kept()}."
            )

    def accept(self, outcome):
        an, st, control = self.an, self.state, self.control
        if st.first_size is None:
            st.first_size = st.size
        dl = st.size
        st.total_time += dl / st.first_size * control.initial_load_factor
        st.step_time = st.lam
        self.frac = control.progress(an, st.lam)
        self.finished = self.frac >= 1.0 - 1e-12 or st.increment >= self.step.max_increments
        return st.lam, dl, self.finished, f"arc length {dl:.4g}"

    def grow(self, outcome, bar):
        st, control = self.state, self.control
        bar.n = min(max(self.frac, 0.0), 1.0)
        bar.refresh()
        dl = st.size * min(max(math.sqrt(control.desired_iterations / max(outcome.iterations, 1)), 0.5), 2.0)
        st.size = min(max(dl, control.min_arc * st.first_size), control.max_arc * st.first_size)

    def finish(self, info):
        info["final_load_factor"] = self.state.lam
        return info
