"""A reference run's converged increments as the predictor of a nearby run.

A fit of an FE experiment runs the same model along the same path many times with slightly
different parameters.  The converged increments of one run (the free DOFs' increment ``Du`` of
every increment) predict those of the next far better than the tangent predictor of the prescribed
motion: Newton then starts an increment from the reference's solution and needs fewer iterations.

* :class:`ReferencePath` is an observer (pass it in ``Analysis(observers=[ref])``) that records the
  converged increments of a run, keyed by (step, total time at the start, at the end);
* ``Analysis.reference = ref`` (another run of a model with the same DOF numbering) makes the
  increment control propose the recorded ``Du`` of the increment with the same step and times as
  the predictor (:attr:`femast.analysis.control.plan.Increment.predictor`); the prescribed motion of the
  increment is applied together with it (newton.py), and increments without a recorded match (a
  cutback, a step the reference did not make) start as without a reference.

The converged solution is the same to within the convergence tolerances: Newton iterates from
another start to the same equilibrium (the tolerances, not the path, bound the difference; a
path-dependent element -- friction, latches -- sees only the converged configuration of each
increment, as its committed state is updated only on convergence).
"""

from __future__ import annotations

import numpy as np

from .output import Observer


def _key(step: int, t0: float, t1: float) -> tuple:
    return (int(step), round(float(t0), 9), round(float(t1), 9))


class ReferencePath(Observer):
    """The converged free-DOF increments of a run (see the module docstring).

    n_free : the number of free DOFs, checked when the path is used (None: not known yet; set by the
    first recorded increment)."""

    def __init__(self):
        self.increments = {}
        self.n_free = None

    def converged(self, analysis, step, increment, attempt, iterations, time, dtime, last, responses, note):
        st = analysis.state
        if st.last_increment is None or iterations == 0:  # 0: nothing changed (no new last_increment)
            return
        t1 = st.total_time
        self.increments[_key(st.step, t1 - dtime, t1)] = st.last_increment.copy()
        self.n_free = st.last_increment.size

    def predictor(self, step: int, t0: float, t1: float):
        """The recorded ``Du`` of the increment of ``step`` from total time ``t0`` to ``t1`` (s), or None."""
        return self.increments.get(_key(step, t0, t1))

    def __len__(self):
        return len(self.increments)

    def nbytes(self) -> int:
        return int(sum(np.asarray(v).nbytes for v in self.increments.values()))
