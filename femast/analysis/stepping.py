"""The step loop: one for every control strategy.

For each step, the step's control strategy makes a plan (controls.py); the loop asks it for
increments, has the algorithm (newton.py) solve each one, retries failed attempts smaller
(cutbacks) and tells the observers (output.py) about every cutback and converged increment.
"""

from __future__ import annotations

from .. import progress as _progress
from ..errors import ConvergenceError
from .control import LoadControl, plan_for


def run_step(analysis, step, resume=None):
    """Walk ``step`` of ``analysis`` from its committed state to the step's end (or raise
    :class:`~femast.errors.ConvergenceError` when an increment cannot be made small enough).
    ``resume``: a restart point inside this step (restart.py): the plan is made as at the step's
    start, then the saved state and the step's start loads are put back."""
    an, st, summary = analysis, analysis.state, analysis.summary
    control = step.control or LoadControl()
    control.setup(an, step)
    if resume is not None:
        an.state.loads, an.state.prescribed = resume["step_start"][0].copy(), resume["step_start"][1].copy()
    plan = plan_for(an, step, control)
    an.algorithm.new_step()
    st.increment = 0
    step_iters = 0
    if resume is not None:
        from .restart import restore

        restore(an, resume)
        step_iters = resume["summary"]["step_iterations"]
    bar = plan.bar(disable=not (an.progress and _progress.enabled()))  # no bar when not on a terminal
    cutbacks = 0  # of this step: at most an.max_cutbacks (a step that never converges ends)
    try:
        while not plan.done():
            plan.next_increment()
            attempt = 0
            while True:
                attempt += 1
                out = an.algorithm.solve(an.system, st, plan.propose(attempt), attempt)
                step_iters += out.iterations
                summary.iterations += out.iterations
                if out.ok:
                    break
                time, total_time, dtime, lam = plan.trial()
                for obs in an.observers:
                    obs.cutback(
                        an, step, st.increment + 1, attempt, out.iterations, time, total_time, dtime, lam, out.note
                    )
                summary.cutbacks += 1
                cutbacks += 1
                if cutbacks >= an.max_cutbacks:
                    raise ConvergenceError(
                        f"step '{step.name}': {cutbacks} cutbacks in this step (max_cutbacks = {an.max_cutbacks}) at "
                        f"step time {st.step_time:.6g}: {out.note}. The {summary.increments} converged increments "
                        f"are {an.kept()}."
                    )
                plan.cutback(out.note)
            st.increment += 1
            summary.increments += 1
            time, dtime, last, note = plan.accept(out)
            for obs in an.observers:
                obs.converged(an, step, st.increment, attempt, out.iterations, time, dtime, last, out.responses, note)
            plan.grow(out, bar)
    finally:
        bar.close()
    summary.steps.append(plan.finish({"name": step.name, "increments": st.increment, "iterations": step_iters}))
