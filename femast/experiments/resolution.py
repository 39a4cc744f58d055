"""The resolution of recorded readings: the step of the grid a column's values lie on.

A test recorded to 0.01 kN and 0.01 mm stores every reading as a whole number of counts.  The
rounding to the nearest count is an error of its own: uniform over one step ``q`` when the signal
moves over several counts, of standard deviation ``q / sqrt(12)`` (Sheppard's correction).  It is a
floor under any noise estimate -- and the estimates built on differences of the readings do not
see it where the signal moves by less than a count from row to row (the differences are then
exactly zero, and a median of them is zero).

The floor of a compared channel (:func:`rounding_floors`) is its own rounding and that of each
recorded input, carried through the model's sensitivity to it (the least-squares slopes of the
model's prediction against the inputs from row to row, a linearisation along the path):
``sigma_q^2 = q_c^2 / 12 + sum_j (b_j q_j)^2 / 12``.  The noise model
(:mod:`femast.experiments.noise`) prints it as the source ``resolution`` and takes no level
estimated from the data below it.

* :func:`resolution` -- the step of a column's grid (0 where the values lie on no grid);
* :func:`rounding_sigma` -- ``q / sqrt(12)`` (in the unit of the column);
* :func:`rounding_floors` -- ``{channel: (level, reason)}`` of an experiment's data.
"""

from __future__ import annotations

import math

import numpy as np

#: a value lies on the grid when it is within this share of a step of a grid point (the decimal
#: values of a file, parsed to binary floating point and scaled by a unit, are off by ~1e-12 of a
#: step; values off the grid by chance are off by up to half a step)
ON_GRID = 1e-3
#: a grid finer than this share of the column's span is no resolution worth a floor
FINEST = 1e-9
MIN_VALUES = 8  # fewer readings than this: no grid is claimed
#: fewest steps of the grid over the column's range: a coarser grid is a designed path (a protocol of
#: prescribed levels, 0.12 deg steps of a twist), not the resolution of a recorder
MIN_COUNTS = 100


def resolution(values) -> float:
    """The step ``q`` (unit of the values) of the grid ``a + k q`` every finite value of ``values``
    lies on, ``a`` the smallest value: the smallest nonzero gap between distinct values, accepted
    only if every value lies on that grid (to ``ON_GRID`` of a step).  0.0 when the values lie on
    no grid (continuous readings), on one of fewer than ``MIN_COUNTS`` steps over their range (a
    designed path of prescribed levels), take fewer than three distinct values, or are fewer than
    ``MIN_VALUES``.  A column recorded to two decimals of a millimetre in metres gives 1e-5."""
    x = np.asarray(values, float).ravel()
    x = x[np.isfinite(x)]
    if x.size < MIN_VALUES:
        return 0.0
    v = np.unique(x)
    span = float(v[-1] - v[0]) if v.size else 0.0
    if v.size < 3 or span <= 0.0:
        return 0.0
    gaps = np.diff(v)
    gaps = gaps[gaps > FINEST * span]
    if gaps.size == 0:
        return 0.0
    q = float(gaps.min())
    q = span / round(span / q)  # the step that fits the whole span (the smallest gap carries round-off)
    if span / q < MIN_COUNTS:
        return 0.0
    k = (v - v[0]) / q
    if np.max(np.abs(k - np.round(k))) > ON_GRID:
        return 0.0
    return q


def rounding_sigma(q: float) -> float:
    """Standard deviation of the rounding to a grid of step ``q``: ``q / sqrt(12)``."""
    return float(q) / math.sqrt(12.0)


def rounding_floors(exp, data, predicted, names) -> dict:
    """``{channel: (level, reason)}``: the rounding floor of each channel recorded to a fixed step or
    driven by inputs that are (module docstring); channels with neither are absent.
    predicted : ``{channel: (n,)}`` the model's prediction (its slopes against the inputs); names :
    the input columns."""
    q_in = {j: resolution(data[j]) for j in names}
    rounded = [j for j in names if q_in[j] > 0.0]
    X = np.column_stack([np.asarray(data[j], float) for j in names]) if names else None
    out = {}
    for c in exp.channels:
        q = resolution(data[c])
        parts = [(c, q, 1.0)] if q > 0.0 else []
        if rounded and data.n > len(names) + 2:
            dX = np.diff(X, axis=0)
            dp = np.diff(np.asarray(predicted[c], float))
            ok = np.all(np.isfinite(dX), axis=1) & np.isfinite(dp)
            b = np.linalg.lstsq(dX[ok], dp[ok], rcond=None)[0] if ok.sum() > len(names) else np.zeros(len(names))
            parts += [(j, q_in[j], abs(float(b[names.index(j)]))) for j in rounded]
        parts = [p for p in parts if p[1] * p[2] > 0.0]
        if not parts:
            continue
        level = math.sqrt(sum(rounding_sigma(qq * bb) ** 2 for _, qq, bb in parts))
        uc = exp.unit_of(c)
        said = ", ".join(
            f"{j} in steps of {qq:.3g} {exp.unit_of(j)}" + ("" if j == c else f" (x {bb:.3g} {uc}/{exp.unit_of(j)})")
            for j, qq, bb in parts
        )
        out[c] = (level, f"the readings' resolution: {said}, rounding q/sqrt(12) each: {level:.3g} {uc}")
    return out
