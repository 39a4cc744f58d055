"""The plan of a step: what every control strategy's increments have in common.

A control strategy (:mod:`.load`, :mod:`.displacement`, :mod:`.arclength`, or one of your own)
holds the user's parameters and makes a *plan* for each step with its ``plan(analysis, step)``
method (:func:`femast.analysis.control.plan_for`; docs/architecture.md shows a control of your own).  The plan is all that
differs between strategies in the step loop (stepping.py): it proposes each increment (times,
loads, predictor, load-factor constraint: an :class:`Increment`, all that the Newton loop reads
from a control), shrinks it after a failure (cutback) and sizes the next one after a success.  The
Newton loop and the output are shared; the control strategies sit below them and import neither.

A plan keeps what it carries from increment to increment in the analysis :class:`State`
(``step_time``, ``size``, ``first_size``, ``easy``, ``last_increment``...), so a saved state holds it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from tqdm.auto import tqdm

from ...model.gravity import step_gravity, unit_gravity_loads


@dataclass
class Increment:
    """One increment as a control strategy proposes it to :meth:`femast.analysis.newton.Newton.solve`.

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
    viscous : a :class:`~femast.analysis.control.stabilize.ViscousTerm` (stabilised step), or None.
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
