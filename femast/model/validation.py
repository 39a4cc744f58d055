"""Checks of user input where it enters femast, and the equilibrium check of converged increments.

Every check raises :class:`~femast.errors.ModelError` naming the item (``what``) and saying what
to give instead.  Magnitudes are bounded by :data:`MAX_MAGNITUDE` of their SI unit: a coordinate
of 1e200 m or a modulus of 1e300 Pa is a typing error, and such numbers overflow in the element
kernels (squares of 1e200 are inf) long before they mean anything.
"""

from __future__ import annotations

import math
import numbers

import numpy as np
from numba import njit

from ..elements.base import DOF_NAMES
from ..errors import EquilibriumError, ModelError

#: largest accepted magnitude of any input number in its SI unit (m, N, Pa, m^4, s, ...)
MAX_MAGNITUDE = 1e15


def number(
    value,
    what: str,
    unit: str = "",
    *,
    positive=False,
    nonnegative=False,
    lo=None,
    hi=None,
    ge=None,
    max_abs=MAX_MAGNITUDE,
) -> float:
    """``value`` as a float, or a ModelError naming ``what``: not a number (strings, None, bools,
    arrays are refused), not finite, beyond ``max_abs``, or outside the asked range (``lo`` < v,
    ``ge`` <= v, v <= ``hi``)."""
    u = f" {unit}" if unit else ""
    if isinstance(value, (bool, np.bool_)) or isinstance(value, (str, bytes)) or value is None:
        raise ModelError(f"{what} = {value!r} is not a number; give a number{(' in' + u) if unit else ''}")
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if not isinstance(value, numbers.Real):
        raise ModelError(f"{what} = {value!r} is not a number; give a number{(' in' + u) if unit else ''}")
    v = float(value)
    if not math.isfinite(v):
        raise ModelError(f"{what} = {value!r} is not finite; give a finite number{(' in' + u) if unit else ''}")
    if abs(v) > max_abs:
        raise ModelError(
            f"{what} = {v:g}{u} is beyond {max_abs:g}{u} (a typing error? such magnitudes "
            "overflow in the element computations); give a realistic value in SI units"
        )
    if positive and not v > 0:
        raise ModelError(f"{what} = {v:g}{u} must be positive")
    if nonnegative and not v >= 0:
        raise ModelError(f"{what} = {v:g}{u} must be zero or positive")
    if lo is not None and not v > lo:
        raise ModelError(f"{what} = {v:g}{u} must be greater than {lo:g}{u}")
    if ge is not None and not v >= ge:
        raise ModelError(f"{what} = {v:g}{u} must be at least {ge:g}{u}")
    if hi is not None and not v <= hi:
        raise ModelError(f"{what} = {v:g}{u} must be at most {hi:g}{u}")
    return v


def whole(value, what: str, minimum: int | None = None) -> int:
    """``value`` as an int: integers, and floats with no fractional part, are accepted; a ModelError
    naming ``what`` otherwise (1.5 is not silently truncated to 1)."""
    if isinstance(value, (bool, np.bool_)) or isinstance(value, (str, bytes)) or value is None:
        raise ModelError(f"{what} = {value!r} must be a whole number")
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, numbers.Integral):
        v = int(value)
    elif isinstance(value, numbers.Real) and math.isfinite(float(value)) and float(value).is_integer():
        v = int(value)
    else:
        raise ModelError(f"{what} = {value!r} must be a whole number")
    if abs(v) > 2**62:
        raise ModelError(f"{what} = {v} is too large; give a whole number below 2**62")
    if minimum is not None and v < minimum:
        raise ModelError(f"{what} = {v} must be at least {minimum}")
    return v


def coordinates(coords, what: str = "nodes") -> np.ndarray:
    """An (n, 3) float array of finite coordinates (m) within MAX_MAGNITUDE, or a ModelError naming
    ``what`` and the shape that was given (a (3, 2) array is not reshaped into garbage nodes)."""
    try:
        a = np.asarray(coords, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{what}: coordinates must be an (n, 3) array of numbers (m)") from None
    if a.ndim == 1 and a.size == 3:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != 3:
        raise ModelError(
            f"{what}: coordinates must be an (n, 3) array (one row x, y, z per node, m); got shape "
            f"{a.shape}" + ("; transpose it" if a.ndim == 2 and a.shape[0] == 3 else "")
        )
    bad = np.argwhere(~np.isfinite(a) | (np.abs(a) > MAX_MAGNITUDE))
    if bad.size:
        r, c = bad[0]
        raise ModelError(
            f"{what}: row {r} coordinate {'xyz'[c]} = {a[r, c]!r} m is not a finite number within {MAX_MAGNITUDE:g} m"
        )
    return a


#: an element shorter than this fraction of its nodes' distance from the origin is below the
#: resolution of its own coordinates (double precision: 2.2e-16 of the distance; here 2.2e-6 of its length)
PRECISION = 1e-10


def prescribed_once(prescribed, node, dof: int, value: float, where: str) -> None:
    """A ModelError if DOF ``dof`` of ``node`` is already among the ``prescribed`` conditions of a step
    (the last value would silently win)."""
    for c in prescribed:
        if int(c.node) == int(node) and c.dof == dof:
            unit = "m" if dof < 3 else "rad"
            raise ModelError(
                f"{where}: node {node} {DOF_NAMES[dof]} is prescribed twice in this step "
                f"({c.magnitude:g} {unit}, then {value:g} {unit}); give it one value (a later step may change it)"
            )


def not_fractional(label, where: str) -> None:
    """A ModelError if node label ``label`` is a number with a fractional part (never rounded to a node)."""
    try:
        fractional = float(label) != int(label) and not isinstance(label, (str, bytes, bool))
    except (TypeError, ValueError, OverflowError):
        return
    if fractional:
        raise ModelError(f"{where}: node label {label!r} is not a whole number; give the label Model.node returned")


def element_length(L: float, far: float, where: str, kind: str, n1, n2) -> None:
    """Check the length ``L`` (m) of a two-node element (nodes ``n1``, ``n2``) whose nodes lie up to
    ``far`` (m) from the origin: a ModelError if the nodes coincide, or if the element is too short
    for its coordinates to resolve it (a 1 m beam 1e12 m from the origin: positions there are known
    to 1e-4 m, so its strains would be round-off)."""
    if L <= 1e-12 * max(1.0, far) and not (far > 1e6 and L > 8 * np.finfo(float).eps * far):
        raise ModelError(f"{where}: nodes {n1} and {n2} coincide (length {L:g} m); a {kind} needs two distinct nodes")
    if L < PRECISION * far:
        raise ModelError(
            f"{where}: nodes {n1} and {n2} are {far:.3g} m from the origin but only {L:.3g} m apart; there double "
            f"precision resolves {np.spacing(far):.2g} m, too coarse for the {kind}'s strains. Build the model near "
            "the origin (subtract a reference point from the coordinates)"
        )


def step_increments(step) -> None:
    """Check a step's time and increment settings: finite, positive, ordered (min <= initial <= max
    <= period), a whole max_increments >= 1, hit times inside the step."""
    where = f"step '{step.name}'"
    step.period = number(step.period, f"{where}: period", "s", positive=True)
    for name in ("initial_increment", "min_increment", "max_increment"):
        v = getattr(step, name)
        if v is not None:
            v = number(v, f"{where}: {name}", "s", positive=True)
            if v > step.period * (1 + 1e-12):
                raise ModelError(
                    f"{where}: {name} = {v:g} s is longer than the step period {step.period:g} s; "
                    f"give at most the period"
                )
            setattr(step, name, v)
    lo, ini, hi = step.min_increment, step.initial_increment, step.max_increment
    if lo is not None and hi is not None and lo > hi:
        raise ModelError(
            f"{where}: min_increment = {lo:g} s is larger than max_increment = {hi:g} s; "
            "give min_increment <= initial_increment <= max_increment"
        )
    if lo is not None and ini is not None and ini < lo:
        raise ModelError(
            f"{where}: initial_increment = {ini:g} s is smaller than min_increment = {lo:g} s; "
            "give min_increment <= initial_increment <= max_increment"
        )
    if hi is not None and ini is not None and ini > hi:
        raise ModelError(
            f"{where}: initial_increment = {ini:g} s is larger than max_increment = {hi:g} s; "
            "give min_increment <= initial_increment <= max_increment"
        )
    step.max_increments = whole(step.max_increments, f"{where}: max_increments", minimum=1)
    times = []
    for h in step.hit_times:
        t = number(h, f"{where}: hit time", "s")
        if not 0 <= t <= step.period:
            raise ModelError(f"{where}: hit time {t:g} s is outside the step (0..{step.period:g} s)")
        times.append(t)
    step.hit_times = tuple(times)


def loads_on_active_dofs(model, dofmap) -> None:
    """A load, or a non-zero prescribed value, on a DOF that no element or constraint stiffens would
    vanish from the analysis (the reactions would not balance the loads): a ModelError naming the
    step, node and DOF."""
    for s in model.steps:
        for kind, conds in (("load", s.loads), ("prescribed value", s.prescribed)):
            for c in conds:
                if c.magnitude == 0.0:
                    continue
                i = model.index(c.node)
                if dofmap.eq[i, c.dof] < 0:
                    name = DOF_NAMES[c.dof] if kind != "load" else ("fx", "fy", "fz", "mx", "my", "mz")[c.dof]
                    what = (
                        "no element is connected to the node"
                        if not np.any(dofmap.eq[i] >= 0)
                        else f"the node's elements give no stiffness to {DOF_NAMES[c.dof]} (e.g. a moment on a "
                        "node with trusses or cables only)"
                    )
                    raise ModelError(
                        f"step '{s.name}': {kind} {name} on node {c.node}: {what}; it would be lost. "
                        "Connect the node to an element that stiffens this DOF, tie it to one, or "
                        "remove the load"
                    )


def self_equilibrated(families) -> bool:
    """True when every family's nodal forces are internal (sum to zero force and moment)."""
    return all(getattr(f, "self_equilibrated", False) for f in families)


@njit(cache=True)
def _balance(x, P, RF, r_free, free_dof):
    """Net force and moment (about the origin) of the loads ``P`` plus reactions ``RF`` at ``x``, the
    summed magnitudes of their forces and of their moments, the largest coordinate magnitude and
    the summed magnitudes of the free residual's forces and moments: one pass, no temporaries
    (the numpy version cost a small model's increment more than its Newton iteration)."""
    fx = fy = fz = mx = my = mz = 0.0
    sum_f = sum_m = xmax = 0.0
    for i in range(x.shape[0]):
        tx, ty, tz = P[i, 0] + RF[i, 0], P[i, 1] + RF[i, 1], P[i, 2] + RF[i, 2]
        fx += tx
        fy += ty
        fz += tz
        mx += x[i, 1] * tz - x[i, 2] * ty + P[i, 3] + RF[i, 3]
        my += x[i, 2] * tx - x[i, 0] * tz + P[i, 4] + RF[i, 4]
        mz += x[i, 0] * ty - x[i, 1] * tx + P[i, 5] + RF[i, 5]
        for k in range(3):
            sum_f += abs(P[i, k]) + abs(RF[i, k])
            sum_m += abs(P[i, 3 + k]) + abs(RF[i, 3 + k])
            xmax = max(xmax, abs(x[i, k]))
    rt = rm = 0.0
    for j in range(r_free.shape[0]):
        if free_dof[j] < 3:
            rt += abs(r_free[j])
        else:
            rm += abs(r_free[j])
    return fx, fy, fz, mx, my, mz, sum_f, sum_m, xmax, rt, rm


def check_equilibrium(
    x, P, RF, r_free, free_dof, where: str, internal: float = 0.0, labels=None, rel: float = 1e-9, ground=None
) -> None:
    """Global balance of a converged increment of a model whose elements are self-equilibrated:
    the applied loads ``P`` (n, 6) and reactions ``RF`` (n, 6) at positions ``x`` (n, 3) balance
    (force and moment about the origin) up to what the free DOFs' residual ``r_free`` leaves
    unbalanced (bounded by the triangle inequality) plus round-off: ``rel`` (1e-9, a million times
    double precision, for sums over many nodes) of the summed magnitudes of the loads, reactions
    and ``internal`` (the summed magnitudes of the element nodal forces, N).  ``ground``: the
    resultant (6,) (force, moment about the origin) of the element families tied to the ground
    (not self-equilibrated), which the loads and reactions balance instead of zero.
    Raises :class:`~femast.errors.EquilibriumError` naming the increment otherwise."""
    fx, fy, fz, mx, my, mz, sum_f, sum_m, xmax, rt, rm = _balance(
        np.ascontiguousarray(x, dtype=float),
        np.ascontiguousarray(P, dtype=float),
        np.ascontiguousarray(RF, dtype=float),
        np.ascontiguousarray(r_free, dtype=float),
        np.ascontiguousarray(free_dof, dtype=np.int64),
    )
    if ground is not None:
        fx, fy, fz, mx, my, mz = (a - float(b) for a, b in zip((fx, fy, fz, mx, my, mz), ground))
    arm = xmax * math.sqrt(3.0)
    scale_f = sum_f + internal
    scale_m = sum_m + arm * scale_f
    tol_f = rt + rel * scale_f + 1e-300
    tol_m = rm + arm * rt + rel * scale_m + 1e-300
    nf, nm = math.sqrt(fx * fx + fy * fy + fz * fz), math.sqrt(mx * mx + my * my + mz * mz)
    if nf > tol_f * math.sqrt(3.0) or nm > tol_m * math.sqrt(3.0):
        worst = int(np.argmax(np.abs(P).sum(axis=1)))
        node = labels[worst] if labels is not None else worst
        raise EquilibriumError(
            f"{where}: the reactions do not balance the applied loads (net force {nf:.3g} N, "
            f"net moment {nm:.3g} N m, allowed {tol_f:.3g} N, {tol_m:.3g} N m; largest load "
            f"on node {node}): a load is lost or an element family is not self-equilibrated; "
            "please report this with the model"
        )
