"""The discrete system: DOF numbering, constraint handling, assembly and the linear solver.

:class:`System` is what OpenSees splits into a constraint handler, a DOF numberer and a linear
system of equations: it numbers the DOFs of a model (fixed and prescribed ones last, rigid-body
and tie slaves eliminated by the transformation method), evaluates the element families at the
current configuration, assembles and reduces the residual and the tangent, factorises and solves,
and updates the configuration with a Newton correction.  It knows nothing of steps, increments
or files: the Newton loop (newton.py) drives it; the configuration lives in the :class:`State`
it is given (``system.state``).
"""

from __future__ import annotations

import time as _time

import numpy as np
import scipy.sparse as sp
from numba import njit

from ..elements.base import DOF_NAMES, IncrementContext
from ..elements.beam_corot import BeamFamily
from ..elements.truss import TrussFamily
from ..errors import EquilibriumError, ModelError, NonFiniteError, SingularModelError
from ..model import validation
from ..model.constraints import Constraints, transpose_times
from .assembly import Assembler, assigning_positions
from .configuration import update_configuration
from .convergence import all_finite, evaluate, force_moment_abs_max, scaled_size
from .dofs import number_dofs
from .equilibrium import family_balance
from .linalg.linear import SparseLU, mechanism_dofs
from .reduction import ReducedTangent


@njit(cache=True)
def _reached(x, X0, spin, cons_node, cons_dof, reactions, prescribed, RF):
    """The values reached at the constrained DOFs into ``prescribed`` (displacement x - X0, m, or
    the accumulated spin, rad) and their ``reactions`` into the nodal array ``RF`` (zeros)."""
    for i in range(cons_node.shape[0]):
        n = cons_node[i]
        d = cons_dof[i]
        prescribed[n, d] = x[n, d] - X0[n, d] if d < 3 else spin[n, d - 3]
        RF[n, d] = reactions[i]


@njit(cache=True)
def _abs_sum(a):
    """Sum of |a| over every entry of ``a``."""
    s = 0.0
    for v in a.flat:
        s += abs(v)
    return s


def _shape_message(family, r, f_shape, k_shape) -> str:
    """Why ``family``'s response ``r`` is refused: its f or k does not have the contract's shape."""
    return (
        f"element family '{family.name}' returned f of shape {np.shape(r.f)} and k of shape {np.shape(r.k)}; "
        f"its {f_shape[0]} element(s) of {f_shape[1] // 6} nodes need f {f_shape} and k {k_shape} (6 DOFs per "
        "node, femast/elements/base.py): fix the family's evaluate()"
    )


def _nonfinite_message(family, f, labels) -> str:
    """Which element of ``family`` returned the non-finite forces ``f`` (node ``labels`` by row)."""
    e = int(np.flatnonzero(~np.isfinite(np.asarray(f)).all(axis=1))[0])
    label = int(family.labels[e]) if hasattr(family, "labels") else e + 1
    nodes = ", ".join(str(labels[n]) for n in np.asarray(family.nodes)[e])
    return (
        f"element family '{family.name}' returned NaN or infinite internal forces for element {label} (nodes "
        f"{nodes}); check its parameters, or its evaluate() for a user element, at that configuration"
    )


SHORT = 1e-6  # an element shorter than this fraction of the model's size swamps the tangent's conditioning


def _response_shapes(family):
    """The shapes (f, k) of ``family``'s response: (n_el, 6 m) and (n_el, 6 m, 6 m) for m nodes per element."""
    n_el, m = np.shape(family.nodes)
    return (n_el, 6 * m), (n_el, 6 * m, 6 * m)


def _short_elements(families, X0, size, labels) -> None:
    """A ModelError naming a beam or truss element shorter than :data:`SHORT` of the model's size
    ``size`` (m): its stiffness would exceed the others' by 1e6 (axial) to 1e18 (bending), beyond
    what a factorisation in double precision can tell from a mechanism."""
    for f in families:
        if not isinstance(f, (BeamFamily, TrussFamily)):
            continue
        nodes = np.asarray(f.nodes)
        L = np.linalg.norm(X0[nodes[:, 1]] - X0[nodes[:, 0]], axis=1)
        for e in np.flatnonzero(L < SHORT * size)[:1]:
            raise ModelError(
                f"{type(f).__name__[:-6].lower()} element {int(f.labels[e])} (nodes {labels[nodes[e, 0]]}-"
                f"{labels[nodes[e, 1]]}) of family '{f.name}' is {L[e]:.3g} m long, {L[e] / size:.2g} of the model's "
                f"size {size:.3g} m: its stiffness would swamp the others' in double precision. Merge its nodes (or "
                "tie them with Model.tie or a rigid body), or give it a realistic length"
            )


class System:
    """The numbered, assembled system of ``model`` with element ``families`` (see module docstring).

    summary : the :class:`AnalysisSummary` whose ``assembly_time`` / ``solve_time`` (s) it adds to.
    """

    def __init__(self, model, families, summary, linear_solver: str = "auto"):
        self.model = model
        self.families = families
        self.summary = summary
        self.state = None  # the State whose configuration is updated (set by Analysis)
        self.X0 = model.coordinates
        n = len(self.X0)
        constrained = np.zeros((n, 6), dtype=bool)
        self.fixed = np.zeros((n, 6), dtype=bool)
        for label, dofs in model.fixed.items():
            self.fixed[model.index(label), list(dofs)] = True
        constrained |= self.fixed
        for s in model.steps:
            for c in s.prescribed:
                i = model.index(c.node)
                if self.fixed[i, c.dof]:
                    raise ModelError(
                        f"step '{s.name}': node {c.node} {DOF_NAMES[c.dof]} is both fixed and "
                        "prescribed; remove one of the two"
                    )
                constrained[i, c.dof] = True
        for s in model.steps:
            for c in s.loads:
                if constrained[model.index(c.node), c.dof] and c.magnitude != 0.0:
                    raise ModelError(
                        f"step '{s.name}': node {c.node} {DOF_NAMES[c.dof]} is both loaded and "
                        "fixed/prescribed; a DOF can have a load or a prescribed value, not both"
                    )
        self.constrained = constrained
        self.constraints = Constraints(model, n)
        clash = self.constraints.dependent & constrained
        if clash.any():
            i, d = np.argwhere(clash)[0]
            raise ModelError(
                f"node {model.node_labels[i]} {DOF_NAMES[d]} is dependent in a rigid body or tie and "
                "also fixed or prescribed; fix or drive the reference (master) node instead"
            )
        extra = np.zeros((n, 6), dtype=bool)
        extra[self.constraints.references] = True
        self.dofmap = number_dofs(
            n, self.families, constrained, model.node_labels, extra_active=extra, dependent=self.constraints.dependent
        )
        if self.dofmap.n_free == 0:
            raise ModelError(f"model '{model.name}' has no free DOFs")
        validation.loads_on_active_dofs(model, self.dofmap)  # a load nothing stiffens: an error
        self.check_balance = validation.self_equilibrated(self.families)
        self._constrained = self.constraints.active  # fixed from here on (asked every iteration)
        self.assembler = Assembler(self.dofmap, self.families, full=self._constrained)
        self.constraints.setup(self.dofmap, self.X0)
        nf, ni = self.dofmap.n_free, self.dofmap.n_independent
        self.n_free = nf
        self.free_node, self.free_dof = self.dofmap.slots(np.arange(nf))
        self.cons_node, self.cons_dof = self.dofmap.slots(np.arange(nf, ni))
        self._labels = model.node_labels
        self.act_node, self.act_dof = self.dofmap.slots(np.arange(self.dofmap.n_active))
        self.is_rot = self.free_dof >= 3
        self._W = np.zeros((n, 3))  # scratch spins of the configuration update
        self._no_update = np.zeros(0)
        self._Pa = None  # (loads array, its values on the active DOFs)
        self.length = float(np.ptp(self.X0, axis=0).max()) or 1.0
        self._shapes = [_response_shapes(f) for f in families]  # (f, k) of each family's response
        _short_elements(families, self.X0, self.length, model.node_labels)
        self.symmetric = all(getattr(f, "symmetric", False) for f in self.families)
        self.solver = SparseLU(symmetric=self.symmetric, backend=linear_solver)
        if not self._constrained:
            # symbolic analysis (the ordering) from the assembly pattern, once, at set-up; a
            # constrained model's reduced pattern T^T K T is only known at its first iteration
            self.solver.analyse(self.assembler.K_ff)
        self._direct = None  # (solver layout, positions): K_ff assembled into the solver's matrix
        # constrained models: T^T K T + G on a pattern computed once (femast/analysis/reduction.py)
        self._reduced = (
            ReducedTangent(
                self.assembler.K_aa,
                self.constraints.transformation(self.X0),
                *self.constraints.geometric_entries(),
                self.dofmap.n_free,
            )
            if self._constrained
            else None
        )
        self.last_converged = None  # (version, responses) of the last committed increment
        self._diag_cache = None  # (K's indptr, indices, K + diag buffer, diagonal positions)
        self.zero_force = None

    # ------------------------------------------------------------ evaluation
    def dof_value(self, idx, dof):
        """Displacement (m) or accumulated rotation (rad) of DOF ``dof`` of node index ``idx``."""
        st = self.state
        return st.x[idx, dof] - self.X0[idx, dof] if dof < 3 else st.spin[idx, dof - 3]

    def evaluate(self, ctx, reuse=False):
        """Element responses at the current configuration.  With ``reuse``, a path-independent
        family whose converged response belongs to this very configuration (nothing has moved
        since the last commit) is not evaluated again; families with history always are, since
        their response at the start of an increment (trial state = committed state) differs from
        the converged one (e.g. an elastic instead of an elastoplastic tangent)."""
        st = self.state
        last = self.last_converged
        cached = last[1] if reuse and last is not None and last[0] == st.version else None
        responses = []
        x, R = st.x, st.R
        for i, (f, s) in enumerate(zip(self.families, st.families)):
            if cached is not None and f.path_independent:
                responses.append(cached[i])
                continue
            r = f.evaluate(x, R, s, ctx)
            if np.shape(r.f) != self._shapes[i][0] or np.shape(r.k) != self._shapes[i][1]:
                raise ModelError(_shape_message(f, r, *self._shapes[i]))
            if not all_finite(r.f):  # (compiled: numpy's isfinite + all cost ~2 us a call)
                raise NonFiniteError(_nonfinite_message(f, r.f, self._labels))
            responses.append(r)
        return responses

    def nonfinite_tangent(self, responses):
        """Why a factorisation or solve failed, if an element tangent holds a NaN or inf (tested
        only then: a scan of every element matrix costs as much as assembling them)."""
        for f, r in zip(self.families, responses or ()):
            if not np.all(np.isfinite(r.k)):
                return f"non-finite tangent stiffness in element family '{f.name}'"
        return None

    def bad_tangent(self, exc, responses):
        """The named non-finite element tangent behind a failed factorisation or solve, or None."""
        return self.nonfinite_tangent(responses) if isinstance(exc, SingularModelError) else None

    def residual(self, responses, P):
        """Residual P - F on the independent DOFs (free first, then constrained)."""
        F = self.assembler.forces([q.f for q in responses])
        if self._Pa is None or self._Pa[0] is not P:  # the loads are fixed within an increment
            self._Pa = (P, P[self.act_node, self.act_dof])
        self._net = F - self._Pa[1]
        if not self._constrained:
            return -self._net
        self._T = self.constraints.transformation(self.state.x)
        return -transpose_times(self._T, self._net)

    def reduce_load(self, P):
        """A nodal load array (n, 6) as a vector on the free DOFs (through the constraints)."""
        Pa = P[self.act_node, self.act_dof]
        if self._constrained:
            Pa = transpose_times(self._T, Pa)
        return Pa[: self.dofmap.n_free]

    # ------------------------------------------------------------ tangent and solve
    def factorize_tangent(self, responses, with_fc):
        """Assemble and factorise K_ff; returns (K_ff or None, K_fc or None).

        An unconstrained model's element matrices go straight into the linear solver's permuted
        matrix (positions composed once: no CSR fill and no gather per iteration), and K_ff is
        then not formed (None); the first tangent's diagonal, which sets the zero-force floors, is
        summed from the element matrices.  Constrained models go through :meth:`tangent`."""
        if self._constrained or self.solver.chosen is None:
            return self.factorize_csr(responses, with_fc)
        if self._direct is None or self._direct[0] != self.solver.layout:
            # a stabilised step may have widened the solver's pattern (a diagonal entry K_ff lacks):
            # the direct path needs the solver's pattern to be K_ff's own
            same = self.solver.has_pattern(self.assembler.K_ff)
            positions = [self.solver.permuted_positions(p) for p in self.assembler.pos_ff] if same else None
            if positions is not None:  # the first entry of each position assigns it: no zeroing
                positions = assigning_positions(positions, self.solver.values.size)
            self._direct = (self.solver.layout, positions)
        if self._direct[1] is None:
            return self.factorize_csr(responses, with_fc)
        ta = _time.perf_counter()
        k_list = [q.k for q in responses]
        if self.zero_force is None:
            self._set_floors(self.assembler.diagonal(k_list))
        Kfc = self.assembler.coupling(k_list) if with_fc else None
        self.assembler.tangent_into(k_list, self.solver.values, self._direct[1], assigning=True)
        self.summary.assembly_time += _time.perf_counter() - ta
        ts = _time.perf_counter()
        self.solver.factorize_values()
        self.summary.solve_time += _time.perf_counter() - ts
        return None, Kfc

    def factorize_csr(self, responses, with_fc, adjust=None):
        """Assemble K_ff as a CSR matrix (passed through ``adjust`` if given, e.g. to add damping)
        and factorise it; returns (K_ff, K_fc or None)."""
        ta = _time.perf_counter()
        K, Kfc = self.tangent(responses, with_fc)
        if adjust is not None:
            K = adjust(K)
        self.summary.assembly_time += _time.perf_counter() - ta
        ts = _time.perf_counter()
        self.solver.factorize(K)
        self.summary.solve_time += _time.perf_counter() - ts
        return K, Kfc

    def tangent(self, responses, with_fc):
        """(K_ff, K_fc) at the configuration of the last :meth:`residual` call."""
        k_list = [q.k for q in responses]
        if not self._constrained:
            K, Kfc = self.assembler.tangent(k_list, with_fc=with_fc)
        else:
            K_aa = self.assembler.full_tangent(k_list)
            K, Kfc = self._reduced.fill(
                K_aa.data, self._T.data, self.constraints.geometric_values(self.state.x, self._net)
            )
            Kfc = Kfc if with_fc else None
        if self.zero_force is None:
            self._set_floors(K.diagonal())
        return K, Kfc

    def _set_floors(self, diagonal):
        """The 'zero flux' floors from the first tangent's diagonal: forces of a 1e-6 L (1e-6 rad)
        motion of a typical DOF (the median stiffness, so that penalty ties do not inflate it)."""
        dk = np.abs(diagonal)
        kt, kr = (float(np.median(v[v > 0])) if np.any(v > 0) else 0.0 for v in (dk[~self.is_rot], dk[self.is_rot]))
        self.zero_force = 1e-6 * max(kt * self.length, kr / self.length)

    def plus_diagonal(self, K, c):
        """K + diag(c) on K's own pattern, explicit zeros kept (the viscous term of a stabilised step).

        scipy's sum drops entries that are zero, and early in a stabilised step many are (latches
        and joints not loaded yet): each new nonzero then changed the pattern, and the solver
        analysed a new ordering, three or four times per run of an ADAM model.  On K's pattern the
        stabilised and the later steps share one ordering.  The result is one matrix refilled in
        place; a K without its whole diagonal falls back to scipy's sum."""
        cache = self._diag_cache
        if cache is None or cache[0] is not K.indptr or cache[1] is not K.indices:
            n = K.shape[0]
            rows = np.repeat(np.arange(n), np.diff(K.indptr))
            d = np.flatnonzero(K.indices == rows)
            if K.has_canonical_format and d.size == n:  # one diagonal entry per row
                out = sp.csr_matrix((K.data.copy(), K.indices, K.indptr), shape=K.shape)
            else:
                out = d = None
            cache = self._diag_cache = (K.indptr, K.indices, out, d)
        out, d = cache[2], cache[3]
        if out is None:
            return (K + sp.diags(c)).tocsr()
        np.copyto(out.data, K.data)
        out.data[d] += c
        return out

    # ------------------------------------------------------------ configuration
    def update(self, du_free, du_cons=None):
        """Add a correction of the free DOFs (and, optionally, of the constrained ones) to the
        configuration of ``state``; dependent (slave) DOFs follow their constraints."""
        st = self.state
        st.version += 1
        update_configuration(
            st.x,
            st.spin,
            st.R,
            self._W,
            self.free_node,
            self.free_dof,
            np.ascontiguousarray(du_free, dtype=float),
            self.cons_node,
            self.cons_dof,
            self._no_update if du_cons is None else np.ascontiguousarray(du_cons, dtype=float),
        )
        if self._constrained:
            self.constraints.update_slaves(st.x, st.R, st.spin)

    def converged(self, convergence, r, du, Du, responses, P, iteration=0):
        """Force/moment residual against the largest element nodal force/moment or applied load
        (Abaqus' 'flux' magnitude), displacement correction against the increment:
        (converged, residual ratio, force test passed, scaled correction), as the convergence test
        answers them (:func:`~femast.analysis.convergence.evaluate`)."""
        fmax, mmax = force_moment_abs_max(P)
        for resp in responses:
            ff, mm = force_moment_abs_max(resp.f)
            fmax = max(fmax, ff)
            mmax = max(mmax, mm)
        L = self.length
        ref_f = max(fmax, 1e-2 * mmax / L, self.zero_force)
        ref_m = max(mmax, 1e-2 * fmax * L, self.zero_force * L)
        return evaluate(convergence, r, du, Du, self.is_rot, ref_f, ref_m, L, iteration)

    def scaled_size(self, v, Du):
        """The correction test's measure of a correction ``v`` given the increment so far ``Du``
        (:func:`~femast.analysis.convergence.scaled_size`)."""
        return scaled_size(v, Du, self.is_rot, self.length)

    def commit(self, responses, P, res, lam, equilibrium=True):
        """Commit a converged increment into the state (one call: see :meth:`State.commit`)."""
        st = self.state
        self.last_converged = (st.version, responses)
        reactions = -res[self.dofmap.n_free :]
        RF = np.zeros(P.shape)
        # the values reached (displacements x - X0, rotations the accumulated spins) and the reactions
        _reached(st.x, self.X0, st.spin, self.cons_node, self.cons_dof, reactions, st.prescribed, RF)
        st.commit(
            [r.state for r in responses],
            P,
            lam,
            reactions,
            float(sum(np.sum(r.energy) for r in responses if r.energy is not None)),
            equilibrium,
        )
        if equilibrium and self.check_balance:  # the reactions balance the loads (every increment)
            where = f"increment {self.summary.increments + 1}"
            try:
                validation.check_equilibrium(
                    st.x,
                    P,
                    RF,
                    res[: self.dofmap.n_free],
                    self.free_dof,
                    where,
                    internal=float(sum(_abs_sum(q.f) for q in responses)),
                    labels=self._labels,
                )
            except EquilibriumError:
                family_balance(self, responses, st.x, where)  # names a family that is not in balance
                raise

    # ------------------------------------------------------------ messages
    def worst(self, r):
        """The DOF of the largest residual entry, named."""
        return self.dofmap.describe(int(np.argmax(np.abs(r))))

    def name_dofs(self, eqs):
        return ", ".join(self.dofmap.describe(int(e)) for e in eqs)

    def singular_message(self, K, where):
        eqs = mechanism_dofs(K)
        what = (
            f"the free DOFs of the mechanism include: {self.name_dofs(eqs)}"
            if eqs is not None
            else "the model is too large to name the mechanism"
        )
        return (
            f"{where}: the tangent stiffness is singular: {what}. Fix or constrain these DOFs, or connect "
            "the nodes to an element that stiffens them."
        )

    def committed_context(self):
        """An increment context at the current configuration (taken as committed)."""
        return IncrementContext(x_committed=self.state.x, R_committed=self.state.R)
