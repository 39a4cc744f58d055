"""Multi-point constraints: rigid bodies and equal-DOF ties, exact for large rotations.

A *rigid body* ties a set of nodes to a reference node (Abaqus *RIGID BODY, REF NODE):

    x_s = x_r + R_r (X_s - X_r),     R_s = R_r

for every tied node s, whatever the size of the reference rotation R_r.  A *tie* makes chosen DOFs
of a node equal to those of a master node (Abaqus *EQUATION / *TIE with coincident nodes):
translations u_s = u_m, and, if all three rotations are tied, R_s = R_m (tying one or two rotation
components is exact only for rotations about a fixed axis).

The analysis eliminates the dependent DOFs by the transformation method: with T the (exact,
configuration-dependent) map from independent to all variations,

    dx_s = dx_r - [d]x dw_r,   dw_s = dw_r,   d = x_s - x_r,

forces are reduced as T^T f and the tangent as T^T K T + G, where G = sum_s [f_s]x [d_s]x on the
reference rotation block is the derivative of the lever arm (f_s = net force on node s).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numba import njit

from ..errors import ModelError


@njit(cache=True)
def _csr_transpose_matvec(indptr, indices, data, v, out):
    for i in range(indptr.size - 1):
        vi = v[i]
        for k in range(indptr[i], indptr[i + 1]):
            out[indices[k]] += data[k] * vi


@njit(cache=True)
def _update_slaves(x, R, spin, rigid, X_rel, X0, tie_trans, tie_rot, tie_full):
    """Rigid slaves x_s = x_r + R_r X_rel, R_s = R_r, spin_s = spin_r; then ties (translations
    u_s = u_m, rotation components spin_s = spin_m, R_s = R_m where all three are tied)."""
    for k in range(rigid.shape[0]):
        s = rigid[k, 0]
        r = rigid[k, 1]
        for i in range(3):
            x[s, i] = x[r, i] + (R[r, i, 0] * X_rel[k, 0] + R[r, i, 1] * X_rel[k, 1] + R[r, i, 2] * X_rel[k, 2])
            spin[s, i] = spin[r, i]
            for j in range(3):
                R[s, i, j] = R[r, i, j]
    for k in range(tie_trans.shape[0]):
        s, m, d = tie_trans[k, 0], tie_trans[k, 1], tie_trans[k, 2]
        x[s, d] = X0[s, d] + (x[m, d] - X0[m, d])
    for k in range(tie_rot.shape[0]):
        s, m, d = tie_rot[k, 0], tie_rot[k, 1], tie_rot[k, 2]
        spin[s, d - 3] = spin[m, d - 3]
    for k in range(tie_full.shape[0]):
        s, m = tie_full[k, 0], tie_full[k, 1]
        for i in range(3):
            for j in range(3):
                R[s, i, j] = R[m, i, j]


@njit(cache=True)
def _geometric_values(x, rigid, trans_eq, f_net, out):
    """Per rigid slave, the 9 values (row-major) of d f^T - (f . d) I, d = x_s - x_r, f the net
    force on the slave's translations (0 on a DOF without an equation)."""
    d = np.empty(3)
    f = np.empty(3)
    for k in range(rigid.shape[0]):
        s = rigid[k, 0]
        r = rigid[k, 1]
        for i in range(3):
            d[i] = x[s, i] - x[r, i]
            q = trans_eq[k, i]
            f[i] = f_net[q] if q >= 0 else 0.0
        fd = (f[0] * d[0] + f[2] * d[2]) + f[1] * d[1]  # numpy einsum's order: the same bits as before
        for i in range(3):
            for j in range(3):
                out[9 * k + 3 * i + j] = d[i] * f[j] - (fd if i == j else 0.0)


def transpose_times(T, v):
    """T^T v for a CSR matrix T, without forming T^T (scipy builds and checks a new matrix for
    ``T.T`` on every call: 8 % of a small constrained model's run).  Same order of
    summation as scipy's T.T @ v, so the same bits."""
    out = np.zeros(T.shape[1])
    _csr_transpose_matvec(T.indptr, T.indices, T.data, np.ascontiguousarray(v, dtype=float), out)
    return out


@dataclass
class RigidBodySpec:
    name: str
    reference: int
    nodes: tuple


@dataclass
class TieSpec:
    master: int
    slave: int
    dofs: tuple


def rigid_body_spec(model, reference, nodes, name: str) -> RigidBodySpec:
    """The :class:`RigidBodySpec` of :meth:`Model.rigid_body <femast.model.Model.rigid_body>`
    after checking its nodes (known, at least one besides the reference, none twice, not the
    reference itself)."""
    model._check_node(reference, f"rigid body '{name}'")
    nodes = [n for n in np.atleast_1d(nodes).tolist()]
    for n in nodes:
        model._check_node(n, f"rigid body '{name}'")
    others = [n for n in nodes if int(n) != int(reference)]
    if len(others) < 1:
        raise ModelError(
            f"rigid body '{name}': needs the reference node and at least one other node "
            f"(got {len(others) + 1} node in all); a rigid body with fewer than two nodes ties nothing"
        )
    if len(others) != len(nodes):
        raise ModelError(
            f"rigid body '{name}': node {int(reference)} is its reference node and also listed among the nodes it "
            "carries; list only the other nodes (the reference moves them)"
        )
    if len(set(int(n) for n in others)) != len(others):
        raise ModelError(f"rigid body '{name}': a node is listed twice")
    return RigidBodySpec(name, int(reference), tuple(int(n) for n in others))


def tie_spec(model, master, slave, dofs) -> TieSpec:
    """The :class:`TieSpec` of :meth:`Model.tie <femast.model.Model.tie>` after checking it
    (default DOFs: the three translations; "all": the six)."""
    from .specs import dof_index

    model._check_node(master, "tie")
    model._check_node(slave, "tie")
    if int(master) == int(slave):
        raise ModelError(f"tie: node {master} tied to itself")
    if not dofs:
        idx = (0, 1, 2)
    elif dofs == ("all",):
        idx = tuple(range(6))
    else:
        idx = tuple(dof_index(d) for d in dofs)
    return TieSpec(int(master), int(slave), idx)


def _skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


class Constraints:
    """Dependent DOFs of a model and the transformation to the independent ones."""

    def __init__(self, model, n_nodes):
        self.n = n_nodes
        self.dependent = np.zeros((n_nodes, 6), dtype=bool)
        self.rigid_slave = []  # (slave index, reference index)
        self.tie = []  # (slave index, master index, dof)
        owner = {}
        for rb in model.rigid_bodies:
            r = model.index(rb.reference)
            for lab in rb.nodes:
                s = model.index(lab)
                if s == r:
                    continue
                if s in owner:
                    raise ModelError(
                        f"node {lab} is in two constraints ({owner[s]} and rigid body '{rb.name}'); "
                        "a node can belong to one rigid body or tie only"
                    )
                owner[s] = f"rigid body '{rb.name}'"
                self.rigid_slave.append((s, r))
                self.dependent[s, :] = True
        for t in model.ties:
            s, m = model.index(t.slave), model.index(t.master)
            if s in owner:
                raise ModelError(
                    f"node {t.slave} is in two constraints ({owner[s]} and a tie to node {t.master}); "
                    "a node can belong to one rigid body or tie only"
                )
            owner[s] = f"tie to node {t.master}"
            for d in t.dofs:
                self.tie.append((s, m, d))
                self.dependent[s, d] = True
        masters = {r for _, r in self.rigid_slave} | {m for _, m, _ in self.tie}
        for node in masters:
            if node in owner:
                lab = model.node_labels[node]
                raise ModelError(
                    f"node {lab} is the reference/master of one constraint and dependent in another "
                    f"({owner[node]}); chains of constraints are not supported: tie it to the same "
                    "reference node instead"
                )
        self.rigid_slave = np.array(self.rigid_slave, dtype=np.int64).reshape(-1, 2)
        self.tie = np.array(self.tie, dtype=np.int64).reshape(-1, 3)
        self.references = np.unique(self.rigid_slave[:, 1]) if len(self.rigid_slave) else np.zeros(0, np.int64)
        self.X_rel = None

    @property
    def active(self) -> bool:
        return bool(self.dependent.any())

    def setup(self, dofmap, X0):
        """Fix the sparsity of T once; each iteration only refills the lever-arm values."""
        self.eq = dofmap.eq
        self.n_ind = dofmap.n_free + dofmap.n_constrained
        self.n_active = dofmap.n_active
        s, r = self.rigid_slave[:, 0], self.rigid_slave[:, 1]
        self.X0 = np.ascontiguousarray(X0, dtype=float)
        self.X_rel = self.X0[s] - self.X0[r]
        # the ties split for the compiled slave update: translations, rotation components, and the
        # (slave, master) pairs with all three rotations tied (R_s = R_m)
        t = self.tie
        pairs = {}
        for sl, m, d in t[t[:, 2] >= 3]:
            pairs.setdefault((int(sl), int(m)), set()).add(int(d))
        full = np.array([p for p, ds in pairs.items() if len(ds) == 3], dtype=np.int64).reshape(-1, 2)
        self._tie_split = (np.ascontiguousarray(t[t[:, 2] < 3]), np.ascontiguousarray(t[t[:, 2] >= 3]), full)
        eq = self.eq
        if len(s) and np.any(eq[r][:, 3:] < 0):
            raise ModelError("a rigid-body reference node has no rotational DOFs")
        rows, cols, vals = [], [], []
        flat = eq.ravel()
        ind = flat[(flat >= 0) & (flat < self.n_ind)]
        rows.append(ind), cols.append(ind), vals.append(np.ones(ind.size))
        # rigid slaves: dx_s = dx_r - [d]x dw_r, dw_s = dw_r
        for i in range(6):
            es = eq[s, i]
            ok = es >= 0
            rows.append(es[ok]), cols.append(eq[r[ok], i]), vals.append(np.ones(ok.sum()))
        lever_rows, lever_cols, lever_k, lever_c, lever_sign = [], [], [], [], []
        # -[d]x entries (i, j): (0,1) d2, (0,2) -d1, (1,0) -d2, (1,2) d0, (2,0) d1, (2,1) -d0
        for i, j, c, sign in (
            (0, 1, 2, 1.0),
            (0, 2, 1, -1.0),
            (1, 0, 2, -1.0),
            (1, 2, 0, 1.0),
            (2, 0, 1, 1.0),
            (2, 1, 0, -1.0),
        ):
            es = eq[s, i]
            ok = np.flatnonzero(es >= 0)
            lever_rows.append(es[ok]), lever_cols.append(eq[r[ok], 3 + j])
            lever_k.append(ok), lever_c.append(np.full(ok.size, c)), lever_sign.append(np.full(ok.size, sign))
        for sl, m, d in self.tie:
            es, em = eq[sl, d], eq[m, d]
            if es >= 0:
                if em < 0:
                    raise ModelError(f"tie: master node {m} has no active DOF {d} to tie to")
                rows.append([es]), cols.append([em]), vals.append([1.0])
        fixed_rows = np.concatenate(rows).astype(np.int64)
        fixed_cols = np.concatenate(cols).astype(np.int64)
        self._fixed_vals = np.concatenate(vals)
        self._lever_k = np.concatenate(lever_k).astype(np.int64) if lever_k else np.zeros(0, np.int64)
        self._lever_c = np.concatenate(lever_c).astype(np.int64) if lever_c else np.zeros(0, np.int64)
        self._lever_sign = np.concatenate(lever_sign) if lever_sign else np.zeros(0)
        all_rows = np.concatenate([fixed_rows] + lever_rows)
        all_cols = np.concatenate([fixed_cols] + lever_cols)
        n_entries = all_rows.size
        T = sp.coo_matrix(
            (np.arange(1, n_entries + 1, dtype=float), (all_rows, all_cols)), shape=(self.n_active, self.n_ind)
        ).tocsr()
        self._T = T
        self._T_pos = np.empty(n_entries, dtype=np.int64)
        self._T_pos[T.data.astype(np.int64) - 1] = np.arange(T.nnz)  # entry -> position in T.data
        self._n_fixed = fixed_rows.size
        # geometric term: 9 entries per rigid slave on its reference's rotation block
        if len(s):
            er = eq[r][:, 3:6]
            self._G_rows = np.repeat(er, 3, axis=1).ravel()
            self._G_cols = np.tile(er, (1, 3)).ravel()
            self._slave_trans_eq = np.ascontiguousarray(eq[s][:, :3], dtype=np.int64)

    def update_slaves(self, x, R, spin):
        """Put every dependent node where its constraint says (exact for any rotation): one
        compiled pass (numpy's fancy indexing on a dozen 3-vectors cost ~4 % of a bay run)."""
        _update_slaves(x, R, spin, self.rigid_slave, self.X_rel, self.X0, *self._tie_split)

    def transformation(self, x):
        """T (n_active x n_ind): variations of all active DOFs from the independent ones."""
        vals = np.empty(self._T_pos.size)
        vals[: self._n_fixed] = self._fixed_vals
        if self._lever_k.size:
            s, r = self.rigid_slave[:, 0], self.rigid_slave[:, 1]
            d = x[s] - x[r]
            vals[self._n_fixed :] = self._lever_sign * d[self._lever_k, self._lever_c]
        self._T.data[self._T_pos] = vals
        return self._T

    def geometric_entries(self):
        """(rows, cols) in independent numbering of the entries :meth:`geometric_values` fills."""
        if not len(self.rigid_slave):
            return np.zeros(0, np.int64), np.zeros(0, np.int64)
        return self._G_rows, self._G_cols

    def geometric_values(self, x, f_net):
        """Values of G at :meth:`geometric_entries`: per rigid slave, d f^T - (f.d) I (3x3, row-major)."""
        if not len(self.rigid_slave):
            return np.zeros(0)
        out = np.empty(9 * len(self.rigid_slave))
        _geometric_values(x, self.rigid_slave, self._slave_trans_eq, np.ascontiguousarray(f_net, dtype=float), out)
        return out
