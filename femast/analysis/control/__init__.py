"""Control strategies: what fixes the load level of each increment, and how a step is walked.

Each strategy's module holds the user's parameters and the step's plan together:

* :mod:`.load`: :class:`LoadControl` (the default: the load level follows the step time) and its
  plan :class:`TimeIncrements` (sizes, cutbacks, growth, hit times);
* :mod:`.displacement`: :class:`DisplacementControl` (one DOF ramps; the load factor is an unknown),
  walked by the same time increments;
* :mod:`.arclength`: :class:`ArcLength` (Crisfield's cylindrical arc length) and
  :class:`ArcIncrements`;
* :mod:`.stabilize`: :class:`Stabilize` (viscous stabilisation of a step, Abaqus *STABILIZE) and
  the :class:`ViscousTerm` the Newton loop adds;
* :mod:`.plan`: the :class:`Plan` base every plan extends, the :class:`Increment` a plan proposes to the
  Newton loop (the strategies import nothing else of the analysis), :func:`step_values`;
* :func:`plan_for`: the plan of a step under a control.
"""

from .arclength import ArcIncrements, ArcLength
from .displacement import DisplacementControl
from .load import LoadControl, TimeIncrements
from .plan import Increment, Plan, step_values
from .stabilize import Stabilize, ViscousTerm


def plan_for(analysis, step, control):
    """The plan of ``step`` under ``control``: the control's own (its ``plan`` method); a control
    without one gets the time increments of load control (or the arc-length plan if its
    ``arc_length`` attribute is true)."""
    if hasattr(control, "plan"):
        return control.plan(analysis, step)
    if getattr(control, "arc_length", False):
        return ArcIncrements(analysis, step, control)
    return TimeIncrements(analysis, step, control)


__all__ = [
    "ArcIncrements",
    "ArcLength",
    "Increment",
    "DisplacementControl",
    "LoadControl",
    "TimeIncrements",
    "Plan",
    "plan_for",
    "step_values",
    "Stabilize",
    "ViscousTerm",
]
