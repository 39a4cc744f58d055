"""Units of measured data: headers in the user's units, and values whose size betrays a unit mistake.

* **Unit suffixes in headers are converted.**  A column named with another unit than the
  experiment's (``dx_mm``, ``dx_um``, ``fx_lbf``, ``rz_arcsec`` where mast-top reads ``dx_m``) is
  read as that column, its values converted by pint (a units library, not factors written here).
* **An override for a header that says the wrong unit**: ``--units dx_m=mm`` (``units={"dx_m":
  "mm"}`` in Python) reads the values of column ``dx_m`` as mm.  Naming a column's own unit
  (``--units dx_m=m``) confirms it and skips the size check of that column.
* **Sizes checked against the model** (:func:`check_scale`): each measured channel is compared
  with what the experiment's model predicts under the measured loads with its default
  parameters; the scale ``s`` that best maps the prediction onto the measurement (least squares,
  about the means) tells the unit the values are really in.  A scale near a unit factor of the
  channel's dimension (1000 for mm written as m, 1e6 for um, 25.4 mm and 39.37 in per m, 57.3 deg
  per rad, 206265 arcsec per rad, 0.225 lbf per N, 1000 N mm per N m...) stops compare and
  diagnose with a one-line :class:`~femast.errors.DataFileError` that names the channel, the
  likely unit and how to fix the header.  Factors of 20 and more are flagged when the shapes agree
  at all (correlation > 0.5) and the scale is within 2x of the factor (the nearest one: a default
  model may be off by some tens of percent; the tip-cycle example's x displacement: 0.74x), or when
  it is beyond 100x either way (no physical model error is that large); smaller ones (lbf, ft,
  lbf in) only when the shapes agree well (> 0.7) and the scale is within 5 % of the factor,
  since a default model may be off by a few times without any unit mistake (the tip-cycle
  example's rotations about y: 8.8x).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..errors import DataFileError
from .prediction import predict

# the unit a header suffix names, in pint's words ("dx_mm" -> "mm")
SUFFIXES = {
    "m": "m",
    "cm": "cm",
    "mm": "mm",
    "um": "um",
    "nm": "nm",
    "in": "inch",
    "inch": "inch",
    "ft": "ft",
    "N": "N",
    "kN": "kN",
    "mN": "mN",
    "lbf": "lbf",
    "kip": "kip",
    "Nm": "N*m",
    "Nmm": "N*mm",
    "kNm": "kN*m",
    "lbfin": "lbf*inch",
    "lbfft": "lbf*ft",
    "rad": "rad",
    "mrad": "mrad",
    "urad": "urad",
    "deg": "deg",
    "arcmin": "arcmin",
    "arcsec": "arcsec",
    "Hz": "Hz",
    "kHz": "kHz",
    "s": "s",
    "ms": "ms",
    "K": "K",
    "Pa": "Pa",
    "kPa": "kPa",
    "MPa": "MPa",
    "kg": "kg",
    "g": "g",
}

# unit mistakes worth naming, by the dimension of the column's unit: (unit the values may really
# be in, its pint name).  The scale measured/model of a column in unit U whose values are in V
# is the number of V in one U.
_LIKELY = {
    "[length]": ("mm", "um", "cm", "inch", "m"),  # (not ft: 3.28x is within a default model's reach)
    "[force]": ("kN", "lbf", "mN", "N"),
    "[torque]": ("N*mm", "kN*m", "lbf*inch", "N*m"),
    "[angle]": ("deg", "mrad", "arcsec", "arcmin", "urad", "rad"),
    "[frequency]": ("kHz", "mHz", "Hz"),  # (pint reads rpm and rad/s with rad = 1: no 2 pi)
}
BIG = 20.0  # scales of at least this (or at most 1/BIG) are flagged when the shapes agree at all
SHAPE_LOOSE, SHAPE_CLOSE = 0.5, 0.7  # correlations measured/model for big and small factors
TOL_BIG, TOL_SMALL = 1.0, 0.05  # relative tolerance of a scale around a unit factor (1.0: within 2x)


@functools.lru_cache(maxsize=1)
def registry():
    """pint's unit registry (built once, on first use: pint is imported only when units are converted)."""
    import pint

    return pint.UnitRegistry()


def _pint_name(unit: str) -> str:
    u = unit.strip()
    return {"-": "dimensionless", "": "dimensionless", "N m": "N*m", "N mm": "N*mm"}.get(u, u.replace(" ", "*"))


def factor(from_unit: str, to_unit: str) -> float:
    """Multiply values in ``from_unit`` by this to get ``to_unit`` (pint; raises DataFileError
    naming both units when they are of different kinds)."""
    import pint

    ureg = registry()
    try:
        return float(ureg.Quantity(1.0, _pint_name(from_unit)).to(_pint_name(to_unit)).magnitude)
    except (pint.errors.DimensionalityError, pint.errors.UndefinedUnitError, AttributeError, ValueError) as exc:
        raise DataFileError(f"cannot read {from_unit} as {to_unit} ({type(exc).__name__})") from None


def split(name: str):
    """(quantity, unit suffix) of a header name: ``dx_mm`` -> ``("dx", "mm")``; suffix "" if none."""
    base, _, suffix = name.rpartition("_")
    return (base, suffix) if base else (name, "")


def dimension(unit: str) -> str:
    """The kind of ``unit``: "[length]", "[force]", "[torque]", "[angle]", "[frequency]", or pint's
    dimensionality as text for others ("" if pint does not know the unit)."""
    ureg = registry()
    try:
        dims = ureg.Quantity(1.0, _pint_name(unit)).dimensionality
    except Exception:  # pint's own errors: a unit it does not know
        return ""
    for kind, ref in (("[force]", "N"), ("[torque]", "N*m"), ("[frequency]", "Hz"), ("[length]", "m")):
        if dims == ureg.Quantity(1.0, ref).dimensionality:
            return kind
    if _pint_name(unit) in ("rad", "mrad", "urad", "deg", "arcmin", "arcsec", "radian", "degree"):
        return "[angle]"
    return str(dims)


def parse_override(text) -> dict:
    """``"dx_m=mm, fx_N=lbf"`` (the ``--units`` option) -> ``{"dx_m": "mm", "fx_N": "lbf"}``."""
    if not text:
        return {}
    if isinstance(text, dict):
        return {str(k).strip(): str(v).strip() for k, v in text.items()}
    out = {}
    for item in str(text).split(","):
        if not item.strip():
            continue
        col, sep, unit = item.partition("=")
        if not sep or not col.strip() or not unit.strip():
            raise DataFileError(f"--units '{item.strip()}': give COLUMN=UNIT, e.g. --units dx_m=mm,fx_N=lbf")
        out[col.strip()] = unit.strip()
    return out


def header_columns(exp, names, where: str) -> tuple:
    """The experiment's column names for a header ``names`` and the factor of each column: a name
    of the experiment as it is (factor 1); another unit suffix on a column's quantity (``dx_mm``
    for ``dx_m``) is that column, its values converted (pint).  Unknown names are returned as they
    are, for the header check to name them."""
    by_quantity, known = {}, {c.name for c in exp.all_columns}
    for c in exp.all_columns:
        by_quantity.setdefault(split(c.name)[0], c)
    out, factors = [], []
    for h in names:
        if h in known:
            out.append(h)
            factors.append(1.0)
            continue
        q, suffix = split(h)
        col = by_quantity.get(q)
        if col is None or suffix not in SUFFIXES or col.codes:
            out.append(h)
            factors.append(1.0)
            continue
        try:
            f = factor(SUFFIXES[suffix], col.unit)
        except DataFileError:
            raise DataFileError(
                f"{where}: column '{h}' is in {SUFFIXES[suffix]}, which is not a unit of {col.name} ({col.unit}); "
                f"give {q} in a unit of {col.unit}"
            ) from None
        out.append(col.name)
        factors.append(f)
    return out, factors


def override_factors(exp, header, units: dict, where: str) -> dict:
    """``{column: factor}`` of a ``--units`` override: the values of each named column are in the
    unit given (``dx_m=mm``: multiply by 1e-3)."""
    out = {}
    for name, unit in units.items():
        col = next((c for c in exp.all_columns if c.name == name), None)
        if col is None or name not in header:
            known = ", ".join(h for h in header)
            raise DataFileError(f"--units {name}={unit}: {where} has no column '{name}'; its columns: {known}")
        try:
            out[name] = factor(SUFFIXES.get(unit, unit), col.unit)
        except DataFileError:
            raise DataFileError(
                f"--units {name}={unit}: {unit} is not a unit of {name} ({col.unit}); give a unit of {col.unit}"
            ) from None
    return out


def scale(measured, model) -> tuple:
    """(s, r): the least-squares scale of ``model`` onto ``measured`` about their means, and their
    correlation; (nan, nan) when the model does not vary."""
    m = np.asarray(measured, float)
    p = np.asarray(model, float)
    ok = np.isfinite(m) & np.isfinite(p)
    m, p = m[ok] - m[ok].mean(), p[ok] - p[ok].mean()
    pp, mm = float(p @ p), float(m @ m)
    if not (pp > 0.0 and mm > 0.0):
        return math.nan, math.nan
    return float(m @ p) / pp, float(m @ p) / math.sqrt(pp * mm)


def likely_unit(column_unit: str, s: float, r: float):
    """The unit the values of a column in ``column_unit`` are likely in, given scale ``s`` and
    correlation ``r`` of measured on model (module docstring); None when nothing points to one."""
    if not (math.isfinite(s) and math.isfinite(r)) or s <= 0:
        return None
    dim = dimension(column_unit)
    hits = []
    for unit in _LIKELY.get(dim, ()):
        try:
            f = 1.0 / factor(unit, column_unit)  # how many of `unit` in one column unit
        except DataFileError:
            continue
        big = f >= BIG or f <= 1.0 / BIG
        tol, shape = (TOL_BIG, SHAPE_LOOSE) if big else (TOL_SMALL, SHAPE_CLOSE)
        off = abs(math.log(s / f))
        if f != 1.0 and r > shape and off < math.log1p(tol):
            hits.append((off, unit, f))
    if hits:  # the nearest unit factor (in and cm overlap within a factor of 2)
        return min(hits)[1:]
    if r > SHAPE_LOOSE and (s > 100.0 or s < 0.01):
        return "", s  # far off, no unit named
    return None


def check_scale(exp, data, predicted: dict, confirmed=()) -> None:
    """Stop with a one-line DataFileError when a measured channel's size against the model's
    prediction (default parameters, the measured loads) says its values are in another unit than
    its header (module docstring).  ``confirmed``: channels whose unit the user vouched for
    (``--units dx_m=m``)."""
    for c in exp.channels:
        if c in confirmed or c not in data.columns or c not in predicted:
            continue
        s, r = scale(data[c], predicted[c])
        hit = likely_unit(exp.unit_of(c), s, r)
        if hit is None:
            continue
        unit, f = hit
        q = split(c)[0]
        col_unit = exp.unit_of(c)
        if unit:
            suffix = next((k for k, v in SUFFIXES.items() if v == unit), unit)
            fix = (
                f"if they are in {unit}, name the column {q}_{suffix} (femast converts it) or pass --units {c}={suffix}"
            )
            what = f"~{f:.4g} times what the model predicts under the measured loads: values in {unit}"
        else:
            fix = "check the unit of the column and of the load columns"
            what = f"{s:.3g} times what the model predicts under the measured loads"
        raise DataFileError(
            f"{data.path}: column '{c}' is {what} under a header in {col_unit}? {fix}; "
            f"if they really are in {col_unit}, pass --units {c}={split(c)[1] or col_unit} to confirm"
        )


def check_data(exp, data) -> None:
    """:func:`check_scale` of ``data`` against the model of ``exp`` with its default parameters
    (one model run; the FE experiments keep it in their run cache, where the fits that follow
    find it).  The channels the user confirmed (``--units dx_m=m``) are not checked."""
    check_scale(exp, data, predict(exp, data), confirmed=data.cache.get(CONFIRMED, ()))


CONFIRMED = "units confirmed"  # key in Measured.cache: the channels whose unit the user vouched for
