"""Numbering of degrees of freedom.

Every node has six DOF slots (ux, uy, uz, rx, ry, rz).  A slot is *active* if some
element family gives it stiffness; active slots are *free* (equation numbers
0..n_free-1), *constrained* (fixed or prescribed in some step; numbers
n_free..n_free+n_constrained-1) or *dependent* (eliminated by rigid bodies or ties;
numbered last).  Inactive slots get -1 and are ignored by assembly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..elements.base import DOF_NAMES


@dataclass
class DofMap:
    """eq[node_index, dof] = equation number (free first, then constrained), -1 if inactive."""

    eq: np.ndarray
    n_free: int
    n_active: int
    labels: np.ndarray  # node labels, for messages
    n_constrained: int = 0

    @property
    def n_independent(self) -> int:
        """Free plus constrained DOFs (the rest are dependent, eliminated by constraints)."""
        return self.n_free + self.n_constrained

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


def number_dofs(
    n_nodes: int, families, constrained_slots: np.ndarray, labels, extra_active=None, dependent=None
) -> DofMap:
    """Number the DOFs.  ``constrained_slots`` is a (n_nodes, 6) bool array of slots that are
    fixed or prescribed (constraining an inactive slot has no effect); ``extra_active`` slots are
    active even without an element (rigid-body reference nodes); ``dependent`` slots are
    eliminated by multi-point constraints and numbered last (after the constrained ones)."""
    active = np.zeros((n_nodes, 6), dtype=bool)
    for fam in families:
        nodes = np.unique(np.asarray(fam.nodes).ravel())
        for d in fam.active_dofs:
            active[nodes, d] = True
    if extra_active is not None:
        active |= extra_active
    dep = np.zeros_like(active) if dependent is None else (dependent & active)
    free = active & ~constrained_slots & ~dep
    cons = active & constrained_slots & ~dep
    eq = np.full((n_nodes, 6), -1, dtype=np.int64)
    n_free = int(free.sum())
    n_cons = int(cons.sum())
    eq[free] = np.arange(n_free)
    eq[cons] = n_free + np.arange(n_cons)
    eq[dep] = n_free + n_cons + np.arange(int(dep.sum()))
    return DofMap(eq=eq, n_free=n_free, n_active=int(active.sum()), labels=np.asarray(labels), n_constrained=n_cons)
