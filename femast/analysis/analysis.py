"""The static analysis: set-up, then the steps.

``Analysis(model, out).run()`` builds the element families and the numbered system
(system.py), starts from the initial :class:`State` (state.py) and walks the model's steps
(stepping.py).  For each increment the step's control strategy (controls.py) proposes the load
level, the Newton algorithm (newton.py) iterates with the exact tangent, and when the increment
converges the state is committed and the observers (output.py: the results writer, the
``on_frame`` recorders) are told.  A diverging increment is retried with a quarter of the
increment (Abaqus' cutback); easy increments grow by 1.5.  If the increment falls below the
minimum, the run stops with :class:`~femast.errors.ConvergenceError` saying where and why; every
converged increment is already on disk.  See docs/architecture.md.
"""

from __future__ import annotations

import time as _time
import warnings

import numpy as np
from tqdm.auto import tqdm

from ..elements.base import DOF_NAMES
from ..errors import ConvergenceError, ModelError, SingularModelError
from ..jit import prepare as prepare_kernels
from ..model import validation
from ..model.thermal import FieldLoads, check_controls, has_fields
from ..post.results import Results, run_outcome
from ..post.writer import lock_folder
from .convergence import Convergence, validate
from .equilibrium import check_end_of_run
from .families import build_families
from .newton import Newton
from .output import ResultsOutput
from .restart import RestartOutput, load_restart, require_point, restart_folder, restore
from .state import State
from .stepping import run_step
from .summary import AnalysisSummary
from .system import System

MIN_CUTBACK, MAX_CUTBACK = 1e-3, 0.9  # a factor of 1 (or NaN) never shrinks an increment: no end
MAX_GROWTH = 10.0


def _factor(value, name: str, lo: float, hi: float, why: str) -> float:
    """``value`` as a finite float between ``lo`` and ``hi``, or a ModelError naming ``name`` and why."""
    v = validation.number(value, f"Analysis: {name}")
    if not lo <= v <= hi:
        raise ModelError(f"Analysis: {name} = {v:g} must be between {lo:g} and {hi:g} ({why})")
    return v


class Analysis:
    """A static, geometrically nonlinear analysis of ``model`` writing to folder ``out``.

    out : the results folder, or None to write nothing (no folder, frames or status file): each
        frame then only goes to ``on_frame``, and :meth:`run` returns None.  For scripts and fits
        that keep what they need in memory (an FE experiment's many short runs).

    convergence : :class:`~femast.analysis.convergence.Convergence` (tolerances, max iterations), or a
        convergence test of your own (the contract: :mod:`femast.analysis.convergence`).
    progress : show a tqdm progress bar per step.
    cutback : factor applied to a failed increment (Abaqus: 0.25), between 0.001 and 0.9.
    growth : factor applied after two easy increments (Abaqus: 1.5), between 1 (no growth) and 10.
    max_cutbacks : the most cutbacks of one step (1000): a step cut back that often gives up with a
        ConvergenceError saying where, whatever its minimum increment.
    line_search : secant line search when a Newton step overshoots (load control): True, False, or
        "auto" (default): only when retrying an increment that failed, where plain Newton
        already went astray (a line search slows the easy increments down).
    tangent : "auto" (default: full Newton, the first iteration of an increment on the previous
        increment's last factorisation where that is safe; see docs/performance.md), "full" (a
        new tangent every iteration), "modified" (one per increment, again when convergence slows), "quasi-newton"
        (modified with Broyden's update) or "initial" (one per step): see
        :class:`~femast.analysis.newton.Newton`.
    extrapolate : start each increment from the previous increment's solution scaled to the new
        increment (Abaqus' default linear extrapolation); off after a step change.
    easy_iterations : an increment converged in at most this many iterations is easy (Abaqus'
        I_G = 4 with looser tolerances; 6 with femast's tighter defaults).
    on_frame : a recorder, called with each frame's dict (the arrays written to
        ``frames/frames.npzs``; the first call is the initial state) as soon as its increment has
        converged.  A script that needs a few quantities keeps them in memory this way instead of
        reading the results folder back (which costs about as much as the analysis of a small
        model).  Do not modify the arrays: the same ones are being written to disk.
    observers : more observers of the run (:class:`~femast.analysis.output.Observer`).
    restart_every : save a restart point every that many converged increments (docs/restart.md);
        default None: none (a restarted run goes on saving them as before).
    restart : the results folder of an earlier run of the same model to continue from its last
        restart point (``femast run SCRIPT --restart FOLDER`` sets it for every analysis of a script).
    linear_solver : the back-end that factorises the tangent (:mod:`femast.analysis.linalg.backends`):
        "auto" (default: LAPACK's dense LU up to 64 DOFs; LAPACK's band solver for a narrow reverse
        Cuthill-McKee band, as in a mast; PARDISO, if installed, for other models of 1000 DOFs or
        more; else SuperLU), or one forced by name: "superlu", "banded", "dense", "cholmod", "pardiso".

    After construction: ``state`` (:class:`State`: configuration, element states, loads...),
    ``system`` (:class:`System`: numbering, assembly, linear solver), ``algorithm``
    (:class:`Newton`), ``observers`` and ``summary`` (:class:`AnalysisSummary`).
    """

    def __init__(
        self,
        model,
        out="results",
        convergence: Convergence | None = None,
        progress: bool = True,
        cutback: float = 0.25,
        growth: float = 1.5,
        easy_iterations: int = 6,
        line_search="auto",
        extrapolate: bool = False,
        on_frame=None,
        tangent: str = "auto",
        observers=(),
        restart=None,
        restart_every: int | None = None,
        linear_solver: str = "auto",
        max_cutbacks: int = 1000,
    ):
        _check_model_argument(model, out)
        prepare_kernels()  # the first-run compile notice armed (femast.jit)
        self.model = model
        self.on_frame = on_frame
        self.out = out
        if out is None and on_frame is None:
            warnings.warn(
                "Analysis(out=None) without on_frame keeps no results: only the final state "
                "(Analysis.x, .R, .summary) remains",
                stacklevel=2,
            )
        self.convergence = Convergence() if convergence is None else validate(convergence)
        self.progress = progress
        self.cutback = _factor(
            cutback,
            "cutback",
            MIN_CUTBACK,
            MAX_CUTBACK,
            "a failed increment is retried this much smaller: 1 or more "
            "never shrinks it, and the step would never end; Abaqus uses 0.25",
        )
        self.growth = _factor(
            growth,
            "growth",
            1.0,
            MAX_GROWTH,
            "easy increments grow by this factor: below 1 every increment shrinks; Abaqus uses 1.5",
        )
        self.easy_iterations = validation.whole(easy_iterations, "Analysis: easy_iterations", minimum=1)
        self.max_cutbacks = validation.whole(max_cutbacks, "Analysis: max_cutbacks", minimum=1)
        if line_search not in (True, False, "auto"):
            raise ModelError(f'Analysis: line_search = {line_search!r}; give True, False or "auto"')
        self.line_search = line_search
        self.extrapolate = extrapolate
        self.algorithm = Newton(self.convergence, line_search=line_search, tangent=tangent)
        if not model.steps:
            raise ModelError(f"model '{model.name}' has no steps; add one with model.step()")
        if not (model.beams or model.trusses or model.families):
            raise ModelError(f"model '{model.name}' has no elements")
        for s in model.steps:  # (again: a step's fields may have been set after model.step())
            validation.step_increments(s)
        self.families = build_families(model)
        check_controls(model)
        # length errors and temperatures: None when the model has neither
        self.fields = FieldLoads(model, self.families) if has_fields(model) else None
        self.summary = AnalysisSummary()
        self.system = System(model, self.families, self.summary, linear_solver=linear_solver)
        self.state = State.initial(self.system.X0, self.families)
        self.output = ResultsOutput(out, [on_frame])
        self.observers = [self.output, *observers]
        # restart (restart.py): save a restart point every n increments; continue from one
        self.restart = restart_folder(out, restart)
        self.resume = None
        if restart_every is not None:
            self.observers.append(RestartOutput(validation.whole(restart_every, "restart_every", minimum=1)))
        elif self.restart is not None:  # a restarted run goes on saving restart points
            self.observers.append(RestartOutput(None))

    # ------------------------------------------------------------ the parts, by their usual names
    @property
    def state(self) -> State:
        return self._state

    @state.setter
    def state(self, state: State):
        """Replace the state (e.g. by one read with :meth:`State.load`): the system follows it and
        forgets the responses it kept of the old one's last converged configuration."""
        self._state = state
        self.system.state = state
        self.system.last_converged = None

    X0 = property(lambda self: self.system.X0)
    dofmap = property(lambda self: self.system.dofmap)
    assembler = property(lambda self: self.system.assembler)
    constraints = property(lambda self: self.system.constraints)
    solver = property(lambda self: self.system.solver)
    length = property(lambda self: self.system.length)
    is_rot = property(lambda self: self.system.is_rot)
    fixed = property(lambda self: self.system.fixed)
    free_node = property(lambda self: self.system.free_node)
    free_dof = property(lambda self: self.system.free_dof)
    act_node = property(lambda self: self.system.act_node)
    act_dof = property(lambda self: self.system.act_dof)
    # the committed state, read-only views by name
    states = property(lambda self: self._state.families)
    loads = property(lambda self: self._state.loads)
    prescribed = property(lambda self: self._state.prescribed)
    lam = property(lambda self: self._state.lam)
    total_time = property(lambda self: self._state.total_time)
    strain_energy = property(lambda self: self._state.strain_energy)

    # the configuration (assignable: tests perturb and restore it)
    def _set(name):
        return property(lambda self: getattr(self._state, name), lambda self, v: setattr(self._state, name, v))

    x, R, spin = _set("x"), _set("R"), _set("spin")
    del _set

    @property
    def stabilization_ratio(self) -> float:
        """Stabilisation energy dissipated in the current step / strain energy (dimensionless)."""
        st = self._state
        return (
            st.stabilization_energy / st.strain_energy
            if st.strain_energy > 0
            else (0.0 if st.stabilization_energy == 0 else float("inf"))
        )

    def dof_value(self, idx, dof):
        """Displacement (m) or accumulated rotation (rad) of DOF ``dof`` of node index ``idx``."""
        return self.system.dof_value(idx, dof)

    # ------------------------------------------------------------ tangent queries
    def tangent(self):
        """Tangent stiffness K_ff (scipy CSR, free DOFs) at the current configuration and
        committed state; use :meth:`free_equation` to find a node's rows."""
        sys_ = self.system
        responses = sys_.evaluate(sys_.committed_context())
        sys_.residual(responses, self._state.loads)
        K, _ = sys_.tangent(responses, with_fc=False)
        return K.copy()

    def free_equation(self, label, dof) -> int:
        """Equation number of a free DOF (dof index 0..5 or name); ModelError if not free."""
        from ..model import dof_index

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
            raise SingularModelError(
                "condensed_stiffness: the model is singular once the retained DOFs are "
                "held; it has a mechanism besides them"
            ) from None
        return Kaa - Kab @ lu.solve(K[rest][:, keep].toarray())

    # ------------------------------------------------------------ the run
    def run(self) -> Results | None:
        """Run all steps; returns the :class:`Results` of the folder, or None with ``out=None``."""
        t0 = _time.perf_counter()
        ti = None
        self.folder_lock = None
        self.output.writer = None  # (a run refused its folder writes no summary there, not even an earlier run's)
        try:
            first = 0
            if self.out is not None:  # one writer per folder, taken before a restart point is read
                if self.restart is not None:
                    require_point(self.restart)  # (no folder is made for a restart that has nothing to read)
                self.folder_lock = lock_folder(self.out)
            if self.restart is not None:
                self.resume = load_restart(self.restart, self)  # None: the point is the start
                if self.resume is not None:
                    restore(self, self.resume)
                    first = self.resume["step"] + (1 if self.resume["step_done"] else 0)
            for obs in self.observers:
                obs.started(self)
            ti = _time.perf_counter()
            for k, step in enumerate(self.model.steps):
                if k < first:
                    continue
                self._state.step = k
                runner = getattr(step, "runner", None)  # a step of another kind runs itself (e.g. modes)
                if runner is not None:
                    step_runner(runner)(self, step)
                else:
                    inside = self.resume is not None and k == self.resume["step"] and not self.resume["step_done"]
                    run_step(self, step, resume=self.resume if inside else None)
            check_end_of_run(self)  # no result without equilibrium (equilibrium.py)
            self.summary.status, self.summary.completed = "completed", True
        except BaseException as exc:  # the summary says how the run ended, then the error goes on
            self.summary.status, self.summary.message = run_outcome(exc)
            if isinstance(exc, ConvergenceError):
                for obs in self.observers:
                    obs.stopped(self)
            raise
        finally:
            self.summary.increment_time = _time.perf_counter() - ti if ti is not None else 0.0
            self.summary.wall_time = _time.perf_counter() - t0
            try:
                for obs in self.observers:
                    obs.finished(self)
            finally:
                if self.folder_lock is not None:
                    self.folder_lock.release()
            if self.progress:
                tqdm.write(str(self.summary))
        return None if self.out is None else Results(self.out)

    def kept(self) -> str:
        """Where the converged increments of a run that gives up are (for its error message)."""
        sparse = any(st.output_frequency > 1 for st in self.model.steps)
        where = "passed to on_frame (out=None: nothing written)" if self.out is None else f"saved in '{self.out}'"
        return where + (" at the steps' output frequency, the last one included" if sparse else "")


def _check_model_argument(model, out) -> None:
    """The first argument is the model: ``fm.solve("results/x", m)`` (the two swapped) or a model
    of another kind is a one-line ModelError naming what was given and the right call."""
    from ..model.model import Model

    if isinstance(model, Model):
        return
    if isinstance(out, Model):
        raise ModelError(
            f"solve/Analysis got the results folder {model!r} first and the model second: "
            f"the model comes first, fm.solve(model, {str(model)!r})"
        )
    raise ModelError(
        f"solve/Analysis needs a femast Model as its first argument (fm.solve(model, folder)); got "
        f"{type(model).__name__} {str(model)[:60]!r}"
    )


def solve(model, out="results", **options) -> Results | None:
    """Run all steps of ``model``; write results to folder ``out``; return :class:`Results` (None
    with ``out=None``, see :class:`Analysis`).
    Options are those of :class:`Analysis`."""
    return Analysis(model, out, **options).run()


def step_runner(path: str):
    """The function ``"module:function"`` that runs a step of a kind of its own (a step class's
    ``runner``, e.g. the frequency step's ``femast.modal.step:run_frequency_step``), called as
    ``function(analysis, step)``: the analysis imports no package above it."""
    import importlib

    module, _, name = path.partition(":")
    return getattr(importlib.import_module(module), name)
