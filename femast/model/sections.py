"""Beam cross-sections: elastic properties (SI units) and helpers for common shapes.

A :class:`Section` holds E (Pa), G (Pa), A (m^2), Iy, Iz (m^4, second moments about
the element's local y and z axes) and J (m^4, St Venant torsion constant).

Note on Eq. 10 of the Rocaspect paper.  The paper gives ``J = s_out L (s_out^2 + L^2) / 12`` for
the square-tube mast; that is the polar moment of a solid s_out x L plate, not a
torsion constant of the tube cross-section (it grows with the beam length L).
:func:`square_tube` uses Bredt's thin-walled formula for a closed section,
``J = 4 A_m^2 t / p_m = t (s - t)^3`` with s the outer side and t the wall
thickness (A_m, p_m area and perimeter enclosed by the wall mid-line), which is
also the thick-walled approximation of Roark's formulas for a square tube.
:func:`rocaspect_eq10_torsion_constant` keeps the printed formula for comparison.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, replace

from .._moved import renamed_attributes
from ..errors import ModelError
from .validation import MAX_MAGNITUDE, number

_UNITS = {"E": "Pa", "G": "Pa", "A": "m^2", "Iy": "m^4", "Iz": "m^4", "J": "m^4"}


@dataclass(frozen=True)
class Section:
    """Elastic beam section.

    Parameters
    ----------
    E : Young's modulus, Pa.
    G : shear modulus, Pa.
    A : area, m^2.
    Iy, Iz : second moments of area about local y and z, m^4.
    J : St Venant torsion constant, m^4.
    name : optional label used in messages and output.
    rho : density, kg/m^3 (default 0: massless; only modal analyses use it).  Give it
        with ``sec.with_(rho=2700.0)``.
    """

    E: float
    G: float
    A: float
    Iy: float
    Iz: float
    J: float
    name: str = "section"
    rho: float = 0.0

    def __post_init__(self):
        for field in ("E", "G", "A", "Iy", "Iz", "J"):
            value = getattr(self, field)
            if value is None:
                raise ModelError(f"section '{self.name}': property {field} is missing; give it in SI units")
            if isinstance(value, (str, bytes, bool)) or not isinstance(value, numbers.Real):
                raise ModelError(
                    f"section '{self.name}': property {field}={value!r} is not a number; give it in "
                    f"SI units ({_UNITS[field]})"
                )
            value = float(value)
            if not math.isfinite(value) or value <= 0.0:
                raise ModelError(
                    f"section '{self.name}': property {field}={value!r} must be a finite positive number (SI units)"
                )
            if value > MAX_MAGNITUDE:
                raise ModelError(
                    f"section '{self.name}': property {field}={value:g} {_UNITS[field]} is beyond "
                    f"{MAX_MAGNITUDE:g} (a typing error? it would overflow the stiffness); give it in "
                    "SI units"
                )
            object.__setattr__(self, field, value)
        try:
            rho = float(self.rho)
        except (TypeError, ValueError):
            raise ModelError(f"section '{self.name}': density rho={self.rho!r} is not a number (kg/m^3)") from None
        if not math.isfinite(rho) or rho < 0.0:
            raise ModelError(f"section '{self.name}': density rho={self.rho!r} kg/m^3 must be finite and >= 0")
        object.__setattr__(self, "rho", rho)

    @property
    def EA(self) -> float:
        """Axial stiffness, N."""
        return self.E * self.A

    def with_(self, **changes) -> Section:
        """A copy with some properties changed, e.g. ``sec.with_(E=70e9)``."""
        return replace(self, **changes)


def shear_modulus(E: float, nu: float, name: str = "section") -> float:
    """Isotropic shear modulus G = E / (2 (1 + nu)), Pa, of Young's modulus ``E`` (Pa).  Poisson's
    ratio ``nu`` must lie in (-1, 0.5] (an isotropic solid's range; -1 would make G infinite);
    ``name`` (the section's) labels the messages."""
    E = number(E, f"section '{name}': Young's modulus E", "Pa", positive=True)
    nu = number(nu, f"section '{name}': Poisson's ratio nu", "", lo=-1.0, hi=0.5)
    return E / (2.0 * (1.0 + nu))


def circular_solid(d: float, E: float, nu: float = 0.3, name: str = "circular solid") -> Section:
    """Solid circular section of diameter ``d`` (m); ``E`` in Pa, Poisson's ratio ``nu``; ``name``
    labels it in messages."""
    return circular_tube(d, 0.0, E, nu, name=name)


def circular_tube(
    d_out: float | None = None,
    d_in: float | None = None,
    E: float | None = None,
    nu: float = 0.3,
    name: str = "circular tube",
    *,
    d: float | None = None,
    t: float | None = None,
) -> Section:
    """Circular tube (a pipe) of outer diameter ``d_out`` and inner diameter ``d_in`` (m), or, by
    keyword, of outer diameter ``d`` and wall thickness ``t`` (m): ``circular_tube(d=0.03, t=0.002,
    E=70e9)`` is ``circular_tube(0.03, 0.026, E=70e9)``.  E in Pa, Poisson's ratio ``nu``; ``name``
    labels it in messages.

    J is the polar moment pi (d_out^4 - d_in^4) / 32, exact for circular sections.
    """
    d_out, d_in = _outer_inner(name, "d_out", "d_in", "d", d_out, d_in, d, t)
    _check_dims(name, d_out, d_in)
    _check_modulus(name, E)
    A = math.pi * (d_out**2 - d_in**2) / 4.0
    I = math.pi * (d_out**4 - d_in**4) / 64.0
    return Section(E=E, G=shear_modulus(E, nu, name), A=A, Iy=I, Iz=I, J=2.0 * I, name=name)


def square_solid(s: float, E: float, nu: float = 0.3, name: str = "square solid") -> Section:
    """Solid square of side ``s`` (m); ``E`` in Pa, Poisson's ratio ``nu``, ``name`` for messages;
    J = 0.1406 s^4 (St Venant, b/a = 1)."""
    _check_dims(name, s, 0.0)
    A = s * s
    I = s**4 / 12.0
    return Section(E=E, G=shear_modulus(E, nu, name), A=A, Iy=I, Iz=I, J=0.140577 * s**4, name=name)


def square_tube(
    s_out: float | None = None,
    s_in: float | None = None,
    E: float | None = None,
    nu: float = 0.3,
    name: str = "square tube",
    *,
    b: float | None = None,
    t: float | None = None,
) -> Section:
    """Square tube (a box section) of outer side ``s_out`` and inner side ``s_in`` (m), or, by
    keyword, of width ``b`` and wall thickness ``t`` (m), as steel tables give it:
    ``square_tube(b=0.03, t=0.002, E=70e9)`` is ``square_tube(0.03, 0.026, E=70e9)``.  E in Pa,
    Poisson's ratio ``nu``; ``name`` labels it in messages.

    A = s_out^2 - s_in^2 and I = (s_out^4 - s_in^4)/12 (the Rocaspect paper, Eqs. 11, 9).
    J = t (s_out - t)^3 with t = (s_out - s_in)/2 (Bredt; see the module note on the Rocaspect
    paper's Eq. 10).
    """
    s_out, s_in = _outer_inner(name, "s_out", "s_in", "b", s_out, s_in, b, t)
    _check_modulus(name, E)
    _check_dims(name, s_out, s_in)
    t = 0.5 * (s_out - s_in)
    A = s_out**2 - s_in**2
    I = (s_out**4 - s_in**4) / 12.0
    if s_in == 0.0:
        J = 0.140577 * s_out**4
    else:
        J = t * (s_out - t) ** 3
    return Section(E=E, G=shear_modulus(E, nu, name), A=A, Iy=I, Iz=I, J=J, name=name)


def rocaspect_eq10_torsion_constant(s_out: float, L: float) -> float:
    """Eq. 10 of the Rocaspect paper as printed, J = s_out L (s_out^2 + L^2) / 12 (m^4). Dimensionally
    an area moment but not a torsion constant of the section; kept only for comparison."""
    return s_out * L * (s_out**2 + L**2) / 12.0


def _outer_inner(name, outer_name, inner_name, width_name, outer, inner, width, t):
    """(outer, inner) size of a tube given either as ``outer, inner`` or as ``width=, t=`` (wall
    thickness): the two conventions of tube tables, never mixed."""
    if width is None and t is None:
        if outer is None or inner is None:
            raise ModelError(
                f"section '{name}': give {outer_name} and {inner_name} (outer and inner size, m), or "
                f"{width_name}= and t= (outer size and wall thickness, m)"
            )
        return outer, inner
    if outer is not None or inner is not None:
        raise ModelError(
            f"section '{name}': give {outer_name}, {inner_name} or {width_name}=, t= (outer size and wall "
            "thickness), not both"
        )
    if width is None or t is None:
        raise ModelError(f"section '{name}': give both {width_name}= (outer size, m) and t= (wall thickness, m)")
    for label, v in ((width_name, width), ("t", t)):
        if isinstance(v, (str, bytes, bool)) or not isinstance(v, numbers.Real) or not math.isfinite(v) or v <= 0:
            raise ModelError(f"section '{name}': {label}={v!r} must be a positive length in m")
    if 2 * t > width:
        raise ModelError(
            f"section '{name}': wall thickness t={t} m is more than half the outer size {width_name}={width} m"
        )
    return width, width - 2.0 * t


def _check_modulus(name, E):
    if E is None:
        raise ModelError(f"section '{name}': give Young's modulus E (Pa)")


def _check_dims(name, outer, inner):
    for label, v in (("outer size", outer), ("inner size", inner)):
        if (
            isinstance(v, (str, bytes, bool))
            or not isinstance(v, numbers.Real)
            or not math.isfinite(v)
            or v < 0
            or v > 1e3
        ):
            raise ModelError(
                f"section '{name}': {label}={v!r} must be a finite non-negative length in m (at most 1000 m)"
            )
    if outer <= 0 or inner >= outer:
        raise ModelError(f"section '{name}': need 0 <= inner ({inner}) < outer ({outer}) size, in m")


#: old names, kept for one release (they warn): femast 0.3 removes them
__getattr__ = renamed_attributes(__name__, {"seed000_eq10_torsion_constant": "rocaspect_eq10_torsion_constant"})
