"""The configuration update of a Newton iteration, compiled.

Nodal positions are updated additively, nodal rotations multiplicatively by the spatial spins
(R <- exp(skew(dw)) R, :func:`femast.rotations.apply_spins`), and the accumulated spin (the
rotation output 'URA') additively.
"""

from __future__ import annotations

from numba import njit

from ..rotations import apply_spins


@njit(cache=True)
def _add(x, spin, W, node, dof, du):
    for i in range(du.shape[0]):
        n = node[i]
        d = dof[i]
        if d < 3:
            x[n, d] += du[i]
        else:
            W[n, d - 3] = du[i]
            spin[n, d - 3] += du[i]


@njit(cache=True)
def update_configuration(x, spin, R, W, free_node, free_dof, du_free, cons_node, cons_dof, du_cons):
    """Add the correction ``du_free`` (m, rad) of the free equations (node, DOF 0..5) and
    ``du_cons`` of the constrained ones (an empty array for none) to the positions ``x``
    (n, 3), spins ``spin`` (n, 3) and rotations ``R`` (n, 3, 3), in place.  ``W`` (n, 3) is
    scratch.  A (node, DOF) pair is at most one equation, so no update repeats."""
    W[:] = 0.0
    _add(x, spin, W, free_node, free_dof, du_free)
    _add(x, spin, W, cons_node, cons_dof, du_cons)
    apply_spins(R, W)
