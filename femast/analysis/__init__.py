"""The static analysis, in small parts with one job each (see docs/architecture.md).

* :mod:`.analysis`: :class:`Analysis` (set-up and the run) and :func:`solve`;
* :mod:`.system`: DOF numbering, constraints, assembly, linear solver (:class:`System`);
* :mod:`.state`: everything an increment commits, with commit / rollback / save / load (:class:`State`);
* :mod:`.newton`: the one Newton loop, for every control (:class:`Newton`, :class:`Increment`);
* :mod:`.convergence`: the convergence test of Newton iterations (:class:`Convergence`);
* :mod:`.control`: the control strategies, each with its increment plan (load, displacement, arc
  length, stabilisation);
* :mod:`.stepping`: the step loop (increments, cutbacks, observers);
* :mod:`.linalg`: the linear solvers of the tangent (sparse LU, orderings, LAPACK back-ends);
* :mod:`.output`: output as an observer (results writer, ``on_frame`` recorders);
* :mod:`.families`, :mod:`.summary`: element families from a model; the run summary.
"""

from .analysis import Analysis, solve
from .control.stabilize import StabilizationWarning
from .families import build_families
from .newton import Increment, Newton, Outcome
from .output import Observer, ResultsOutput
from .state import State
from .summary import AnalysisSummary
from .system import System

__all__ = [
    "Analysis",
    "solve",
    "build_families",
    "Increment",
    "Newton",
    "Outcome",
    "Observer",
    "ResultsOutput",
    "State",
    "AnalysisSummary",
    "StabilizationWarning",
    "System",
]
