"""Two-node truss / cable element (the analogue of Abaqus T3D2), geometrically exact.

Axial force N = EA (l - L0) / L0 with L0 the unstretched length (engineering strain
on the reference length, large rotations exact).  A length error or thermal strain makes the
stress-free length L0 s (``length_factor`` s): N = EA (l - L0 s) / L0.  A tension-only element (a cable)
carries N = max(N, 0).  Given a pretension N0 instead of L0, the unstretched length
is chosen so that the element carries N0 in the initial geometry: L0 = l_init / (1 + N0/EA).

Tangent: K = EA/L0 e e^T + N/l (I - e e^T) on each node pair (symmetric).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .base import ElementFamily, ElementResponse


@njit(cache=True)
def truss_family_kernel(nodes, x, L0, EA, tension_only, length_factor, f, K, N_out, energy):
    """All trusses at once; writes the translational entries of ``f`` and ``K`` (the rotational
    rows and columns stay as given: zero).  Scalars only, no allocation.

    ``length_factor`` (dimensionless, per element): the stress-free length is ``L0 * factor``
    (a length error and a thermal strain, femast/model/thermal.py); the strain is measured on ``L0``:
    N = EA (l - L0 factor) / L0, so dN/dl = EA / L0 is unchanged."""
    for el in range(nodes.shape[0]):
        a = nodes[el, 0]
        b = nodes[el, 1]
        d0 = x[b, 0] - x[a, 0]
        d1 = x[b, 1] - x[a, 1]
        d2 = x[b, 2] - x[a, 2]
        l = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        e0 = d0 / l
        e1 = d1 / l
        e2 = d2 / l
        k_ax = EA[el] / L0[el]
        Lf = L0[el] * length_factor[el]
        N = k_ax * (l - Lf)
        if tension_only[el] and N <= 0.0:
            N = 0.0
            k_ax = 0.0
        N_out[el] = N
        energy[el] = 0.5 * N * (l - Lf)
        g = N / l
        for i in range(3):
            ei = e0 if i == 0 else (e1 if i == 1 else e2)
            f[el, i] = -N * ei
            f[el, 6 + i] = N * ei
            for j in range(3):
                ej = e0 if j == 0 else (e1 if j == 1 else e2)
                kij = (k_ax - g) * ei * ej + (g if i == j else 0.0)
                K[el, i, j] = kij
                K[el, 6 + i, 6 + j] = kij
                K[el, i, 6 + j] = -kij
                K[el, 6 + i, j] = -kij


class TrussFamily(ElementFamily):
    """A batch of trusses / cables: ``L0`` unstretched lengths (m), ``EA`` (N),
    ``tension_only`` (bool per element).  ``length_factor`` (dimensionless, ones by default): the
    stress-free length over ``L0`` (length errors and thermal strain, set by femast/model/thermal.py)."""

    name = "truss"
    self_equilibrated = True  # equal and opposite forces along the chord (checked by the analysis)
    active_dofs = (0, 1, 2)
    n_state = 0
    path_independent = True
    symmetric = True

    def __init__(self, nodes, L0, EA, tension_only, labels=None, name="truss"):
        self.name = name
        self.nodes = np.ascontiguousarray(nodes, dtype=np.int64)
        self.L0 = np.ascontiguousarray(L0, dtype=float)
        self.EA = np.ascontiguousarray(EA, dtype=float)
        self.tension_only = np.ascontiguousarray(tension_only, dtype=np.bool_)
        self.length_factor = np.ones(len(self.nodes))
        self.labels = np.arange(1, len(self.nodes) + 1) if labels is None else np.asarray(labels)

    def evaluate(self, x, R, state, ctx=None):
        n = self.n_elements
        f = np.zeros((n, 12))
        K = np.zeros((n, 12, 12))
        N = np.zeros(n)
        energy = np.zeros(n)
        truss_family_kernel(
            self.nodes,
            np.ascontiguousarray(x),
            self.L0,
            self.EA,
            self.tension_only,
            self.length_factor,
            f,
            K,
            N,
            energy,
        )
        return ElementResponse(f=f, k=K, state=state, output={"N": N}, energy=energy)
