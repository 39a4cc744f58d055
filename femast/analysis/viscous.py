"""The viscous term of a stabilised step (Abaqus *STABILIZE), as an option of the Newton loop.

The parameters and the damping law are :class:`~femast.analysis.solvers.stabilize.Stabilize`'s; this is
what the loop does with them: add C/dt to the tangent and -C Du/dt to the residual, and at each
converged increment account the dissipated energy and the largest viscous force and moment, and
adapt C.  The damping C (and its initial value) is kept in the analysis :class:`State`
(``state.damping``, ``state.damping0``), like everything else an increment carries forward.
"""

from __future__ import annotations

import numpy as np


class ViscousTerm:
    """The viscous term of step ``stabilize`` (a :class:`Stabilize`) for an analysis whose free DOFs
    are rotations where ``is_rot``; ``plus_diagonal(K, c)`` adds a diagonal on K's pattern; dt0 is
    the step's initial increment (s), which sets the damping factor from the energy fraction."""

    def __init__(self, stabilize, state, is_rot, dt0, plus_diagonal):
        self.stabilize = stabilize
        self.state = state
        self.is_rot = is_rot
        self.dt0 = dt0
        self.plus_diagonal = plus_diagonal

    @property
    def C(self):
        """The diagonal damping per free DOF (N s/m, N m s/rad), None before the step's first tangent."""
        return self.state.damping

    def tangent(self, K, dt):
        """K + C/dt (C from the diagonal of the first tangent of the step)."""
        st = self.state
        if st.damping is None:  # damping from the tangent at the start of the step
            st.damping = self.stabilize.damping(K.diagonal(), self.is_rot, self.dt0)
            st.damping0 = st.damping.copy()
        return self.plus_diagonal(K, st.damping / dt)

    def converged(self, state, Du, dt, responses):
        """Account a converged increment ``Du`` of size ``dt``: energy, largest forces, adaptation."""
        C = state.damping
        state.stabilization_energy += float(Du @ (C / dt * Du))
        fv = np.abs(C / dt * Du)
        state.stabilization_force = float(fv[~self.is_rot].max(initial=0.0))
        state.stabilization_moment = float(fv[self.is_rot].max(initial=0.0))
        strain = sum(float(np.sum(q.energy)) for q in responses if q.energy is not None)
        ratio = state.stabilization_energy / max(strain, 1e-300)
        state.damping = self.stabilize.adapt(C, state.damping0, ratio)
