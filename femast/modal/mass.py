"""Mass matrices of the modal analysis, assembled on the analysis' own DOF numbering and reduced
through its constraints.  The mass model itself (element matrices, point masses, rigid bodies) is
:mod:`femast.model.mass`; its names are re-exported here.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..analysis.assembly import Assembler
from ..errors import ModelError
from ..model.mass import (  # noqa: F401  (re-exported: the mass model's old home)
    PointMassSpec,
    beam_mass_kernel,
    chain_lumped_mass_kernel,
    family_mass_blocks,
    point_mass_spec,
    truss_mass_kernel,
)


def check_point_masses(model, dofmap):
    """A point mass whose node has no active translation (no element, no rigid body) is lost:
    ModelError naming it."""
    pms = [p for p in getattr(model, "point_masses", []) if p.mass > 0]
    if not pms:
        return
    rows = np.array([model.index(p.node) for p in pms])
    lost = np.flatnonzero(np.all(dofmap.eq[rows, :3] < 0, axis=1))
    if lost.size:
        p = pms[int(lost[0])]
        raise ModelError(
            f"{p.name or 'point mass'} at node {p.node}: the node has no element or rigid body, "
            "so its mass moves with nothing; put the mass on a node of the structure (or a "
            "rigid body's reference node)"
        )


def assemble_mass(analysis):
    """Mass on the analysis' free DOFs (scipy CSR, n_free x n_free) at its current configuration,
    through its constraints (T^T M T for rigid bodies and ties); and M over all active DOFs."""
    dm = analysis.dofmap
    check_point_masses(analysis.model, dm)
    blocks = family_mass_blocks(analysis.model, analysis.families, analysis.x, analysis.R, analysis.X0)
    na, nf = dm.n_active, dm.n_free
    if not blocks:
        return sp.csr_matrix((nf, nf)), sp.csr_matrix((na, na))
    # the pattern depends on the blocks' node rows only: kept on the analysis for the next call (the
    # modes of every increment of a run)
    key = (id(dm), tuple((b.name, b.nodes.shape) for b in blocks))
    cached = getattr(analysis, "_mass_assembler", None)
    if cached is None or cached[0] != key:
        cached = (key, Assembler(dm, blocks, full=True))
        try:
            analysis._mass_assembler = cached
        except AttributeError:  # an analysis object that takes no new attributes: no cache
            pass
    M_aa = cached[1].full_tangent([b.matrices for b in blocks]).copy()
    if analysis.constraints.active:
        T = analysis.constraints.transformation(analysis.x).copy()
        M_ind = (T.T @ M_aa @ T).tocsr()
    else:
        M_ind = M_aa
    return M_ind[:nf, :nf].tocsr(), M_aa


def total_mass(analysis) -> float:
    """Translational mass of the model, kg (trace of the x-translation block of M over all active
    DOFs, slaves of rigid bodies included): a check against the sum of the parts."""
    _, M_aa = assemble_mass(analysis)
    dm = analysis.dofmap
    node, dof = dm.slots(np.arange(dm.n_active))
    ux = np.flatnonzero(dof == 0)
    return float(M_aa[ux][:, ux].sum())
