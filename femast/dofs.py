"""Numbering of degrees of freedom.

Every node has six DOF slots (ux, uy, uz, rx, ry, rz).  A slot is *active* if some
element family gives it stiffness; active slots are either *free* (equation numbers
0..n_free-1) or *constrained* (fixed or prescribed in some step; numbers
n_free..n_active-1).  Inactive slots get -1 and are ignored by assembly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .elements.base import DOF_NAMES


@dataclass
class DofMap:
    """eq[node_index, dof] = equation number (free first, then constrained), -1 if inactive."""

    eq: np.ndarray
    n_free: int
    n_active: int
    labels: np.ndarray  # node labels, for messages

    @property
    def n_constrained(self) -> int:
        return self.n_active - self.n_free

    def element_equations(self, nodes: np.ndarray) -> np.ndarray:
        """(n_el, 6 * n_nodes_per_el) equation numbers of a family's element vectors."""
        return self.eq[nodes].reshape(nodes.shape[0], -1)

    def describe(self, equation: int) -> str:
        """'node 12 uz' for an equation number."""
        node, dof = np.argwhere(self.eq == equation)[0]
        return f"node {self.labels[node]} {DOF_NAMES[dof]}"

    def slots(self, equations) -> tuple[np.ndarray, np.ndarray]:
        """(node indices, dof indices) of equation numbers."""
        order = np.full(self.n_active, -1)
        flat = self.eq.ravel()
        act = np.flatnonzero(flat >= 0)
        order[flat[act]] = act
        pos = order[np.asarray(equations)]
        return pos // 6, pos % 6


def number_dofs(n_nodes: int, families, constrained_slots: np.ndarray, labels) -> DofMap:
    """Number the DOFs.  ``constrained_slots`` is a (n_nodes, 6) bool array of slots that are
    fixed or prescribed; constraining an inactive slot is allowed and has no effect."""
    active = np.zeros((n_nodes, 6), dtype=bool)
    for fam in families:
        nodes = np.unique(np.asarray(fam.nodes).ravel())
        for d in fam.active_dofs:
            active[nodes, d] = True
    free = active & ~constrained_slots
    cons = active & constrained_slots
    eq = np.full((n_nodes, 6), -1, dtype=np.int64)
    n_free = int(free.sum())
    eq[free] = np.arange(n_free)
    eq[cons] = n_free + np.arange(int(cons.sum()))
    return DofMap(eq=eq, n_free=n_free, n_active=int(active.sum()), labels=np.asarray(labels))
