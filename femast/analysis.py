"""The static analysis: numbering, assembly, steps, increments, Newton, commit/rollback.

``Analysis(model, out).run()`` walks the model's steps.  For each increment a control
strategy sets the load level, Newton iterates (with the exact tangent), and when the
increment converges the element states are committed and a frame is written to the
results folder at once.  A diverging increment is retried with a quarter of the
increment (Abaqus' cutback); easy increments grow by 1.5.  If the increment falls
below the minimum, the run stops with :class:`~femast.errors.ConvergenceError`
saying where and why; every converged increment is already on disk.
"""

from __future__ import annotations

import copy
import math
import warnings
import time as _time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from tqdm.auto import tqdm

from .assembly import Assembler
from .configuration import update_configuration
from .constraints import Constraints, transpose_times
from .dofs import number_dofs
from .elements.base import DOF_NAMES, IncrementContext
from .elements.beam_corot import BeamFamily, element_frame
from .elements.truss import TrussFamily
from .reduction import ReducedTangent
from .errors import ConvergenceError, ModelError, SingularModelError
from .results import NullWriter, Results, ResultsWriter, run_outcome
from .rotations import rotation_vectors
from . import validation
from .solvers.control import LoadControl
from .solvers.convergence import Convergence, force_moment_abs_max
from .solvers.linear import SparseLU, mechanism_dofs


class StabilizationWarning(UserWarning):
    """The stabilisation energy of a step exceeds its warning ratio of the strain energy."""


@dataclass
class AnalysisSummary:
    """What a run did: counts, wall time and where it stopped."""

    completed: bool = False      # True only once every step has run (status "completed")
    status: str = "running"      # "running", then "completed", "failed" or "interrupted"
    increments: int = 0
    iterations: int = 0
    cutbacks: int = 0
    line_searches: int = 0
    wall_time: float = 0.0
    # wall time in the steps' increments (s): the run without its results-folder set-up, initial
    # frame, final drain of the writer and summary (per-run costs, not per-iteration ones)
    increment_time: float = 0.0
    assembly_time: float = 0.0
    solve_time: float = 0.0
    message: str = ""
    steps: list = field(default_factory=list)

    def __str__(self):
        state = {"completed": "completed", "interrupted": "INTERRUPTED"}.get(self.status, "FAILED")
        return (f"femast: analysis {state}: {self.increments} increments, {self.iterations} Newton iterations, "
                f"{self.cutbacks} cutbacks, wall time {self.wall_time:.2f} s "
                f"(assembly {self.assembly_time:.2f} s, linear solve {self.solve_time:.2f} s)"
                + (f"\n  {self.message}" if self.message else ""))


def build_families(model):
    """Element families (with node *indices*) from a model's beams, trusses and user families."""
    X = model.coordinates
    fams = []
    groups = {}
    for b in model.beams:
        groups.setdefault(("beam", b.family), []).append(b)
    for t in model.trusses:
        groups.setdefault(("truss", t.family), []).append(t)
    for (kind, name), specs in groups.items():
        nodes = np.array([[model.index(n) for n in s.nodes] for s in specs], dtype=np.int64)
        labels = np.array([s.label for s in specs])
        lengths = np.linalg.norm(X[nodes[:, 1]] - X[nodes[:, 0]], axis=1)
        if kind == "beam":
            E0 = np.empty((len(specs), 3, 3))
            for i, s in enumerate(specs):
                frame = element_frame(X[nodes[i, 0]], X[nodes[i, 1]], s.up)
                if frame is None:
                    raise ModelError(f"beam element {s.label}: up-vector parallel to the element")
                E0[i] = frame
            sec = [s.section for s in specs]
            fams.append(BeamFamily(nodes, E0, lengths, [c.E * c.A for c in sec], [c.G * c.J for c in sec],
                                   [c.E * c.Iy for c in sec], [c.E * c.Iz for c in sec], labels=labels, name=name))
        else:
            L0 = np.empty(len(specs))
            for i, s in enumerate(specs):
                if s.L0 is not None:
                    L0[i] = s.L0
                elif s.pretension is not None:
                    L0[i] = lengths[i] / (1.0 + s.pretension / s.EA)
                else:
                    L0[i] = lengths[i]
            fams.append(TrussFamily(nodes, L0, [s.EA for s in specs], [s.tension_only for s in specs],
                                    labels=labels, name=name))
    for fam in model.families:
        f = copy.copy(fam)
        f.nodes = np.ascontiguousarray(np.vectorize(model.index)(np.asarray(fam.nodes)), dtype=np.int64)
        fams.append(f)
    names = [f.name for f in fams]
    for n in set(names):
        if names.count(n) > 1:
            raise ModelError(f"two element families are named '{n}'; give them different names")
    return fams


class Analysis:
    """A static, geometrically nonlinear analysis of ``model`` writing to folder ``out``.

    out : the results folder, or None to write nothing (no folder, frames or status file): each
        frame then only goes to ``on_frame``, and :meth:`run` returns None.  For scripts and fits
        that keep what they need in memory (an FE experiment's many short runs).

    convergence : :class:`~femast.solvers.convergence.Convergence` (tolerances, max iterations).
    progress : show a tqdm progress bar per step.
    cutback : factor applied to a failed increment (Abaqus: 0.25).
    growth : factor applied after two easy increments (Abaqus: 1.5).
    line_search : secant line search when a Newton step overshoots (load control): True, False, or
        "auto" (default): only when retrying an increment that failed, where plain Newton
        already went astray (a line search slows the easy increments down).
    extrapolate : start each increment from the previous increment's solution scaled to the new
        increment (Abaqus' default linear extrapolation); off after a step change.
    easy_iterations : an increment converged in at most this many iterations is easy (Abaqus'
        I_G = 4 with looser tolerances; 6 with femast's tighter defaults).
    on_frame : a recorder, called with each frame's dict (the arrays written to
        ``frames/NNNNNN.npz``; the first call is the initial state) as soon as its increment has
        converged.  A script that needs a few quantities keeps them in memory this way instead of
        reading the results folder back (which costs about as much as the analysis of a small
        model).  Do not modify the arrays: the same ones are being written to disk.
    """

    def __init__(self, model, out="results", convergence: Convergence | None = None, progress: bool = True,
                 cutback: float = 0.25, growth: float = 1.5, easy_iterations: int = 6, line_search="auto",
                 extrapolate: bool = False, on_frame=None):
        self.model = model
        self.on_frame = on_frame
        self.out = out
        if out is None and on_frame is None:
            warnings.warn("Analysis(out=None) without on_frame keeps no results: only the final state "
                          "(Analysis.x, .R, .summary) remains", stacklevel=2)
        self.convergence = convergence or Convergence()
        self.progress = progress
        self.cutback = cutback
        self.growth = growth
        self.easy_iterations = easy_iterations
        self.line_search = line_search
        self.extrapolate = extrapolate
        self._last_Du = None
        if not model.steps:
            raise ModelError(f"model '{model.name}' has no steps; add one with model.step()")
        if not (model.beams or model.trusses or model.families):
            raise ModelError(f"model '{model.name}' has no elements")
        for s in model.steps:   # (again: a step's fields may have been set after model.step())
            validation.step_increments(s)
        self.X0 = model.coordinates
        n = len(self.X0)
        self.families = build_families(model)
        constrained = np.zeros((n, 6), dtype=bool)
        self.fixed = np.zeros((n, 6), dtype=bool)
        for label, dofs in model.fixed.items():
            self.fixed[model.index(label), list(dofs)] = True
        constrained |= self.fixed
        for s in model.steps:
            for c in s.prescribed:
                i = model.index(c.node)
                if self.fixed[i, c.dof]:
                    raise ModelError(f"step '{s.name}': node {c.node} {DOF_NAMES[c.dof]} is both fixed and "
                                     "prescribed; remove one of the two")
                constrained[i, c.dof] = True
        for s in model.steps:
            for c in s.loads:
                if constrained[model.index(c.node), c.dof] and c.magnitude != 0.0:
                    raise ModelError(f"step '{s.name}': node {c.node} {DOF_NAMES[c.dof]} is both loaded and "
                                     "fixed/prescribed; a DOF can have a load or a prescribed value, not both")
        self.constrained = constrained
        self.constraints = Constraints(model, n)
        clash = self.constraints.dependent & constrained
        if clash.any():
            i, d = np.argwhere(clash)[0]
            raise ModelError(f"node {model.node_labels[i]} {DOF_NAMES[d]} is dependent in a rigid body or tie and "
                             "also fixed or prescribed; fix or drive the reference (master) node instead")
        extra = np.zeros((n, 6), dtype=bool)
        extra[self.constraints.references] = True
        self.dofmap = number_dofs(n, self.families, constrained, model.node_labels, extra_active=extra,
                                  dependent=self.constraints.dependent)
        if self.dofmap.n_free == 0:
            raise ModelError(f"model '{model.name}' has no free DOFs")
        validation.loads_on_active_dofs(model, self.dofmap)
        self._check_balance = validation.self_equilibrated(self.families)
        self._constrained = self.constraints.active   # fixed from here on (asked every iteration)
        self.assembler = Assembler(self.dofmap, self.families, full=self._constrained)
        self.constraints.setup(self.dofmap, self.X0)
        nf, ni = self.dofmap.n_free, self.dofmap.n_independent
        self.free_node, self.free_dof = self.dofmap.slots(np.arange(nf))
        self.cons_node, self.cons_dof = self.dofmap.slots(np.arange(nf, ni))
        self.act_node, self.act_dof = self.dofmap.slots(np.arange(self.dofmap.n_active))
        self.is_rot = self.free_dof >= 3
        self._W = np.zeros((n, 3))     # scratch spins of the configuration update
        self._no_update = np.zeros(0)
        self._Pa = None                # (loads array, its values on the active DOFs)
        self.length = float(np.ptp(self.X0, axis=0).max()) or 1.0
        self.symmetric = all(getattr(f, "symmetric", False) for f in self.families)
        self.solver = SparseLU(symmetric=self.symmetric)
        if not self._constrained:
            # symbolic analysis (the ordering) from the assembly pattern, once, at set-up; a
            # constrained model's reduced pattern T^T K T is only known at its first iteration
            self.solver.analyse(self.assembler.K_ff)
        self._direct = None   # (solver layout, positions): K_ff assembled into the solver's matrix
        # constrained models: T^T K T + G on a pattern computed once (femast/reduction.py)
        self._reduced = (ReducedTangent(self.assembler.K_aa, self.constraints.transformation(self.X0),
                                        *self.constraints.geometric_entries(), self.dofmap.n_free)
                         if self._constrained else None)
        # configuration and committed state
        self.x = self.X0.copy()
        self.R = np.tile(np.eye(3), (n, 1, 1))
        self.spin = np.zeros((n, 3))
        self.states = [f.initial_state() for f in self.families]
        self.loads = np.zeros((n, 6))        # applied at the last converged increment
        self.prescribed = np.zeros((n, 6))   # prescribed values at the last converged increment
        self.total_time = 0.0
        self.lam = 0.0
        self.summary = AnalysisSummary()
        self.strain_energy = 0.0
        self._stab_energy = 0.0
        self._stab_force = (0.0, 0.0)
        self._at_equilibrium = False   # the initial state may hold unbalanced pretension
        self._version = 0              # configuration counter, bumped by every _update
        self._last_converged = None    # (version, responses) of the last committed increment
        self._diag_cache = None        # (K's indptr, indices, K + diag buffer, diagonal positions)
        self._zero_force = None

    # ------------------------------------------------------------ helpers
    def dof_value(self, idx, dof):
        return self.x[idx, dof] - self.X0[idx, dof] if dof < 3 else self.spin[idx, dof - 3]

    def _evaluate(self, ctx, reuse=False):
        """Element responses at the current configuration.  With ``reuse``, a path-independent
        family whose converged response belongs to this very configuration (nothing has moved
        since the last commit) is not evaluated again; families with history always are, since
        their response at the start of an increment (trial state = committed state) differs from
        the converged one (e.g. an elastic instead of an elastoplastic tangent)."""
        last = self._last_converged
        cached = last[1] if reuse and last is not None and last[0] == self._version else None
        responses = []
        for i, (f, s) in enumerate(zip(self.families, self.states)):
            if cached is not None and f.path_independent:
                responses.append(cached[i])
                continue
            r = f.evaluate(self.x, self.R, s, ctx)
            if not np.isfinite(r.f).all():   # (the method: np.all's dispatch costs ~2 us a call)
                raise FloatingPointError(f"non-finite internal forces in element family '{f.name}'")
            responses.append(r)
        return responses

    def _nonfinite_tangent(self, responses):
        """Why a factorisation or solve failed, if an element tangent holds a NaN or inf (tested
        only then: a scan of every element matrix costs as much as assembling them)."""
        for f, r in zip(self.families, responses or ()):
            if not np.all(np.isfinite(r.k)):
                return f"non-finite tangent stiffness in element family '{f.name}'"
        return None

    def _bad_tangent(self, exc, responses):
        """The named non-finite element tangent behind a failed factorisation or solve, or None."""
        return self._nonfinite_tangent(responses) if isinstance(exc, SingularModelError) else None

    def _residual(self, responses, P):
        """Residual P - F on the independent DOFs (free first, then constrained)."""
        F = self.assembler.forces([q.f for q in responses])
        if self._Pa is None or self._Pa[0] is not P:   # the loads are fixed within an increment
            self._Pa = (P, P[self.act_node, self.act_dof])
        self._net = F - self._Pa[1]
        if not self._constrained:
            return -self._net
        self._T = self.constraints.transformation(self.x)
        return -transpose_times(self._T, self._net)

    def _reduce_load(self, P):
        """A nodal load array (n, 6) as a vector on the free DOFs (through the constraints)."""
        Pa = P[self.act_node, self.act_dof]
        if self._constrained:
            Pa = transpose_times(self._T, Pa)
        return Pa[: self.dofmap.n_free]

    def _factorize_tangent(self, responses, with_fc):
        """Assemble and factorise K_ff; returns (K_ff or None, K_fc or None).

        An unconstrained model's element matrices go straight into the linear solver's permuted
        matrix (positions composed once: no CSR fill and no gather per iteration), and K_ff is
        then not formed (None).  Constrained models, and the first tangent (whose diagonal sets
        the zero-force floors), go through :meth:`_tangent`."""
        if self._constrained or self._zero_force is None or self.solver.chosen is None:
            return self._factorize_csr(responses, with_fc)
        if self._direct is None or self._direct[0] != self.solver.layout:
            # a stabilised step may have widened the solver's pattern (a diagonal entry K_ff lacks):
            # the direct path needs the solver's pattern to be K_ff's own
            same = self.solver.has_pattern(self.assembler.K_ff)
            self._direct = (self.solver.layout, [self.solver.permuted_positions(p) for p in self.assembler.pos_ff]
                            if same else None)
        if self._direct[1] is None:
            return self._factorize_csr(responses, with_fc)
        ta = _time.perf_counter()
        k_list = [q.k for q in responses]
        Kfc = self.assembler.coupling(k_list) if with_fc else None
        self.assembler.tangent_into(k_list, self.solver.values, self._direct[1])
        self.summary.assembly_time += _time.perf_counter() - ta
        ts = _time.perf_counter()
        self.solver.factorize_values()
        self.summary.solve_time += _time.perf_counter() - ts
        return None, Kfc

    def _factorize_csr(self, responses, with_fc, adjust=None):
        """Assemble K_ff as a CSR matrix (passed through ``adjust`` if given, e.g. to add damping)
        and factorise it; returns (K_ff, K_fc or None)."""
        ta = _time.perf_counter()
        K, Kfc = self._tangent(responses, with_fc)
        if adjust is not None:
            K = adjust(K)
        self.summary.assembly_time += _time.perf_counter() - ta
        ts = _time.perf_counter()
        self.solver.factorize(K)
        self.summary.solve_time += _time.perf_counter() - ts
        return K, Kfc

    def _tangent(self, responses, with_fc):
        """(K_ff, K_fc) at the configuration of the last :meth:`_residual` call."""
        k_list = [q.k for q in responses]
        if not self._constrained:
            K, Kfc = self.assembler.tangent(k_list, with_fc=with_fc)
        else:
            K_aa = self.assembler.full_tangent(k_list)
            K, Kfc = self._reduced.fill(K_aa.data, self._T.data, self.constraints.geometric_values(self.x, self._net))
            Kfc = Kfc if with_fc else None
        if self._zero_force is None:
            dk = np.abs(K.diagonal())
            kt, kr = (float(np.median(v[v > 0])) if np.any(v > 0) else 0.0
                      for v in (dk[~self.is_rot], dk[self.is_rot]))
            # 'zero flux' floors: forces of a 1e-6 L (1e-6 rad) motion of a typical DOF (the median
            # stiffness, so that penalty ties do not inflate it)
            self._zero_force = 1e-6 * max(kt * self.length, kr / self.length)
        return K, Kfc

    def _update(self, du_free, du_cons=None):
        self._version += 1
        update_configuration(self.x, self.spin, self.R, self._W, self.free_node, self.free_dof,
                             np.ascontiguousarray(du_free, dtype=float), self.cons_node, self.cons_dof,
                             self._no_update if du_cons is None else np.ascontiguousarray(du_cons, dtype=float))
        if self._constrained:
            self.constraints.update_slaves(self.x, self.R, self.spin)

    def _values(self, conds, start, frac_time, period, lam=None):
        """Loads or prescribed values at step time ``frac_time * period`` (or load factor lam)."""
        out = start.copy()
        for c in conds:
            i = self.model.index(c.node)
            if lam is not None:
                out[i, c.dof] = start[i, c.dof] + lam * (c.magnitude - start[i, c.dof])
            elif c.amplitude is not None:
                out[i, c.dof] = c.amplitude(frac_time * period) * c.magnitude
            else:
                out[i, c.dof] = start[i, c.dof] + frac_time * (c.magnitude - start[i, c.dof])
        return out

    def _name_dofs(self, eqs):
        return ", ".join(self.dofmap.describe(int(e)) for e in eqs)

    def _singular_message(self, K, where):
        eqs = mechanism_dofs(K)
        what = (f"the free DOFs of the mechanism include: {self._name_dofs(eqs)}" if eqs is not None
                else "the model is too large to name the mechanism")
        return (f"{where}: the tangent stiffness is singular: {what}. Fix or constrain these DOFs, or connect "
                "the nodes to an element that stiffens them.")

    def tangent(self):
        """Tangent stiffness K_ff (scipy CSR, free DOFs) at the current configuration and
        committed state; use :meth:`free_equation` to find a node's rows."""
        responses = self._evaluate(IncrementContext(x_committed=self.x, R_committed=self.R))
        self._residual(responses, self.loads)
        K, _ = self._tangent(responses, with_fc=False)
        return K.copy()

    def free_equation(self, label, dof) -> int:
        """Equation number of a free DOF (dof index 0..5 or name); ModelError if not free."""
        from .model import dof_index

        d = dof if isinstance(dof, (int, np.integer)) else dof_index(dof)
        eq = int(self.dofmap.eq[self.model.index(label), d])
        if not 0 <= eq < self.dofmap.n_free:
            raise ModelError(f"node {label} {DOF_NAMES[d]} is not a free DOF (fixed, prescribed or unused)")
        return eq

    def condensed_stiffness(self, labels, dofs=range(6)):
        """Stiffness (N/m, N, N m/rad) seen at ``dofs`` of nodes ``labels``: the current tangent
        with every other free DOF condensed out (Schur complement).  Rows/columns ordered
        node by node, DOF by DOF."""
        import scipy.sparse.linalg as spla

        K = self.tangent().tocsc()
        keep = np.array([self.free_equation(l, d) for l in np.atleast_1d(labels) for d in dofs])
        rest = np.setdiff1d(np.arange(K.shape[0]), keep)
        Kaa = K[keep][:, keep].toarray()
        if rest.size == 0:
            return Kaa
        Kab = K[keep][:, rest]
        Kbb = K[rest][:, rest]
        try:
            lu = spla.splu(Kbb.tocsc())
        except RuntimeError:
            raise SingularModelError("condensed_stiffness: the model is singular once the retained DOFs are "
                                     "held; it has a mechanism besides them") from None
        return Kaa - Kab @ lu.solve(K[rest][:, keep].toarray())

    # ------------------------------------------------------------ the run
    def run(self) -> Results | None:
        """Run all steps; returns the :class:`Results` of the folder, or None with ``out=None``."""
        t0 = _time.perf_counter()
        writer = NullWriter() if self.out is None else ResultsWriter(self.out, self.model, self.families)
        self._pending_frame = None   # a converged increment not written yet (Step.output_frequency)
        ti = None
        try:
            self._write(writer, step_name="initial", inc=0, time=0.0, iterations=0, responses=None)
            ti = _time.perf_counter()
            for k, step in enumerate(self.model.steps):
                self._run_step(k, step, writer)
            self.summary.status, self.summary.completed = "completed", True
        except BaseException as exc:   # the summary says how the run ended, then the error goes on
            self.summary.status, self.summary.message = run_outcome(exc)
            if isinstance(exc, ConvergenceError) and self._pending_frame is not None:
                self._write(writer, *self._pending_frame)   # the state of the last converged increment
                self._pending_frame = None
            raise
        finally:
            self.summary.increment_time = _time.perf_counter() - ti if ti is not None else 0.0
            self.summary.wall_time = _time.perf_counter() - t0
            writer.close({**self.summary.__dict__, "strain_energy": self.strain_energy})
            if self.progress:
                tqdm.write(str(self.summary))
        return None if self.out is None else Results(self.out)

    def _run_step(self, k, step, writer):
        if getattr(step.control, "arc_length", False):
            return self._run_arc_step(step, writer)
        period = step.period
        dt = step.initial_increment or min(period, step.max_increment or period)
        dt_min = step.min_increment or period * 1e-5
        dt_max = step.max_increment or period
        control = step.control or LoadControl()
        control.setup(self, step)
        if control.solves_for_load_factor and any(c.amplitude is not None for c in step.loads):
            raise ModelError(f"step '{step.name}': amplitudes cannot be used with {type(control).__name__}; "
                             "the load factor is an unknown")
        hit = sorted({float(h) for h in step.hit_times} |
                     {float(t) for c in step.loads + step.prescribed if c.amplitude is not None
                      for t in c.amplitude.times if 0 < t < period})
        load_start, pres_start = self.loads.copy(), self.prescribed.copy()
        self._last_Du = None
        self._stab_C = None
        self._stab_dt0 = dt
        self._stab_energy = 0.0
        t, inc, easy = 0.0, 0, 0
        self.lam = 0.0
        step_iters = 0
        bar = tqdm(total=period, desc=f"step {step.name}", unit="s", disable=not self.progress, leave=False,
                   bar_format="{desc}: {percentage:3.0f}%|{bar}| t={n:.4g}/{total:.4g} [{elapsed}<{remaining}]")
        while t < period * (1 - 1e-12):
            if inc >= step.max_increments:
                raise ConvergenceError(f"step '{step.name}': reached max_increments={step.max_increments} at step "
                                       f"time {t:.6g} of {period:g} s; raise max_increments or max_increment")
            dt = min(dt, dt_max, period - t)
            for h in hit:
                if t + 1e-12 * period < h < t + dt - 1e-12 * period:
                    dt = h - t
                    break
            attempt = 0
            while True:
                attempt += 1
                ok, iters, note, responses = self._increment(step, control, t, dt, load_start, pres_start,
                                                             line_search=self.line_search is True or
                                                             (self.line_search == "auto" and attempt > 1))
                step_iters += iters
                self.summary.iterations += iters
                if ok:
                    break
                writer.status(step.name, inc + 1, attempt, iters, t + dt, self.total_time + dt, dt, self.lam,
                              f"cutback: {note}")
                self.summary.cutbacks += 1
                dt *= self.cutback
                easy = 0
                if dt < dt_min:
                    bar.close()
                    raise ConvergenceError(
                        f"step '{step.name}': increment fell below the minimum {dt_min:.3g} s at step time "
                        f"{t:.6g} s (total time {self.total_time:.6g} s): {note}. The {self.summary.increments} "
                        f"converged increments are {self._kept()}.")
            inc += 1
            t += dt
            self.total_time += dt
            self.summary.increments += 1
            self._frame_due(writer, step, inc, not t < period * (1 - 1e-12), step.name, inc, t, iters, responses,
                            period)
            note = ""
            if step.stabilize is not None:
                note = (f"stabilisation/strain energy {self.stabilization_ratio:.3g}, largest viscous force "
                        f"{self._stab_force[0]:.3g} N, moment {self._stab_force[1]:.3g} N m")
            writer.status(step.name, inc, attempt, iters, t, self.total_time, dt, self.lam, note)
            bar.update(dt)
            easy = easy + 1 if iters <= self.easy_iterations else 0
            if easy >= 2:
                dt *= self.growth
        bar.close()
        info = {"name": step.name, "increments": inc, "iterations": step_iters}
        if step.stabilize is not None:
            info["stabilization_energy"] = self._stab_energy
            info["stabilization_ratio"] = self.stabilization_ratio
            # viscous forces left in the last increment: how far from equilibrium the end state is
            info["stabilization_force"], info["stabilization_moment"] = self._stab_force
            if self.stabilization_ratio > step.stabilize.warn_ratio:
                msg = (f"step '{step.name}': stabilisation energy is {100 * self.stabilization_ratio:.1f}% of the strain "
                       f"energy (above {100 * step.stabilize.warn_ratio:.0f}%): the stabilised solution may be "
                       "far from equilibrium; lower the damping factor or the energy fraction")
                warnings.warn(msg, StabilizationWarning, stacklevel=3)
                if self.progress:
                    tqdm.write("femast: warning: " + msg)
        self.summary.steps.append(info)

    @property
    def stabilization_ratio(self) -> float:
        """Stabilisation energy dissipated in the current step / strain energy (dimensionless)."""
        return self._stab_energy / self.strain_energy if self.strain_energy > 0 else (
            0.0 if self._stab_energy == 0 else float("inf"))

    def _increment(self, step, control, t, dt, load_start, pres_start, line_search=False):
        """Try one increment; on success commit and return (True, iterations, '', responses);
        on failure restore the committed configuration and return (False, iterations, why, None)."""
        saved = (self.x.copy(), self.R.copy(), self.spin.copy(), self.lam, self._version)
        frac = (t + dt) / step.period
        period = step.period
        ctx = IncrementContext(time=t + dt, dtime=dt, total_time=self.total_time + dt, x_committed=saved[0],
                               R_committed=saved[1], step_name=step.name)
        uses_lam = control.solves_for_load_factor
        if uses_lam:
            lam = self.lam
            P_end = self._values(step.loads, load_start, 1.0, period)
            P_ref_full = P_end - load_start
        else:
            lam = frac
        pres = self._values(step.prescribed, pres_start, frac, period)
        dpres = pres[self.cons_node, self.cons_dof] - self.prescribed[self.cons_node, self.cons_dof]
        dpres[self.fixed[self.cons_node, self.cons_dof]] = 0.0
        has_dpres = bool(np.any(dpres))
        nf = self.dofmap.n_free
        Du = np.zeros(nf)
        iters = 0
        rnorm_hist = []
        responses = None

        def loads_now(lam_):
            return (self._values(step.loads, load_start, frac, period) if not uses_lam
                    else load_start + lam_ * P_ref_full)

        stab = step.stabilize

        def damped(K):
            """K + C/dt: the viscous term of the stabilisation (*STABILIZE)."""
            if self._stab_C is None:  # damping from the tangent at the start of the step
                self._stab_C = stab.damping(K.diagonal(), self.is_rot, self._stab_dt0)
                self._stab_C0 = self._stab_C.copy()
            return self._plus_diagonal(K, self._stab_C / dt)

        def evaluate(P, Dtrial=None, reuse=False):
            ta = _time.perf_counter()
            resp = self._evaluate(ctx, reuse=reuse)
            res_ = self._residual(resp, P)
            self.summary.assembly_time += _time.perf_counter() - ta
            if not np.isfinite(res_).all():
                raise FloatingPointError("non-finite residual")
            r_ = res_[:nf]
            if stab is not None and self._stab_C is not None:
                r_ = r_ - self._stab_C / dt * (Du if Dtrial is None else Dtrial)
            return resp, res_, r_

        if self.extrapolate and self._last_Du is not None and not has_dpres:
            # Abaqus' linear extrapolation: start from the previous increment's solution, scaled
            scale = dt / self._last_dt
            Du += scale * self._last_Du
            self._update(scale * self._last_Du)
            lam += scale * self._last_Dlam if uses_lam else 0.0
        lam_start = self.lam
        try:
            P = loads_now(lam)
            responses, F, r = evaluate(P, reuse=True)
            for it in range(self.convergence.max_iterations + 1):
                if (it == 0 and not uses_lam and not has_dpres and not np.any(Du) and stab is None
                        and self._at_equilibrium and np.array_equal(P, self.loads)):
                    # nothing changes (e.g. a step that repeats the previous loads): the committed
                    # state is the converged solution
                    self._commit(responses, P, F, lam)
                    return True, 0, "", responses
                if it > 0:
                    ok, ratio = self._converged(r, du, Du, responses, P, iters)
                    rnorm_hist.append(ratio)
                    if ok:
                        if stab is not None:
                            self._stab_energy += float(Du @ (self._stab_C / dt * Du))
                            fv = np.abs(self._stab_C / dt * Du)
                            self._stab_force = (float(fv[~self.is_rot].max(initial=0.0)),
                                                float(fv[self.is_rot].max(initial=0.0)))
                            strain = sum(float(np.sum(q.energy)) for q in responses if q.energy is not None)
                            ratio = self._stab_energy / max(strain, 1e-300)
                            self._stab_C = stab.adapt(self._stab_C, self._stab_C0, ratio)
                        self._last_Du, self._last_dt, self._last_Dlam = Du.copy(), dt, lam - lam_start
                        self._commit(responses, P, F, lam, equilibrium=stab is None)
                        return True, iters, "", responses
                    if it == self.convergence.max_iterations:
                        return self._fail(saved, iters, f"no convergence in {iters} iterations "
                                          f"(residual ratio {ratio:.3g}, worst at {self._worst(r)})")
                    if it >= 8 and rnorm_hist[-1] > rnorm_hist[-2] > rnorm_hist[-3] > rnorm_hist[-4]:
                        return self._fail(saved, iters, f"residual diverging (ratio {ratio:.3g}, worst at "
                                          f"{self._worst(r)})")
                # the tangent only when another iteration is needed
                K = None
                try:
                    if stab is None:
                        K, Kfc = self._factorize_tangent(responses, with_fc=(it == 0 and has_dpres))
                    else:
                        K, Kfc = self._factorize_csr(responses, with_fc=(it == 0 and has_dpres), adjust=damped)
                except SingularModelError:
                    bad = self._nonfinite_tangent(responses)
                    if bad:
                        return self._fail(saved, iters, bad)
                    if self.summary.increments == 0 and it == 0:
                        if K is None:
                            K, _ = self._tangent(responses, with_fc=False)
                        raise SingularModelError(self._singular_message(K, f"step '{step.name}'")) from None
                    return self._fail(saved, iters, "singular tangent (bifurcation or mechanism)")
                ts = _time.perf_counter()
                rhs = r if Kfc is None else r - Kfc @ dpres
                du = self.solver.solve(rhs)
                if uses_lam:
                    du_p = self.solver.solve(self._reduce_load(P_ref_full))
                    cur = self.dof_value(self.free_node[control.eq], self.free_dof[control.eq])
                    dlam = control.dlambda(du, du_p, cur, frac)
                    du = du + dlam * du_p
                    lam += dlam
                self.summary.solve_time += _time.perf_counter() - ts
                iters += 1
                search = line_search and not uses_lam and not (it == 0 and has_dpres)
                before = (self.x.copy(), self.R.copy(), self.spin.copy()) if search else None
                self._update(du, dpres if it == 0 else None)
                if uses_lam:  # under load control the loads are those of the increment's end
                    P = loads_now(lam)
                Du_before = Du.copy()
                Du += du
                responses, F, r_new = evaluate(P)
                if search:
                    du, responses, F, r_new = self._line_search(du, r, r_new, responses, F, before, evaluate, P,
                                                                Du_before)
                    Du = Du_before + du
                r = r_new
        except (FloatingPointError, SingularModelError, ValueError) as exc:
            bad = self._bad_tangent(exc, responses)
            if bad:
                return self._fail(saved, iters, bad)
            if isinstance(exc, SingularModelError) and self.summary.increments == 0 and iters == 0:
                raise
            if isinstance(exc, ModelError):
                raise
            return self._fail(saved, iters, str(exc))
        return self._fail(saved, iters, "no convergence")

    def _line_search(self, du, r0, r1, responses, F, before, evaluate, P, Du_before, eta=0.8, max_steps=5):
        # F here is the reduced residual of the trial point (kept for the commit)
        """Secant line search on g(s) = du . r(u + s du) (Crisfield 1991, sec. 9.3): only when the
        full step leaves |g(1)| > eta |g(0)|.  Returns the accepted step and its evaluation."""
        g0 = float(du @ r0)
        g1 = float(du @ r1)
        if g0 == 0.0 or abs(g1) <= eta * abs(g0):
            return du, responses, F, r1
        s_prev, g_prev, s, g = 0.0, g0, 1.0, g1
        best = (abs(g1), 1.0, responses, F, r1)
        for _ in range(max_steps):
            s_new = s - g * (s - s_prev) / (g - g_prev) if g != g_prev else 0.5 * s
            s_new = min(max(s_new, 0.05), 1.0)
            self.x, self.R, self.spin = before[0].copy(), before[1].copy(), before[2].copy()
            self._update(s_new * du)
            resp, F_, r_ = evaluate(P, Du_before + s_new * du)
            g_new = float(du @ r_)
            if abs(g_new) < best[0]:
                best = (abs(g_new), s_new, resp, F_, r_)
            if abs(g_new) <= eta * abs(g0):
                break
            s_prev, g_prev, s, g = s, g, s_new, g_new
        _, s_best, resp, F_, r_ = best
        if s_best != s_new:
            self.x, self.R, self.spin = before[0].copy(), before[1].copy(), before[2].copy()
            self._update(s_best * du)
        self.summary.line_searches += 1
        return s_best * du, resp, F_, r_

    # ------------------------------------------------------------ arc length
    def _run_arc_step(self, step, writer):
        control = step.control
        control.setup(self, step)
        load_start = self.loads.copy()
        P_ref_full = self._values(step.loads, load_start, 1.0, step.period) - load_start
        self.lam = 0.0
        dl0 = dl = None
        prev = None
        inc = step_iters = 0
        bar = tqdm(total=1.0, desc=f"step {step.name} (arc length)", disable=not self.progress, leave=False,
                   bar_format="{desc}: {percentage:3.0f}%|{bar}| [{elapsed}<{remaining}]")
        while True:
            attempt = 0
            while True:
                attempt += 1
                ok, iters, note, responses, dl_used, Du, dlam = self._increment_arc(
                    step, control, dl, prev, load_start, P_ref_full)
                step_iters += iters
                self.summary.iterations += iters
                if dl0 is None:
                    dl0 = dl_used
                if ok:
                    break
                writer.status(step.name, inc + 1, attempt, iters, self.lam, self.total_time, dl_used, self.lam,
                              f"cutback: {note}")
                self.summary.cutbacks += 1
                dl = dl_used * self.cutback
                if dl < control.min_arc * dl0:
                    bar.close()
                    raise ConvergenceError(
                        f"step '{step.name}': arc length fell below the minimum ({control.min_arc:g} of the first) "
                        f"at load factor {self.lam:.6g}: {note}. The {self.summary.increments} converged "
                        f"increments are {self._kept()}.")
            inc += 1
            prev = (Du, dlam)
            dt = dl_used / dl0 * control.initial_load_factor
            self.total_time += dt
            self.summary.increments += 1
            frac = control.progress(self, self.lam)
            self._frame_due(writer, step, inc, frac >= 1.0 - 1e-12 or inc >= step.max_increments,
                            step.name, inc, self.lam, iters, responses)
            writer.status(step.name, inc, attempt, iters, self.lam, self.total_time, dl_used, self.lam,
                          f"arc length {dl_used:.4g}")
            bar.n = min(max(frac, 0.0), 1.0)
            bar.refresh()
            dl = dl_used * min(max(math.sqrt(control.desired_iterations / max(iters, 1)), 0.5), 2.0)
            dl = min(max(dl, control.min_arc * dl0), control.max_arc * dl0)
            if frac >= 1.0 - 1e-12 or inc >= step.max_increments:
                break
        bar.close()
        self.summary.steps.append({"name": step.name, "increments": inc, "iterations": step_iters,
                                   "final_load_factor": self.lam})

    def _increment_arc(self, step, control, dl, prev, load_start, P_ref_full):
        """One arc-length increment; returns (ok, iterations, note, responses, dl, Du, dlambda)."""
        saved = (self.x.copy(), self.R.copy(), self.spin.copy(), self.lam, self._version)
        ctx = IncrementContext(time=self.lam, dtime=0.0, total_time=self.total_time, x_committed=saved[0],
                               R_committed=saved[1], step_name=step.name)
        nf = self.dofmap.n_free
        lam = lam0 = self.lam
        iters = 0
        responses = None
        try:
            P = load_start + lam * P_ref_full
            responses = self._evaluate(ctx, reuse=True)
            res = self._residual(responses, P)
            K, _ = self._tangent(responses, with_fc=False)
            self.solver.factorize(K)
            du_p = self.solver.solve(self._reduce_load(P_ref_full))
            norm_p = math.sqrt(control.norm2(du_p))
            if dl is None:
                dl = control.initial_load_factor * norm_p
            sign = 1.0
            if prev is not None:
                sign = 1.0 if float(prev[0] @ (control.weights * du_p)) >= 0 else -1.0
            dlam = sign * dl / norm_p
            du = dlam * du_p
            Du = du.copy()
            lam += dlam
            self._update(du)
            iters = 1
            rhist = []
            for it in range(1, self.convergence.max_iterations + 1):
                P = load_start + lam * P_ref_full
                responses = self._evaluate(ctx)
                res = self._residual(responses, P)
                r = res[:nf]
                if not np.all(np.isfinite(r)):
                    raise FloatingPointError("non-finite residual")
                ok, ratio = self._converged(r, du, Du, responses, P, iters)
                rhist.append(ratio)
                if ok:
                    self._commit(responses, P, res, lam)
                    return True, iters, "", responses, dl, Du, lam - lam0
                if it >= 8 and rhist[-1] > rhist[-2] > rhist[-3] > rhist[-4]:
                    break
                K, _ = self._tangent(responses, with_fc=False)
                self.solver.factorize(K)
                du_r = self.solver.solve(r)
                du_p = self.solver.solve(self._reduce_load(P_ref_full))
                d = control.correction(Du, du_r, du_p, dl)
                if d is None:
                    return self._fail_arc(saved, iters, "arc-length constraint has no real root", dl)
                du = du_r + d * du_p
                lam += d
                Du += du
                self._update(du)
                iters += 1
            return self._fail_arc(saved, iters, f"no convergence in {iters} iterations", dl)
        except (FloatingPointError, SingularModelError) as exc:
            bad = self._bad_tangent(exc, responses)
            return self._fail_arc(saved, iters, bad or str(exc), dl)

    def _fail_arc(self, saved, iters, why, dl):
        self._fail(saved, iters, why)
        return False, iters, why, None, dl, None, 0.0

    def _worst(self, r):
        return self.dofmap.describe(int(np.argmax(np.abs(r))))

    def _converged(self, r, du, Du, responses, P, iteration=0):
        """Force/moment residual against the largest element nodal force/moment or applied load
        (Abaqus' 'flux' magnitude), displacement correction against the increment."""
        fmax, mmax = force_moment_abs_max(P)
        for resp in responses:
            ff, mm = force_moment_abs_max(resp.f)
            fmax = max(fmax, ff)
            mmax = max(mmax, mm)
        L = self.length
        ref_f = max(fmax, 1e-2 * mmax / L, self._zero_force)
        ref_m = max(mmax, 1e-2 * fmax * L, self._zero_force * L)
        return self.convergence.check(r, du, Du, self.is_rot, ref_f, ref_m, L, iteration)

    def _fail(self, saved, iters, why):
        self.x, self.R, self.spin, self.lam, self._version = saved
        return False, iters, why, None

    def _commit(self, responses, P, res, lam, equilibrium=True):
        self._at_equilibrium = equilibrium   # False after a stabilised increment (viscous forces)
        self._last_converged = (self._version, responses)
        self.states = [r.state.copy() if r.state is not None else s for r, s in zip(responses, self.states)]
        self.loads = P.copy()
        t = self.cons_dof < 3   # the values reached: displacements x - X0, rotations the accumulated spins
        self.prescribed[self.cons_node[t], self.cons_dof[t]] = (self.x[self.cons_node[t], self.cons_dof[t]]
                                                                - self.X0[self.cons_node[t], self.cons_dof[t]])
        self.prescribed[self.cons_node[~t], self.cons_dof[~t]] = self.spin[self.cons_node[~t], self.cons_dof[~t] - 3]
        self.lam = lam
        self.strain_energy = float(sum(np.sum(r.energy) for r in responses if r.energy is not None))
        self._reactions = -res[self.dofmap.n_free:]
        if equilibrium and self._check_balance:   # issue 16: reactions balance the loads
            RF = np.zeros_like(P)
            RF[self.cons_node, self.cons_dof] = self._reactions
            validation.check_equilibrium(self.x, P, RF, res[:self.dofmap.n_free], self.free_dof,
                                         f"increment {self.summary.increments + 1}",
                                         internal=float(sum(np.abs(q.f).sum() for q in responses)),
                                         labels=self.model.node_labels)

    def _plus_diagonal(self, K, c):
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
            if K.has_canonical_format and d.size == n:   # one diagonal entry per row
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

    def _frame_due(self, writer, step, inc, last, *frame):
        """Write the frame ``frame`` (the arguments of :meth:`_write`) of increment ``inc`` if the
        step's output frequency asks for it or it is the step's ``last``; else keep it pending."""
        if last or inc % step.output_frequency == 0:
            self._write(writer, *frame)
            self._pending_frame = None
        else:
            self._pending_frame = frame

    def _kept(self) -> str:
        """Where the converged increments of a run that gives up are (for its error message)."""
        sparse = any(st.output_frequency > 1 for st in self.model.steps)
        where = "passed to on_frame (out=None: nothing written)" if self.out is None else f"saved in '{self.out}'"
        return where + (" at the steps' output frequency, the last one included" if sparse else "")

    def _write(self, writer, step_name, inc, time, iterations, responses, period=1.0):
        if self.out is None and self.on_frame is None:
            return
        n = len(self.X0)
        RF = np.zeros((n, 6))
        if responses is not None:
            RF[self.cons_node, self.cons_dof] = self._reactions
        data = {"step": step_name, "increment": inc, "time": time, "total_time": self.total_time,
                "load_factor": self.lam, "iterations": iterations, "U": self.x - self.X0, "R": self.R.copy(),
                "UR": rotation_vectors(self.R), "URA": self.spin.copy(), "RF": RF, "P": self.loads.copy(),
                "strain_energy": self.strain_energy, "stabilization_energy": self._stab_energy}
        if responses is None:
            responses = self._evaluate(IncrementContext(x_committed=self.x, R_committed=self.R))
        for f, r in zip(self.families, responses):
            for key, val in r.output.items():
                data[f"el/{f.name}/{key}"] = val
        writer.frame(**data)
        if self.on_frame is not None:
            self.on_frame(data)


def solve(model, out="results", **options) -> Results | None:
    """Run all steps of ``model``; write results to folder ``out``; return :class:`Results` (None
    with ``out=None``, see :class:`Analysis`).
    Options are those of :class:`Analysis`."""
    return Analysis(model, out, **options).run()
