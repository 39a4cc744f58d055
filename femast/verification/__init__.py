"""Verification of the FE core against independent references (docs/verification.md).

* :mod:`.cases`: the classic static cases (:class:`Check` rows), shared by tests and
  ``benchmarks/verification.py``;
* :mod:`.arclength`: the arc-length cases; :mod:`.modal`: the modal cases;
* :mod:`.references`: the independent reference solutions (closed forms, published values).

``femast.verification`` was one module before the package move; its names are
re-exported here.
"""

from . import references
from .cases import Check, all_cases, bend45, elastica, euler_column, format_table, linear_compliance, roll_up

__all__ = [
    "Check",
    "all_cases",
    "bend45",
    "elastica",
    "euler_column",
    "format_table",
    "linear_compliance",
    "roll_up",
    "references",
]
