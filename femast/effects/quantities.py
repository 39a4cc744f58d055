"""The physical quantities an experiment's model shows to effects (the effect contract).

An experiment declares, in ``Experiment.quantities``, which of these its model provides:

==============  ==========================================================================
kind            what it is
==============  ==========================================================================
``load``        the load through the mechanism: a force or a moment, one value per row
                ``(n,)`` or one per axis ``(n, k)``; the model passes it through
                ``effects.apply("load", value)`` before its elastic part sees it
``displacement`` the displacement (or rotation) that load drives, same shape; the model
                passes it through ``effects.apply("displacement", value)``
``temperature`` a data column with the temperature of each row (declared with ``column``)
==============  ==========================================================================

Time needs no declaration: every experiment provides it (the ``t_s`` column, else the row
index).  An effect built on these quantities (an implementation with ``needs``, see
:mod:`femast.effects.base`) applies to every experiment that declares them -- the built-in rigs
and a user's own -- and names and sizes its parameters from them: a clearance's gap takes the
displacement's unit, a friction threshold is called ``M_f`` on a moment and ``F_f`` on a force,
a per-axis form has one parameter per axis (``c_x``, ``c_y``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ModelError

HOOKS = ("load", "displacement")  # the quantities the model passes through effects.apply
ALWAYS = ("time",)  # what every experiment provides without declaring it
KINDS = (*HOOKS, "temperature")


@dataclass(frozen=True)
class Quantity:
    """A physical quantity an experiment's model provides to effects.

    unit : its unit ("N m", "rad", "N", "mm", "degC").
    axes : names of the columns of an ``(n, k)`` value (``("x", "y")``); ``()`` for an ``(n,)`` value.
    symbol : the letter parameter names use for it ("M" a moment, "F" a force; default "M" for a
        load in N m, "F" for other loads).
    scale : its typical magnitude in ``unit`` (a load: the largest load of the test; a
        displacement: the largest displacement): the effects size their parameters' defaults,
        bounds and starts with it.
    column : for ``temperature``, the data column that holds it.
    doc : what it is on this rig ("moment about the base axes", "slip of the connection").
    """

    unit: str
    axes: tuple = ()
    symbol: str = ""
    scale: float = 1.0
    column: str = ""
    doc: str = ""

    def __post_init__(self):
        if not (isinstance(self.scale, (int, float)) and math.isfinite(self.scale) and self.scale > 0):
            raise ModelError(f"quantity in {self.unit}: scale must be a finite number > 0, got {self.scale!r}")
        if len(set(self.axes)) != len(self.axes):
            raise ModelError(f"quantity in {self.unit}: duplicate axis names {self.axes}")

    @property
    def letter(self) -> str:
        """The symbol of its parameters ("M" for a moment in N m unless given, else "F")."""
        if self.symbol:
            return self.symbol
        return "M" if self.unit.replace(" ", "").replace("*", "").lower() in ("nm", "knm") else "F"

    @property
    def n_axes(self) -> int:
        """Number of axes (1 for an (n,) value)."""
        return max(len(self.axes), 1)


def check_quantities(owner: str, quantities: dict) -> dict:
    """``quantities`` checked: known kinds, :class:`Quantity` values, a temperature with its column,
    load and displacement with the same axes.  Returns it as a plain dict."""
    quantities = dict(quantities or {})
    for kind, q in quantities.items():
        if kind not in KINDS:
            raise ModelError(f"{owner}: unknown quantity '{kind}'; accepted: {', '.join(KINDS)}")
        if not isinstance(q, Quantity):
            raise ModelError(f"{owner}: quantity '{kind}' must be a femast.effects.Quantity, got {type(q).__name__}")
    t = quantities.get("temperature")
    if t is not None and not t.column:
        raise ModelError(f"{owner}: the temperature quantity needs the data column that holds it (column=...)")
    load, disp = quantities.get("load"), quantities.get("displacement")
    if load is not None and disp is not None and load.axes != disp.axes:
        raise ModelError(
            f"{owner}: the load (axes {load.axes}) and the displacement it drives (axes {disp.axes}) need the same axes"
        )
    return quantities


def unit_inverse(unit: str, power: int = 1) -> str:
    """``1/(unit)`` or ``1/(unit)^power`` as text."""
    u = unit if " " not in unit and "/" not in unit else f"({unit})"
    return f"1/{u}" + (f"^{power}" if power != 1 else "")
