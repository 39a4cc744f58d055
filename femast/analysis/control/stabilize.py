"""Viscous stabilisation of a step, like Abaqus *STABILIZE.

Viscous forces proportional to the nodal pseudo-velocities are added to the residual,

    f_v = C Du / dt,    C = c D,

with Du the increment of the free DOFs, dt the increment of step time, D the median diagonal
stiffness of the DOF's field (translations, rotations) in the tangent at the start of the step
(one value per field, like a uniform mass) and c (s, pseudo-time) the damping factor.

Given a dissipated-energy fraction f (Abaqus' default 2e-4) rather than c directly, femast sets
c = f dt_0 / 2 with dt_0 the step's initial increment: for a DOF that moves elastically,
Du D Du ~ 2 x the strain energy of that motion, so the first increment dissipates about f times
the strain energy it stores.  Mechanism motions, which store little strain energy, dissipate
more: that is why the ratio of stabilisation energy to strain energy is reported for every
increment and at the end of the step, with a warning above 5 %.

With ``adaptive=True`` (default, like Abaqus' adaptive stabilisation) the damping is halved
after every converged increment while the step's ratio exceeds half the warning ratio (down
to 1e-4 of its initial value); a cut-back increment gets more damping anyway, since C/dt grows.

:class:`Stabilize` holds the user's parameters and the damping law; :class:`ViscousTerm` is what the
Newton loop does with them: add C/dt to the tangent and -C Du/dt to the residual, and at each
converged increment account the dissipated energy and the largest viscous force and moment, and
adapt C.  The damping C (and its initial value) is kept in the analysis :class:`State`
(``state.damping``, ``state.damping0``), like everything else an increment carries forward.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import ModelError


class StabilizationWarning(UserWarning):
    """The stabilisation energy of a step exceeds its warning ratio of the strain energy."""


@dataclass
class Stabilize:
    """energy_fraction : dissipated-energy fraction (dimensionless, default 2e-4), or
    factor : the damping factor c (s of step time) directly.  warn_ratio : warn when the
    stabilisation energy exceeds this fraction of the strain energy (default 0.05).
    adaptive : lower the damping while the energy ratio is high (see module docstring)."""

    energy_fraction: float = 2e-4
    factor: float | None = None
    warn_ratio: float = 0.05
    adaptive: bool = True

    def __post_init__(self):
        if self.factor is not None and not (self.factor > 0 and np.isfinite(self.factor)):
            raise ModelError(f"Stabilize: factor = {self.factor} must be a positive number (s)")
        if not (self.energy_fraction > 0 and np.isfinite(self.energy_fraction)):
            raise ModelError(f"Stabilize: energy_fraction = {self.energy_fraction} must be positive")

    def damping(self, K_diag, is_rot, dt0):
        """The diagonal C (per free DOF): c times the median stiffness of the DOF's field
        (translations or rotations) of the start-of-step tangent.  One value per field, like a
        uniform mass: penalty ties and stiff members do not make their DOFs stickier, and the
        mechanism DOFs (zero stiffness), which the damping is for, get the typical value."""
        d = np.abs(np.asarray(K_diag, dtype=float))
        D = np.empty_like(d)
        for field in (~is_rot, is_rot):
            if not field.any():
                continue
            vals = d[field]
            pos = vals[vals > 1e-12 * vals.max(initial=0.0)]
            D[field] = np.median(pos) if pos.size else 1.0
        c = self.factor if self.factor is not None else 0.5 * self.energy_fraction * dt0
        return c * D

    def adapt(self, C, C0, ratio):
        """Damping for the next increment given the step's current energy ratio."""
        if self.adaptive and ratio > 0.5 * self.warn_ratio:
            return np.maximum(0.5 * C, 1e-4 * C0)
        return C


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
