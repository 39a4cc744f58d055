"""Load control: the load level follows the step time (the default control of a step).

* :class:`LoadControl`: the user's choice (no parameters: the step's own increment options).
* :class:`TimeIncrements`: its plan, shared with displacement control (:mod:`.displacement`).  The
  step time runs from 0 to the step's period; loads and prescribed values follow it (or, under
  displacement control, the loads are ``P_start + lambda P_ref`` with lambda fixed by the
  controlled DOF).  A failed increment is retried with ``cutback`` x its size (Abaqus: 0.25); after
  two easy increments the size grows by ``growth`` (1.5); the increment lands on the step's hit
  times and amplitude breakpoints.  A stabilised step adds the viscous term of :mod:`.stabilize`.
"""

from __future__ import annotations

import warnings

from tqdm.auto import tqdm

from ...errors import ConvergenceError, ModelError
from .plan import Increment, Plan, _rows, _values, gravity_of, with_gravity
from .stabilize import StabilizationWarning, ViscousTerm


class LoadControl:
    """Load level = step time fraction (no extra unknown)."""

    solves_for_load_factor = False

    def setup(self, analysis, step):
        pass

    def plan(self, analysis, step):
        return TimeIncrements(analysis, step, self)


class TimeIncrements(Plan):
    """The increments of a load- or displacement-controlled step (see module docstring)."""

    def __init__(self, analysis, step, control):
        super().__init__(analysis, step, control)
        st = self.state
        period = self.period = step.period
        self.dt_min = step.min_increment or period * 1e-5
        self.dt_max = step.max_increment or period
        self.uses_lam = control.solves_for_load_factor
        self.gravity = gravity_of(analysis, step)
        g_amp = None if self.gravity is None else self.gravity[2]
        if self.uses_lam and (g_amp is not None or any(c.amplitude is not None for c in step.loads)):
            raise ModelError(
                f"step '{step.name}': amplitudes cannot be used with {type(control).__name__}; "
                "the load factor is an unknown"
            )
        self.hit = sorted(
            {float(h) for h in step.hit_times}
            | {
                float(t)
                for c in step.loads + step.prescribed
                if c.amplitude is not None
                for t in c.amplitude.times
                if 0 < t < period
            }
            | {
                float(t)
                for _, _, amp in getattr(step, "temperatures", ())
                if amp is not None
                for t in amp.times
                if 0 < t < period
            }
            | {float(t) for t in (g_amp.times if g_amp is not None else ()) if 0 < t < period}
        )  # temperature and gravity amplitudes
        # the concentrated loads at the step's start (the applied loads less the gravity)
        self.load_start = st.loads.copy() if self.gravity is None else st.loads - self.gravity[0]
        self.pres_start = st.prescribed.copy()
        self.load_rows, self.pres_rows = _rows(analysis.model, step.loads), _rows(analysis.model, step.prescribed)
        sys_ = analysis.system
        # the constrained DOFs that are not fixed (prescribed in some step); none: every increment's
        # dpres is zero, and passed as None (nothing to apply, no coupling term)
        self.moving = ~sys_.fixed[sys_.cons_node, sys_.cons_dof]
        self.any_moving = bool(self.moving.any())
        st.size = st.first_size = step.initial_increment or min(period, step.max_increment or period)
        st.step_time, st.easy, st.lam = 0.0, 0, 0.0
        st.last_increment = None
        st.damping = None
        st.stabilization_energy = 0.0
        self.viscous = (
            ViscousTerm(step.stabilize, st, sys_.is_rot, st.first_size, sys_.plus_diagonal)
            if step.stabilize is not None
            else None
        )

    def bar(self, disable):
        return tqdm(
            total=self.period,
            desc=f"step {self.step.name}",
            unit="s",
            disable=disable,
            leave=False,
            bar_format="{desc}: {percentage:3.0f}%|{bar}| t={n:.4g}/{total:.4g} [{elapsed}<{remaining}]",
        )

    def done(self) -> bool:
        st, step = self.state, self.step
        if not st.step_time < self.period * (1 - 1e-12):
            return True
        if st.increment >= step.max_increments:
            raise ConvergenceError(
                f"step '{step.name}': reached max_increments={step.max_increments} at step "
                f"time {st.step_time:.6g} of {self.period:g} s; raise max_increments or "
                "max_increment"
            )
        return False

    def next_increment(self):
        """Size the coming increment: not beyond the step's end, its maximum or the next hit time."""
        st, period = self.state, self.period
        t = st.step_time
        dt = min(st.size, self.dt_max, period - t)
        for h in self.hit:
            if t + 1e-12 * period < h < t + dt - 1e-12 * period:
                dt = h - t
                break
        st.size = dt

    def propose(self, attempt) -> Increment:
        an, st, step, period = self.an, self.state, self.step, self.period
        sys_ = an.system
        t, dt = st.step_time, st.size
        frac = (t + dt) / period
        fields = getattr(an, "fields", None)
        if fields is not None and fields.set(st.step, frac):
            # the element properties changed (temperature): the committed response is not this one's
            sys_.last_converged = None
            st.at_equilibrium = False
        inc = Increment(
            time=t + dt, dtime=dt, total_time=st.total_time + dt, step_name=step.name, lam=frac, viscous=self.viscous
        )
        if self.uses_lam:
            inc.lam = st.lam
            P_end = with_gravity(_values(self.load_rows, self.load_start, 1.0, period), self.gravity, 1.0, period)
            P_start = with_gravity(self.load_start, self.gravity, 0.0, period)
            inc.P_start, inc.P_ref = P_start, P_end - P_start
            eq, control = self.control.eq, self.control
            node, dof = sys_.free_node[eq], sys_.free_dof[eq]
            inc.dlambda = lambda du_r, du_p, Du: control.dlambda(du_r, du_p, sys_.dof_value(node, dof), frac)
        else:
            inc.P = with_gravity(_values(self.load_rows, self.load_start, frac, period), self.gravity, frac, period)
        dpres = None
        if self.any_moving:
            pres = _values(self.pres_rows, self.pres_start, frac, period)
            cn, cd = sys_.cons_node, sys_.cons_dof
            dpres = pres[cn, cd] - st.prescribed[cn, cd]
            dpres[~self.moving] = 0.0
        inc.dpres = dpres
        ref = getattr(an, "reference", None)
        pdu = None if ref is None or self.uses_lam else ref.predictor(st.step, st.total_time, st.total_time + dt)
        if pdu is not None and pdu.shape == (
            sys_.n_free,
        ):  # a reference run's converged increment (femast.analysis.reference)
            inc.predictor, inc.whole = (pdu, 0.0), True
        elif an.extrapolate and st.last_increment is not None and (dpres is None or not dpres.any()):
            # Abaqus' linear extrapolation: start from the previous increment's solution, scaled
            scale = dt / st.last_size
            inc.predictor = (scale * st.last_increment, scale * st.last_dlam)
        return inc

    def trial(self):
        """(step time, total time, size, load factor) of the increment being tried, for status lines."""
        st = self.state
        return st.step_time + st.size, st.total_time + st.size, st.size, st.lam

    def cutback(self, note):
        an, st, step = self.an, self.state, self.step
        st.size *= an.cutback
        st.easy = 0
        if st.size < self.dt_min:
            raise ConvergenceError(
                f"step '{step.name}': increment fell below the minimum {self.dt_min:.3g} s at step time "
                f"{st.step_time:.6g} s (total time {st.total_time:.6g} s): {note}. The {an.summary.increments} "
                f"converged increments are {an.kept()}."
            )

    def accept(self, outcome):
        """Advance past a converged increment; returns (step time, size, last of the step, status note)."""
        st, dt = self.state, self.state.size
        st.step_time += dt
        st.total_time += dt
        last = not st.step_time < self.period * (1 - 1e-12)
        note = ""
        if self.step.stabilize is not None:
            note = (
                f"stabilisation/strain energy {self.stabilization_ratio:.3g}, largest viscous force "
                f"{st.stabilization_force:.3g} N, moment {st.stabilization_moment:.3g} N m"
            )
        return st.step_time, dt, last, note

    def grow(self, outcome, bar):
        st = self.state
        bar.update(st.size)
        st.easy = st.easy + 1 if outcome.iterations <= self.an.easy_iterations else 0
        if st.easy >= 2:
            st.size *= self.an.growth

    @property
    def stabilization_ratio(self) -> float:
        st = self.state
        return (
            st.stabilization_energy / st.strain_energy
            if st.strain_energy > 0
            else (0.0 if st.stabilization_energy == 0 else float("inf"))
        )

    def finish(self, info):
        st, step = self.state, self.step
        if step.stabilize is not None:
            info["stabilization_energy"] = st.stabilization_energy
            info["stabilization_ratio"] = ratio = self.stabilization_ratio
            # viscous forces left in the last increment: how far from equilibrium the end state is
            info["stabilization_force"], info["stabilization_moment"] = (
                st.stabilization_force,
                st.stabilization_moment,
            )
            if ratio > step.stabilize.warn_ratio:
                msg = (
                    f"step '{step.name}': stabilisation energy is {100 * ratio:.1f}% of the strain "
                    f"energy (above {100 * step.stabilize.warn_ratio:.0f}%): the stabilised solution may be "
                    "far from equilibrium; lower the damping factor or the energy fraction"
                )
                warnings.warn(msg, StabilizationWarning, stacklevel=4)
                if self.an.progress:
                    tqdm.write("femast: warning: " + msg)
        return info
