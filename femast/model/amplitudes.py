"""Amplitudes: how a load or prescribed value varies over a step (as Abaqus *AMPLITUDE).

An :class:`Amplitude` is a piecewise-linear table of (step time, factor).  A load or a
prescribed displacement with an amplitude takes the value ``factor(t) * magnitude``
at step time t (s).  Without an amplitude a value ramps linearly from what it was at
the start of the step to its new magnitude at the end (Abaqus' default for static steps).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError


@dataclass(frozen=True)
class Amplitude:
    """Piecewise-linear amplitude: ``times`` (step time, s, increasing) and ``values``
    (dimensionless factors).  Outside the table the end values are held.  ``name`` labels it in
    messages."""

    times: np.ndarray
    values: np.ndarray
    name: str = "amplitude"

    def __init__(self, times, values, name: str = "amplitude"):
        t = np.asarray(times, dtype=float).ravel()
        v = np.asarray(values, dtype=float).ravel()
        if t.size == 0 or t.size != v.size:
            raise ModelError(f"amplitude '{name}': need as many times as values (got {t.size} and {v.size})")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
            bad = int(np.flatnonzero(~(np.isfinite(t) & np.isfinite(v)))[0])
            raise ModelError(f"amplitude '{name}': row {bad} (time {t[bad]}, value {v[bad]}) is not finite")
        if np.any(np.diff(t) <= 0):
            bad = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
            raise ModelError(f"amplitude '{name}': times must increase; row {bad} has time {t[bad]} after {t[bad - 1]}")
        object.__setattr__(self, "times", t)
        object.__setattr__(self, "values", v)
        object.__setattr__(self, "name", name)

    def __call__(self, t):
        return np.interp(t, self.times, self.values)

    @classmethod
    def from_path(cls, values, period: float = 1.0, name: str = "path") -> Amplitude:
        """Evenly spaced samples ``values`` over a step of length ``period`` (s)."""
        v = np.asarray(values, dtype=float).ravel()
        return cls(np.linspace(0.0, period, v.size), v, name=name)
