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
* :mod:`.plan`: the :class:`Plan` base every plan extends, :func:`plan_for`, :func:`step_values`.
"""

from .arclength import ArcIncrements, ArcLength
from .displacement import DisplacementControl
from .load import LoadControl, TimeIncrements
from .plan import Plan, plan_for, step_values
from .stabilize import Stabilize, ViscousTerm

__all__ = [
    "ArcIncrements",
    "ArcLength",
    "DisplacementControl",
    "LoadControl",
    "TimeIncrements",
    "Plan",
    "plan_for",
    "step_values",
    "Stabilize",
    "ViscousTerm",
]
