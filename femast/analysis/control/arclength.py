"""Arc-length control: Crisfield's cylindrical arc-length method (a Riks-type integrator).

The loads defined in the step form a reference pattern P_ref scaled by an unknown load factor
lambda (P = P_start + lambda P_ref).  Each increment moves a fixed distance dl along the
equilibrium path, measured in the displacement space:

    Du^T W Du = dl^2,    W = 1 on translations (m), s^2 on rotations (s = rotation_scale, m/rad)

(Crisfield 1981, "A fast incremental/iterative solution procedure that handles snap-through",
Comput. Struct. 13:55-62; Crisfield 1991, vol. 1, ch. 9).  Every Newton iteration solves
K du_r = r and K du_p = P_ref and takes du = du_r + dlambda du_p, with dlambda the root of the
quadratic constraint that keeps the smallest angle with the increment so far.  The predictor
follows the direction of the previous increment (sign of Du_prev^T W du_p), which carries the
path through limit points and snap-backs.  The arc length adapts: dl <- dl sqrt(I_d / I) with I
the iterations of the last increment and I_d the desired number; a failed increment (no real
root, no convergence) is retried with a quarter of dl.

The step ends when lambda reaches ``max_load_factor``, when the ``monitor`` DOF reaches its
value, or after the step's ``max_increments`` (as Abaqus' *STATIC, RIKS).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from tqdm.auto import tqdm

from ...errors import ConvergenceError, ModelError
from ...model import dof_index, validation
from .plan import Increment, Plan, gravity_of, step_values, with_gravity


@dataclass
class ArcLength:
    """initial_load_factor : load-factor increment of the first predictor (sets the first arc
    length); max_load_factor : end the step when lambda reaches it; monitor : (node, dof, value),
    end the step when the DOF (m or rad) reaches value; desired_iterations : target Newton
    iterations per increment; min_arc, max_arc : bounds on dl relative to the first arc length;
    rotation_scale : m per rad in the arc-length norm (default: the model size)."""

    initial_load_factor: float = 0.05
    max_load_factor: float = 1.0
    monitor: tuple | None = None
    desired_iterations: int = 5
    min_arc: float = 1e-5
    max_arc: float = 20.0
    rotation_scale: float | None = None
    solves_for_load_factor = True
    arc_length = True

    def __post_init__(self):
        """Every bound a finite number in its range, or a ModelError naming it (a NaN bound would let
        the arc length shrink, or grow, without end)."""
        w = "ArcLength:"
        self.initial_load_factor = validation.number(
            self.initial_load_factor, f"{w} initial_load_factor", positive=True
        )
        self.max_load_factor = validation.number(self.max_load_factor, f"{w} max_load_factor")
        self.desired_iterations = validation.whole(self.desired_iterations, f"{w} desired_iterations", minimum=1)
        self.min_arc = validation.number(self.min_arc, f"{w} min_arc", positive=True, hi=1.0)
        self.max_arc = validation.number(self.max_arc, f"{w} max_arc", ge=1.0)
        if self.rotation_scale is not None:
            self.rotation_scale = validation.number(self.rotation_scale, f"{w} rotation_scale", "m", positive=True)

    def plan(self, analysis, step):
        return ArcIncrements(analysis, step, self)

    def setup(self, analysis, step):
        if not step.loads and getattr(step, "gravity_spec", None) is None:
            raise ModelError(
                f"step '{step.name}': arc-length control needs a reference load pattern; "
                "define at least one load (or gravity) in the step"
            )
        if step.prescribed:
            raise ModelError(
                f"step '{step.name}': arc-length control with prescribed displacements is not "
                "supported; drive the model by loads in this step"
            )
        if step.stabilize is not None:
            raise ModelError(f"step '{step.name}': stabilisation cannot be combined with arc-length control")
        if not (self.initial_load_factor > 0):
            raise ModelError(f"step '{step.name}': initial_load_factor must be positive")
        s = self.rotation_scale or analysis.length
        self.weights = np.where(analysis.is_rot, s * s, 1.0)
        self.monitor_slot = None
        if self.monitor is not None:
            node, dof, value = self.monitor
            idx, d = analysis.model.index(node), dof_index(dof)
            self.monitor_slot = (idx, d)
            self.monitor_start = analysis.dof_value(idx, d)
            self.monitor_value = float(value)

    def norm2(self, v):
        return float(v @ (self.weights * v))

    def correction(self, Du, du_r, du_p, dl):
        """dlambda for the corrector, or None when the constraint has no real root."""
        w = self.weights
        a = float(du_p @ (w * du_p))
        v = Du + du_r
        b = 2.0 * float(v @ (w * du_p))
        c = float(v @ (w * v)) - dl * dl
        disc = b * b - 4 * a * c
        if disc < 0 or a == 0:
            return None
        sq = math.sqrt(disc)
        roots = ((-b + sq) / (2 * a), (-b - sq) / (2 * a))
        # the root whose new increment keeps the smallest angle with the increment so far
        return max(roots, key=lambda d: float((v + d * du_p) @ (w * Du)))

    def progress(self, analysis, lam):
        """Fraction of the step done (0..1), from the load factor or the monitored DOF."""
        frac = lam / self.max_load_factor if self.max_load_factor else 0.0
        if self.monitor_slot is not None:
            cur = analysis.dof_value(*self.monitor_slot)
            span = self.monitor_value - self.monitor_start
            if span != 0:
                frac = max(frac, (cur - self.monitor_start) / span)
        return frac


class ArcIncrements(Plan):
    """The increments of an arc-length step (:class:`ArcLength`)."""

    def __init__(self, analysis, step, control):
        super().__init__(analysis, step, control)
        st = self.state
        self.load_start = st.loads.copy()
        gravity = gravity_of(analysis, step)
        if gravity is not None and gravity[2] is not None:
            raise ModelError(f"step '{step.name}': a gravity amplitude cannot be used with arc length")
        user_start = self.load_start if gravity is None else self.load_start - gravity[0]
        P_end = with_gravity(step_values(analysis.model, step.loads, user_start, 1.0, step.period), gravity, 1.0, 1.0)
        self.P_ref = P_end - self.load_start
        st.lam = 0.0
        st.size = st.first_size = None  # the first arc length comes from the first predictor
        st.step_time = 0.0
        st.last_increment = None
        self.finished = False

    def bar(self, disable):
        return tqdm(
            total=1.0,
            desc=f"step {self.step.name} (arc length)",
            disable=disable,
            leave=False,
            bar_format="{desc}: {percentage:3.0f}%|{bar}| [{elapsed}<{remaining}]",
        )

    def done(self) -> bool:
        return self.finished

    def _predict(self, du_p):
        """Load-factor predictor: the arc length along the tangent, in the previous increment's direction."""
        st, control = self.state, self.control
        norm_p = math.sqrt(control.norm2(du_p))
        if st.size is None:
            st.size = control.initial_load_factor * norm_p
        sign = 1.0
        if st.last_increment is not None:
            sign = 1.0 if float(st.last_increment @ (control.weights * du_p)) >= 0 else -1.0
        return sign * st.size / norm_p

    def _correct(self, du_r, du_p, Du):
        return self.control.correction(Du, du_r, du_p, self.state.size)

    def propose(self, attempt) -> Increment:
        st = self.state
        return Increment(
            time=st.lam,
            dtime=0.0,
            total_time=st.total_time,
            step_name=self.step.name,
            lam=st.lam,
            P_start=self.load_start,
            P_ref=self.P_ref,
            predict=self._predict,
            dlambda=self._correct,
            direct=False,
        )

    def trial(self):
        st = self.state
        return st.lam, st.total_time, st.size, st.lam

    def cutback(self, note):
        an, st, control = self.an, self.state, self.control
        if st.first_size is None:
            st.first_size = st.size
        st.size *= an.cutback
        if st.size < control.min_arc * st.first_size:
            raise ConvergenceError(
                f"step '{self.step.name}': arc length fell below the minimum ({control.min_arc:g} of the first) "
                f"at load factor {st.lam:.6g}: {note}. The {an.summary.increments} converged "
                f"increments are {an.kept()}."
            )

    def accept(self, outcome):
        an, st, control = self.an, self.state, self.control
        if st.first_size is None:
            st.first_size = st.size
        dl = st.size
        st.total_time += dl / st.first_size * control.initial_load_factor
        st.step_time = st.lam
        self.frac = control.progress(an, st.lam)
        self.finished = self.frac >= 1.0 - 1e-12 or st.increment >= self.step.max_increments
        return st.lam, dl, self.finished, f"arc length {dl:.4g}"

    def grow(self, outcome, bar):
        st, control = self.state, self.control
        bar.n = min(max(self.frac, 0.0), 1.0)
        bar.refresh()
        dl = st.size * min(max(math.sqrt(control.desired_iterations / max(outcome.iterations, 1)), 0.5), 2.0)
        st.size = min(max(dl, control.min_arc * st.first_size), control.max_arc * st.first_size)

    def finish(self, info):
        info["final_load_factor"] = self.state.lam
        return info
