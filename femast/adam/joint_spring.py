"""Elastic rotational spring in parallel with each friction ball joint (a regularisation).

A longeron with a friction ball joint at each end has an indeterminate spin (and, in general,
an indeterminate rigid rotation along the joints' slip directions) whenever both joints slip:
the friction moments are saturated at mu B |F| and any spin between the two corners' rotations
is in equilibrium.  Newton's tangent is then singular along that mode; the iterates wander (in
the 40-bay mast under Table 1's loads, a joint was seen turning by more than 3 rad in one
iteration).  A weak linear spring ``M = k theta``, theta = log(R_b R_a^T), between the longeron
end and the corner makes the mode determinate.  With k = ``joint_spring`` (default 10 N m/rad)
its moment is 0.004 N m at the 4e-4 rad relative rotations of Table 1's load case, 1 % of the
friction limit mu B |F| = 0.38 N m, and it adds about 8 k r^2 / l^2 (r = b / sqrt 2) ~ 90 N m/rad
to a bay's torsional stiffness, below 1 % of the cables' (~1e4 N m/rad).

The kernel is the linear case of the torsion spring of ``docs/user_elements.md`` (exact tangent
for finite relative rotations).
"""

from __future__ import annotations

import numpy as np
from numba import carray, njit

from ..elements._mat3 import mm, mm_at, mm_bt, mtv, skew_into
from ..elements._stack import stack_buffer
from ..elements.base import ElementFamily, ElementResponse
from ..rotations import logm_so3_into, ts_inv_into, ts_inv_T_times_derivative_into


@njit(cache=True)
def _spring_kernel(nodes, R, k, f, K, theta):
    # scratch on the stack, 3x3 products without BLAS (femast/elements/_mat3.py)
    vec = carray(stack_buffer(9), (3, 3))
    th, m, g = vec[0], vec[1], vec[2]
    mats = carray(stack_buffer(54), (6, 3, 3))
    Q, Ti, G, GT, H, S = mats[0], mats[1], mats[2], mats[3], mats[4], mats[5]
    for e in range(nodes.shape[0]):
        a, b = nodes[e, 0], nodes[e, 1]
        mm_bt(R[b], R[a], Q)
        logm_so3_into(Q, th)
        for i in range(3):
            m[i] = k[e] * th[i]
        ts_inv_into(th, Ti)
        mtv(Ti, m, g)
        ts_inv_T_times_derivative_into(th, m, G)
        for i in range(3):
            for j in range(3):
                G[i, j] = Ti[j, i] * k[e] + G[i, j]
        mm(G, Ti, GT)
        skew_into(g, S)
        for i in range(3):
            for j in range(3):
                S[i, j] = S[i, j] + GT[i, j]
        mm_at(Q, S, H)
        mtv(Q, g, f[e, 3:6])
        for i in range(3):
            f[e, 3 + i] = -f[e, 3 + i]
            f[e, 9 + i] = g[i]
        mm(GT, Q, K[e, 9:12, 3:6])
        mm(H, Q, K[e, 3:6, 3:6])
        for i in range(3):
            for j in range(3):
                K[e, 9 + i, 9 + j] = GT[i, j]
                K[e, 9 + i, 3 + j] = -K[e, 9 + i, 3 + j]
                K[e, 3 + i, 9 + j] = -H[i, j]
        for i in range(3):
            theta[e, i] = th[i]


class JointSprings(ElementFamily):
    """Linear rotational springs between node pairs (a, b): k (N m/rad) per spring.

    Output ``theta`` (n, 3): relative rotation vector log(R_b R_a^T), rad."""

    active_dofs = (3, 4, 5)
    symmetric = False
    path_independent = True

    def __init__(self, nodes, k, name: str = "adam_joint_spring"):
        self.name = name
        self.nodes = np.asarray(nodes, dtype=np.int64).reshape(-1, 2)
        self.k = np.broadcast_to(np.asarray(k, dtype=float), (self.nodes.shape[0],)).copy()

    def evaluate(self, x, R, state, ctx=None):
        n = self.n_elements
        f, K = np.zeros((n, 12)), np.zeros((n, 12, 12))
        th = np.zeros((n, 3))
        _spring_kernel(self.nodes, np.ascontiguousarray(R), self.k, f, K, th)
        energy = 0.5 * self.k * np.einsum("ij,ij->i", th, th)
        return ElementResponse(f=f, k=K, state=state, output={"theta": th}, energy=energy)
