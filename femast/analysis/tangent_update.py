"""When the Newton loop forms a new tangent: the tangent updates of :class:`~femast.analysis.newton.Newton`.

Each update is a small strategy the loop asks at every iteration (:meth:`TangentUpdate.due`) and at
the start of each attempt (:meth:`TangentUpdate.secant`); :data:`UPDATES` maps the names of
``Analysis(tangent=...)`` to them.

* :class:`FullNewton` (``"full"``): a new tangent every iteration (Newton-Raphson).
* :class:`AutoNewton` (``"auto"``, the default): full Newton, except that the first iteration of an
  increment reuses the factorisation of the previous increment's last iteration (formed one
  correction away from the converged configuration, of the order of the tolerance) when nothing
  else may have changed the tangent: the same step, load control without a predictor, no
  prescribed values, no viscous term, every element family path-independent and the previous
  increment converged.  A restart point keeps the configuration that factorisation was formed at
  (:meth:`AutoNewton.configuration`), and a restarted run forms it again there, so that it continues
  bit for bit as the uninterrupted run.
* :class:`ModifiedNewton` (``"modified"``): a tangent at the start of each attempt, formed again after
  ``refactor_every`` iterations on it or as soon as convergence slows (the residual ratio or the
  correction falls by less than the factor ``slow`` in an iteration).
* :class:`QuasiNewton` (``"quasi-newton"``): as modified, with Broyden's update of the inverse
  between two factorisations (:class:`Broyden`); under a control whose load factor is an unknown
  it acts as modified.
* :class:`InitialStiffness` (``"initial"``): one tangent per step, formed again only where an
  increment needs its own (prescribed values or a viscous term).
"""

from __future__ import annotations

import numpy as np


class TangentUpdate:
    """The base of the tangent updates: a new tangent whenever :meth:`due` says so.

    method : the name reported by :meth:`Newton.method`.  exact : the tangent is the current
    iterate's at every iteration (the predicted-correction acceptance is valid only then).
    watches_progress : the loop records the residual ratios and correction sizes :meth:`due` reads.
    """

    method = "full"
    exact = True
    watches_progress = False

    def __init__(self, refactor_every: int = 6, slow: float = 0.25):
        self.refactor_every = refactor_every
        self.slow = slow

    def new_step(self):
        """A new step begins."""

    def due(self, it, inc, has_dpres, since, ratios, steps, force_tol) -> bool:
        """A new factorisation for iteration ``it`` (0: the attempt's first) of increment ``inc``?
        (Asked only when a factorisation exists.)"""
        return True

    def secant(self, uses_lam):
        """The secant update of this attempt's inverse (a :class:`Broyden`), or None."""
        return None

    # the factorisation kept across increments (AutoNewton only)
    def reusable(self, system, state, inc, has_dpres, uses_lam, it) -> bool:
        return False

    def keeps(self, system) -> bool:
        """Does this attempt remember where its factorisations were formed (to keep the last)?"""
        return False

    def keep(self, version, formed_at):
        pass

    def drop(self):
        pass

    def configuration(self):
        return None

    def resume(self, version, x, R):
        pass


class FullNewton(TangentUpdate):
    """Newton-Raphson: a new tangent every iteration."""


class AutoNewton(FullNewton):
    """Full Newton whose increments may start on the previous increment's last factorisation
    (module docstring)."""

    def __init__(self, refactor_every: int = 6, slow: float = 0.25):
        super().__init__(refactor_every, slow)
        # [state version, x, R, formed] of the factorisation kept for the next increment's first
        # iteration (x, R: the configuration it was formed at; formed False after a restart)
        self.kept = None

    def new_step(self):
        self.kept = None  # no factorisation is reused across steps

    def reusable(self, system, state, inc, has_dpres, uses_lam, it) -> bool:
        """The kept factorisation serves this increment's first iteration."""
        r = self.kept
        return (
            it == 0
            and r is not None
            and r[0] == state.version
            and not has_dpres
            and not uses_lam
            and inc.predictor is None
            and inc.viscous is None
            and inc.direct
            and all(f.path_independent for f in system.families)
        )

    def form_again(self, system, state, ctx):
        """Form the kept factorisation again at the configuration it was formed at (a restarted run)."""
        keep = state.x, state.R
        state.x, state.R = self.kept[1].copy(), self.kept[2].copy()
        try:
            system.factorize_tangent(system.evaluate(ctx), False)
        finally:
            state.x, state.R = keep
        self.kept[3] = True

    def keeps(self, system) -> bool:
        return all(f.path_independent for f in system.families)

    def keep(self, version, formed_at):
        self.kept = [version, formed_at[0], formed_at[1], True]

    def drop(self):
        self.kept = None

    def configuration(self):
        return None if self.kept is None else (self.kept[1], self.kept[2])

    def resume(self, version, x, R):
        self.kept = [version, x, R, False]


class ModifiedNewton(TangentUpdate):
    """A tangent per attempt, formed again after ``refactor_every`` iterations or when
    convergence slows."""

    method = "modified"
    exact = False
    watches_progress = True

    def due(self, it, inc, has_dpres, since, ratios, steps, force_tol) -> bool:
        """Each attempt starts on its own tangent; a new one when the last iteration reduced the
        residual ratio by less than the factor ``slow`` (unless the residual already meets its
        tolerance, 1e-2 of it: the iterations left are for the displacement test) or the
        correction by less than that factor.  ``ratios``: the residual ratios of this attempt, the
        first one before any iteration; ``steps``: the largest |correction| of each iteration."""
        if it == 0 or since >= self.refactor_every:
            return True
        slow_r = ratios[-1] > 1e-2 * force_tol and ratios[-1] > self.slow * ratios[-2]
        slow_d = len(steps) >= 2 and steps[-1] > self.slow * steps[-2]
        return slow_r or slow_d


class QuasiNewton(ModifiedNewton):
    """Modified Newton with Broyden's update of the inverse between factorisations."""

    method = "quasi-newton"

    def secant(self, uses_lam):
        return None if uses_lam else Broyden()


class InitialStiffness(TangentUpdate):
    """One tangent per step, formed again for an increment with prescribed values or a viscous term."""

    method = "initial"
    exact = False

    def due(self, it, inc, has_dpres, since, ratios, steps, force_tol) -> bool:
        return it == 0 and (has_dpres or inc.viscous is not None)


#: ``Analysis(tangent=...)`` -> the tangent update
UPDATES = {
    "auto": AutoNewton,
    "full": FullNewton,
    "modified": ModifiedNewton,
    "quasi-newton": QuasiNewton,
    "initial": InitialStiffness,
}


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
