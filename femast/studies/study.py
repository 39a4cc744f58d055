"""A study: a model factory, its uncertain inputs, the outputs to record and the sampling design.
:func:`femast.studies.run` runs it; ``femast study SCRIPT`` runs the ``study`` of a
script.

Two ways to say what one sample is:

* ``model=factory``: ``factory(**values)`` builds and returns a femast :class:`~femast.Model`
  with its load history (steps); femast runs it (``Analysis(model, None, **analysis)``) and
  records the :class:`~femast.studies.outputs.NodeOutput` / ``ElementOutput`` list ``outputs``
  at the ends of their steps.  Everything is checked against the model built at the inputs'
  medians before any sample runs.
* ``run=function``: ``function(**values)`` does the whole sample itself and returns a dict of
  named floats or arrays; ``outputs`` lists the names it must return (checked on every sample).

``values`` has one keyword per input: a float for a scalar input, an array of ``size`` values for
a per-member input.  A sample that raises (a :class:`~femast.errors.ConvergenceError`, any femast
error, any exception) is recorded as failed with its reason; it never stops the study.
"""

from __future__ import annotations

import inspect

import numpy as np

from ..errors import FemastError, StudyError
from .distributions import check_inputs
from .outputs import ElementOutput, NodeOutput, Recorder, family_outputs
from .sampling import Design


class Study:
    """A study definition (see the module docstring).

    inputs : list of :class:`~femast.studies.distributions.Input` (Normal, Uniform, ...).
    outputs : with ``model=``: NodeOutput / ElementOutput objects; with ``run=``: output names.
    sampler, seed, sensitivity, correlation : the design (:class:`~femast.studies.sampling.Design`).
    analysis : options of :class:`~femast.Analysis` for ``model=`` studies (e.g. convergence).
    units : {output name: unit} for tables and figures (``run=`` studies; node outputs know theirs).
    timeout_s : wall-clock seconds after which a sample is stopped and recorded as failed
        (SampleTimeout); None: no limit.  Everywhere the analyses check it at each Newton
        iteration (a thread's deadline: dask workers too); in this process and in local workers a
        SIGALRM timer (Unix) also stops other code (a ``run=`` function's own loops).  On dask
        workers a ``run=`` function that runs no femast analysis is not stopped.
    name : a label for summaries and figures.
    """

    def __init__(
        self,
        model=None,
        *,
        run=None,
        inputs,
        outputs,
        sampler: str = "sobol",
        seed: int = 1,
        sensitivity: bool = False,
        correlation: dict | None = None,
        analysis: dict | None = None,
        units: dict | None = None,
        timeout_s: float | None = None,
        name: str = "study",
    ):
        if (model is None) == (run is None):
            raise StudyError(
                "give a study either model=FACTORY (returns a femast Model; femast runs it) or "
                "run=FUNCTION (runs a sample, returns a dict of outputs), not both / neither"
            )
        fn = model if model is not None else run
        if not callable(fn):
            raise StudyError(
                f"{'model' if model is not None else 'run'} = {fn!r} is not callable; give a function of the inputs"
            )
        self.factory, self.runner = model, run
        self.inputs = check_inputs(inputs)
        self.design = Design(self.inputs, sampler=sampler, seed=seed, sensitivity=sensitivity, correlation=correlation)
        outputs = list(outputs)
        if not outputs:
            raise StudyError("a study needs at least one output to record")
        if model is not None:
            for o in outputs:
                if not isinstance(o, (NodeOutput, ElementOutput)):
                    raise StudyError(
                        f"output {o!r}: a model= study records NodeOutput or ElementOutput objects "
                        "(a run= study returns named values instead)"
                    )
            names = [o.name for o in outputs]
        else:
            for o in outputs:
                if not isinstance(o, str) or not o.isidentifier():
                    raise StudyError(
                        f"output {o!r}: a run= study lists the names (identifiers) of the values its function returns"
                    )
            names = list(outputs)
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise StudyError(f"output name(s) {', '.join(sorted(dup))} given twice; output names must be unique")
        clash = set(names) & {x.name for x in self.inputs}
        if clash:
            raise StudyError(f"{', '.join(sorted(clash))}: both an input and an output; rename one")
        self.outputs = outputs
        self.output_names = names
        self.units = {o.name: o.unit for o in outputs} if model is not None else {n: "" for n in names}
        for k, u in (units or {}).items():
            if k not in self.units:
                raise StudyError(f"units: '{k}' is not an output of the study (outputs: {', '.join(names)})")
            self.units[k] = str(u)
        self.analysis = dict(analysis or {})
        self.name = str(name)
        if timeout_s is not None:
            try:
                timeout_s = float(timeout_s)
            except (TypeError, ValueError):
                timeout_s = -1.0
            if not timeout_s > 0.0 or timeout_s != timeout_s:
                raise StudyError("timeout_s must be a number of seconds > 0 (or None: no limit)")
        self.timeout_s = timeout_s
        self.labels = {}  # output name -> names along each axis (model= studies, set by check())
        self._checked = False

    # ------------------------------------------------------------ checks (before any sample)
    def nominal_values(self) -> dict:
        """Every input at its median (a per-member input: size copies)."""
        return {x.name: (x.nominal if x.size is None else np.full(x.size, x.nominal)) for x in self.inputs}

    def check(self) -> None:
        """Check the inputs against the factory's parameters and (``model=``) the outputs against the
        model built at the nominal values; raises :class:`StudyError` naming the item and the fix."""
        fn = self.factory if self.factory is not None else self.runner
        what = "model factory" if self.factory is not None else "run function"
        fname = getattr(fn, "__name__", repr(fn))
        try:
            sig = inspect.signature(fn)
        except (TypeError, ValueError):
            sig = None
        if sig is not None:
            params = sig.parameters
            var_kw = any(p.kind is p.VAR_KEYWORD for p in params.values())
            accepted = [n for n, p in params.items() if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]
            if not var_kw:
                for x in self.inputs:
                    if x.name not in accepted:
                        raise StudyError(
                            f"input '{x.name}' matches nothing in the {what} {fname}(): its parameters "
                            f"are {', '.join(accepted) or '(none)'}; rename the input or add a "
                            f"parameter '{x.name}' to {fname}()"
                        )
            names = {x.name for x in self.inputs}
            for n, p in params.items():
                if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) and p.default is p.empty and n not in names:
                    raise StudyError(
                        f"{fname}() needs '{n}', which no input of the study gives; add an input "
                        f"'{n}' or give the parameter a default"
                    )
        if self.factory is not None:
            model = self._build(self.nominal_values(), nominal=True)
            fams = (
                family_outputs(model, self.analysis)
                if any(isinstance(o, ElementOutput) for o in self.outputs)
                else None
            )
            for o in self.outputs:
                try:
                    o.check(model, fams)
                except FemastError as exc:
                    raise StudyError(str(exc) if isinstance(exc, StudyError) else f"output '{o.name}': {exc}") from None
            self.labels = {o.name: o.labels(model) for o in self.outputs}
        self._checked = True

    def _build(self, values, nominal=False):
        from ..model import Model

        try:
            model = self.factory(**values)
        except FemastError as exc:
            if nominal:
                raise StudyError(f"the model factory fails at the nominal inputs (medians): {exc}") from None
            raise
        if not isinstance(model, Model):
            raise StudyError(
                f"the model factory returned {type(model).__name__}, not a femast Model; return the "
                "model (with its steps), or use run= for a function that runs the sample itself"
            )
        if nominal and not model.steps:
            raise StudyError("the model factory's model has no steps; add the load history (model.step(...))")
        return model

    # ------------------------------------------------------------ one sample
    def evaluate(self, values: dict) -> dict:
        """Run one sample: {output name: float or array}.  Raises whatever the sample raises."""
        if self.factory is None:
            out = self.runner(**values)
            if not isinstance(out, dict):
                raise StudyError(
                    f"the run function returned {type(out).__name__}; return a dict of the outputs "
                    f"{', '.join(self.output_names)}"
                )
            missing = [n for n in self.output_names if n not in out]
            if missing:
                raise StudyError(
                    f"output(s) {', '.join(missing)} not returned by the run function (it returned "
                    f"{', '.join(map(str, out)) or 'nothing'}); return them or drop them from outputs"
                )
            return {n: _as_values(n, out[n]) for n in self.output_names}
        from ..analysis import Analysis

        model = self._build(values)
        rec = Recorder(model, self.outputs)
        opts = {k: v for k, v in self.analysis.items() if k not in ("progress", "on_frame")}
        Analysis(model, None, progress=False, on_frame=rec, **opts).run()
        return rec.values()

    def spec(self) -> dict:
        """Plain description (the manifest of the store: a resumed study must have the same)."""
        return {
            "name": self.name,
            "design": self.design.spec(),
            "outputs": self.output_names,
            "units": self.units,
            "labels": self.labels,
        }


def _as_values(name, v):
    a = np.asarray(v, dtype=float)
    return float(a) if a.ndim == 0 else a
