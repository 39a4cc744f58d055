"""Helpers for checking elements, for femast's tests and for users writing their own elements."""

from __future__ import annotations

import numpy as np

from .elements.base import IncrementContext
from .rotations import expm_so3


def fd_tangent(family, x, R=None, state=None, h: float = 1e-6, ctx=None, dofs=range(6)):
    """Central finite difference of an element family's internal forces, (n_el, m, m) with
    m = 6 x nodes per element, with respect to nodal translations (m) and spatial spins (rad,
    R <- expm(h e_k) R), the variables of the element contract.  Each element is perturbed on
    its own, so families whose elements share nodes are handled correctly.  Only the node DOFs in
    ``dofs`` are perturbed (e.g. ``range(3)`` for translation-only elements); other columns are 0.
    Compare with ``family.evaluate(x, R, state, ctx).k``."""
    ctx = ctx or IncrementContext()
    R = np.tile(np.eye(3), (len(x), 1, 1)) if R is None else R
    nodes = np.asarray(family.nodes)
    n_el, nn = nodes.shape
    Kfd = np.zeros((n_el, 6 * nn, 6 * nn))
    for e in range(n_el):
        for slot in range(nn):
            a = nodes[e, slot]
            for d in dofs:
                fs = []
                for s in (h, -h):
                    xp, Rp = x.copy(), R.copy()
                    if d < 3:
                        xp[a, d] += s
                    else:
                        w = np.zeros(3)
                        w[d - 3] = s
                        Rp[a] = expm_so3(w) @ R[a]
                    fs.append(family.evaluate(xp, Rp, state, ctx).f[e])
                Kfd[e, :, 6 * slot + d] = (fs[0] - fs[1]) / (2 * h)
    return Kfd
