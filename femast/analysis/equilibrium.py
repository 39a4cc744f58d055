"""No result without equilibrium: the balance of a completed run, checked for every element family.

Newton accepts an increment when its convergence test says so, and that test is only as good as
its tolerances (or, for a test of one's own, its code).  A run that ends "completed" is checked
once more at its last converged state, independently of both:

1. **The free residual is small**: its largest force (moment) is at most :data:`END_RATIO` of the
   force (moment) scale of the convergence test (the largest applied load or element nodal force,
   never below the zero-force floor of the model's stiffness).  On the last increment of a
   stabilised step the viscous forces are part of the balance (Abaqus *STABILIZE): the residual
   may exceed the bound by the largest viscous force (moment) of that increment.
2. **The reactions balance the applied loads**, force and moment about the origin, for every
   element family: the loads plus the reactions equal the resultant of the families tied to the
   ground (those that do not claim ``self_equilibrated``), up to what the residual leaves and
   round-off.  A family that claims to be self-equilibrated must have a zero resultant itself.

Either failure raises :class:`~femast.errors.EquilibriumError` naming the worst DOF or the family;
the run's summary then says "failed" (its frames stay on disk).  The cost is one assembly of the
converged forces per run.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import EquilibriumError
from ..model import validation
from .assembly import _scatter_vector
from .convergence import field_abs_max, force_moment_abs_max

END_RATIO = 1e-2  # the largest residual of a completed run, as a fraction of its force scale
ROUND_OFF = 1e-9  # a self-equilibrated family's resultant, as a fraction of its summed forces


def _nodal(system, active_values) -> np.ndarray:
    """An (n, 6) nodal array of a vector on the active DOFs."""
    out = np.zeros((len(system.X0), 6))
    out[system.act_node, system.act_dof] = active_values
    return out


def _resultant(x, F) -> np.ndarray:
    """Resultant force and moment about the origin (6,) of nodal forces ``F`` (n, 6) at ``x`` (n, 3)."""
    return np.concatenate([F[:, :3].sum(axis=0), np.cross(x, F[:, :3]).sum(axis=0) + F[:, 3:].sum(axis=0)])


def check_end_of_run(analysis) -> None:
    """The two checks of the module docstring on ``analysis``' committed state, or EquilibriumError."""
    sys_, st = analysis.system, analysis.state
    last = sys_.last_converged
    responses = last[1] if last is not None and last[0] == st.version else sys_.evaluate(sys_.committed_context())
    res = sys_.residual(responses, st.loads)
    nf = sys_.n_free
    r = res[:nf]
    _small_residual(analysis, r, responses)
    ground = family_balance(sys_, responses, st.x, _where(analysis))
    RF = np.zeros((len(st.x), 6))
    RF[sys_.cons_node, sys_.cons_dof] = -res[nf:]
    validation.check_equilibrium(
        st.x,
        st.loads,
        RF,
        r,
        sys_.free_dof,
        _where(analysis),
        internal=float(sum(np.abs(q.f).sum() for q in responses)),
        labels=sys_.model.node_labels,
        ground=ground,
    )


def family_balance(system, responses, x, where: str) -> np.ndarray:
    """The resultant (6,) of the families tied to the ground (force, moment about the origin) at
    positions ``x``; an EquilibriumError naming a family that claims ``self_equilibrated`` but whose
    own resultant is not zero (beyond round-off of its summed forces)."""
    ground = np.zeros(6)
    arm = float(np.abs(x).max()) * math.sqrt(3.0) + 1.0
    for fam, q, eqs in zip(system.families, responses, system.assembler.eqs):
        F = np.zeros(system.dofmap.n_active)
        _scatter_vector(q.f, eqs, F)  # its forces on the active DOFs, as assembled
        R = _resultant(x, _nodal(system, F))
        if not getattr(fam, "self_equilibrated", False):
            ground += R
            continue
        scale = float(np.abs(q.f).sum()) + 1e-300
        if np.linalg.norm(R[:3]) > ROUND_OFF * scale or np.linalg.norm(R[3:]) > ROUND_OFF * scale * arm:
            raise EquilibriumError(
                f"{where}: element family '{fam.name}' is marked self-equilibrated, but its nodal forces sum to "
                f"{np.linalg.norm(R[:3]):.3g} N and {np.linalg.norm(R[3:]):.3g} N m; set self_equilibrated = False "
                "if its elements are tied to the ground (or act off the line between their nodes), else its "
                "forces are wrong"
            )
    return ground


def _where(analysis) -> str:
    st = analysis.state
    step = analysis.model.steps[st.step].name
    return f"the end of the run (step '{step}', increment {st.increment})"


def _small_residual(analysis, r, responses) -> None:
    """Check 1 of the module docstring."""
    sys_, st = analysis.system, analysis.state
    fmax, mmax = force_moment_abs_max(st.loads)
    for q in responses:
        ff, mm = force_moment_abs_max(q.f)
        fmax, mmax = max(fmax, ff), max(mmax, mm)
    L = sys_.length
    floor = sys_.zero_force or 0.0
    ref_f = max(fmax, 1e-2 * mmax / L, floor)
    ref_m = max(mmax, 1e-2 * fmax * L, floor * L)
    viscous = analysis.model.steps[st.step].stabilize is not None and not st.at_equilibrium
    extra_f, extra_m = (st.stabilization_force, st.stabilization_moment) if viscous else (0.0, 0.0)
    rt, rm = field_abs_max(np.ascontiguousarray(r, dtype=float), sys_.is_rot)
    for worst, ref, extra, unit, mask in (
        (rt, ref_f, extra_f, "N", ~sys_.is_rot),
        (rm, ref_m, extra_m, "N m", sys_.is_rot),
    ):
        if worst < 0.0:  # no DOF of this field
            continue
        allowed = END_RATIO * ref + extra
        if not worst <= allowed:  # (NaN too)
            eq = int(np.flatnonzero(mask)[np.argmax(np.abs(r[mask]))])
            raise EquilibriumError(
                f"{_where(analysis)}: the completed run is not in equilibrium: a residual of {worst:.3g} {unit} at "
                f"{sys_.dofmap.describe(eq)}, {100 * worst / ref:.3g} % of the force scale {ref:.3g} {unit} (at most "
                f"{100 * END_RATIO:g} % allowed{' with the viscous forces' if extra else ''}): the convergence test accepted "
                "increments that are not converged; tighten its tolerances (Convergence(force_tol=..., disp_tol=...))"
            )
