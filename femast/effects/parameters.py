"""A fittable parameter of a model or of an effect: name, unit, default, bounds, typical size."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ModelError


@dataclass(frozen=True)
class Parameter:
    """A fittable parameter of a model or of an effect.

    name : identifier (used in JSON reports and as ``params[name]``).
    unit : its SI unit as text ("N m/rad", "m", "-").
    default : value used without ``--fit`` and as the start of a fit.
    lower, upper : bounds of the fit (same unit).
    doc : one line of physics.
    scale : typical magnitude, used to scale the fit (default ``|default|`` or 1).
    starts : extra start values tried by the fit (multi-start for non-convex effects).
    """

    name: str
    unit: str
    default: float
    lower: float = -math.inf
    upper: float = math.inf
    doc: str = ""
    scale: float | None = None
    starts: tuple = ()

    def __post_init__(self):
        if not (self.lower <= self.default <= self.upper):
            raise ModelError(
                f"parameter {self.name}: default {self.default!r} {self.unit} lies outside its "
                f"bounds [{self.lower!r}, {self.upper!r}]"
            )
        for s in self.starts:
            if not (self.lower <= s <= self.upper):
                raise ModelError(
                    f"parameter {self.name}: start {s!r} {self.unit} lies outside its bounds "
                    f"[{self.lower!r}, {self.upper!r}]; give starts within the bounds"
                )

    @property
    def typical(self) -> float:
        """Magnitude used to scale the fit, in the parameter's unit."""
        if self.scale:
            return float(self.scale)
        return abs(float(self.default)) or 1.0
