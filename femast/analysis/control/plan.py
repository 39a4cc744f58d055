"""The plan of a step: what every control strategy's increments have in common.

A control strategy (:mod:`.load`, :mod:`.displacement`, :mod:`.arclength`, or one of your own)
holds the user's parameters and makes a *plan* for each step with its ``plan(analysis, step)``
method (:func:`femast.analysis.control.plan_for`; docs/architecture.md shows a control of your own).  The plan is all that
differs between strategies in the step loop (stepping.py): it proposes each increment (times,
loads, predictor, load-factor constraint: a :class:`~femast.analysis.newton.Increment`), shrinks it
after a failure (cutback) and sizes the next one after a success.  The Newton loop and the output
are shared.

A plan keeps what it carries from increment to increment in the analysis :class:`State`
(``step_time``, ``size``, ``first_size``, ``easy``, ``last_increment``...), so a saved state holds it.
"""

from __future__ import annotations

import numpy as np
from tqdm.auto import tqdm

from ...model.gravity import step_gravity, unit_gravity_loads


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
