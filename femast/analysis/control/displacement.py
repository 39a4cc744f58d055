"""Displacement control (OpenSees' DisplacementControl integrator).

The loads defined in the step form a reference pattern P_ref scaled by an unknown load factor
lambda (P = P_start + lambda P_ref); one chosen DOF follows a linear ramp to ``value`` at the end
of the step.  Passes limit points in load (not in the controlled displacement).

Each Newton iteration solves K du_r = r and K du_p = P_ref and combines du = du_r + dlambda du_p;
the strategy only says how dlambda is chosen.  Its plan is load control's time increments
(:class:`~femast.analysis.control.load.TimeIncrements`) with the load factor as an unknown.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import ModelError
from ...model import dof_index
from .load import TimeIncrements


@dataclass
class DisplacementControl:
    """Control the displacement (m) or accumulated rotation (rad) of ``dof`` at ``node``:
    it ramps linearly from its value at the start of the step to ``value`` at the end."""

    node: int
    dof: str
    value: float
    solves_for_load_factor = True

    def plan(self, analysis, step):
        return TimeIncrements(analysis, step, self)

    def setup(self, analysis, step):
        idx = analysis.model.index(self.node)
        d = dof_index(self.dof)
        eq = analysis.dofmap.eq[idx, d]
        if eq < 0 or eq >= analysis.dofmap.n_free:
            raise ModelError(
                f"step '{step.name}': displacement control on node {self.node} {self.dof}: "
                "that DOF is not a free DOF of the model (fixed, prescribed or unused)"
            )
        self.eq = int(eq)
        self.start = analysis.dof_value(idx, d)
        if not step.loads and getattr(step, "gravity_spec", None) is None:
            raise ModelError(
                f"step '{step.name}': displacement control needs a reference load pattern; "
                "define at least one load (or gravity) in the step"
            )

    def target(self, fraction):
        return self.start + fraction * (self.value - self.start)

    def dlambda(self, du_r, du_p, current, fraction):
        """Load-factor correction that puts the controlled DOF on its target."""
        if abs(du_p[self.eq]) < 1e-300:
            raise ModelError("displacement control: the reference load does not move the controlled DOF")
        return (self.target(fraction) - current - du_r[self.eq]) / du_p[self.eq]
