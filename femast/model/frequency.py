"""The ``frequency`` step of model scripts (Abaqus *FREQUENCY after a *STATIC step): its definition.

``model.frequency_step("modes", n_modes=10)`` appends a step that changes nothing: the analysis
computes the lowest ``n_modes`` modes of the state reached so far (the initial state if it is the
first step, else the end of the previous step: prestress, loads and joint/latch states included),
keeps them in ``analysis.modes[step name]`` and writes ``<results>/modes/<step name>.npz`` and
``.csv`` (:class:`femast.modal.Modes`), with ``vtk=True`` also the animated series
``<results>/modes/<step name>_vtk/mode_NN/series.pvd``.  The loads of the previous step stay
applied to the steps after it.  The step is defined here, with the model; the analysis runs it
with its ``runner``, :func:`femast.modal.step.run_frequency_step`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ModelError
from .step import Step


@dataclass
class FrequencyStep(Step):
    """A step that computes vibration modes of the current state (see the module docstring).

    n_modes : number of modes (lowest first).  shift_hz : find the modes nearest this frequency
    (Hz; default just below the lowest).  vtk : also write the animated VTK series."""

    n_modes: int = 10
    shift_hz: float | None = None
    vtk: bool = False
    kind = "frequency"
    #: what runs the step in an analysis ("module:function", called as function(analysis, step))
    runner = "femast.modal.step:run_frequency_step"

    def load(self, *a, **k):
        raise ModelError(
            f"step '{self.name}' is a frequency step: it applies no loads; put them in a static step before it"
        )

    def prescribe(self, *a, **k):
        raise ModelError(
            f"step '{self.name}' is a frequency step: it prescribes no motion; put it in a static step before it"
        )


def add_frequency_step(model, name=None, n_modes: int = 10, shift_hz: float | None = None, vtk: bool = False):
    """Append a :class:`FrequencyStep` to ``model`` (see the module docstring); returns it."""
    name = name or f"Step-{len(model.steps) + 1}"
    if any(s.name == name for s in model.steps):
        raise ModelError(f"step '{name}' is defined twice; step names must be unique")
    if isinstance(n_modes, bool) or not isinstance(n_modes, int) or n_modes < 1:
        raise ModelError(f"frequency step '{name}': n_modes = {n_modes!r} must be a whole number >= 1")
    if shift_hz is not None and not math.isfinite(float(shift_hz)):
        raise ModelError(f"frequency step '{name}': shift_hz = {shift_hz!r} must be a finite frequency (Hz)")
    s = FrequencyStep(name=name, n_modes=n_modes, shift_hz=shift_hz, vtk=bool(vtk))
    s._model = model
    model.steps.append(s)
    return s


def is_frequency_step(step) -> bool:
    return getattr(step, "kind", "static") == "frequency"
