"""Uncertain inputs of a study: a name, a distribution and a size (issue 20).

Each input maps a uniform number u in (0, 1) to a value by the inverse of its cumulative
distribution (``ppf``), so any sampler of the unit cube (Monte Carlo, Latin hypercube, Sobol')
and a Gaussian copula for correlations (:mod:`femast.studies.sampling`) work with every
distribution.  ``size=n`` makes a per-member input: n independent draws of the same
distribution (e.g. the length error of each of 160 longerons), passed to the model factory as
an array of n values; ``size=None`` (default) is one shared scalar.  A per-member input counts
as one group in the sensitivity indices.

Values are in the unit the input's name or docstring says (SI: m, N, rad, 1); the distribution
does not convert anything.

    Normal("pretension_N", mean=180.0, std=18.0)
    Uniform("mu", 0.3, 0.7)
    TruncatedNormal("dL_m", mean=0.0, std=0.05e-3, low=-0.1e-3, high=0.1e-3, size=160)
"""

from __future__ import annotations

import math

import numpy as np
from scipy import special, stats

from ..errors import StudyError

#: u is kept inside [EPS, 1 - EPS]: a normal's ppf(0) is -inf (a scrambled Sobol' point can be 0).
EPS = 1e-12


def _number(value, what: str, name: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise StudyError(f"input '{name}': {what} = {value!r} is not a number; give a finite float") from None
    if not math.isfinite(v):
        raise StudyError(f"input '{name}': {what} = {value!r} is not finite; give a finite float")
    return v


class Input:
    """Base of the uncertain inputs: ``name`` (an identifier: the factory's keyword), ``size``
    (None: one scalar; n: n independent values, per member)."""

    kind = "input"

    def __init__(self, name: str, size: int | None = None):
        if not isinstance(name, str) or not name.isidentifier():
            raise StudyError(f"input name {name!r} is not a Python identifier; use letters, digits and _ "
                             "(it is the keyword the model factory receives)")
        self.name = name
        if size is not None:
            if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or size < 1:
                raise StudyError(f"input '{name}': size = {size!r} must be a whole number >= 1 (the number of "
                                 "members drawn independently), or None for one shared value")
            size = int(size)
        self.size = size

    @property
    def dims(self) -> int:
        """Columns of the unit cube the input uses."""
        return 1 if self.size is None else self.size

    def ppf(self, u: np.ndarray) -> np.ndarray:   # pragma: no cover - abstract
        raise NotImplementedError

    def value(self, u: np.ndarray):
        """The value(s) for the unit numbers ``u`` ((n, dims)): (n,) for a scalar input, (n, size)
        for a per-member one."""
        x = self.ppf(np.clip(np.asarray(u, dtype=float), EPS, 1.0 - EPS))
        return x[:, 0] if self.size is None else x

    @property
    def nominal(self) -> float:
        """The median (used to build the model once before the study, to check it)."""
        return float(self.ppf(np.array([0.5]))[0])

    def spec(self) -> dict:
        """Plain description (stored in the study's manifest: a resumed study must be the same)."""
        return {"kind": self.kind, "name": self.name, "size": self.size,
                **{k: v for k, v in vars(self).items() if k not in ("name", "size")}}

    def __repr__(self):
        args = ", ".join(f"{k}={v!r}" for k, v in self.spec().items() if k not in ("kind", "name") and v is not None)
        return f"{type(self).__name__}({self.name!r}, {args})"


class Normal(Input):
    """Normal distribution: ``mean`` and standard deviation ``std`` (> 0), in the input's unit."""

    kind = "normal"

    def __init__(self, name: str, mean: float, std: float, size: int | None = None):
        super().__init__(name, size)
        self.mean = _number(mean, "mean", name)
        self.std = _number(std, "std", name)
        if self.std <= 0.0:
            raise StudyError(f"input '{name}': std = {std!r} must be > 0 (a fixed value is not uncertain: pass it "
                             "to the model directly)")

    def ppf(self, u):
        return self.mean + self.std * special.ndtri(u)


class Uniform(Input):
    """Uniform distribution on [low, high] (low < high), in the input's unit."""

    kind = "uniform"

    def __init__(self, name: str, low: float, high: float, size: int | None = None):
        super().__init__(name, size)
        self.low = _number(low, "low", name)
        self.high = _number(high, "high", name)
        if not self.low < self.high:
            raise StudyError(f"input '{name}': low = {low!r} must be below high = {high!r}; give low < high")

    def ppf(self, u):
        return self.low + (self.high - self.low) * u


class TruncatedNormal(Input):
    """Normal(``mean``, ``std``) restricted to [low, high] (either may be None: no bound); the
    bounds are values in the input's unit, not multiples of std."""

    kind = "truncated_normal"

    def __init__(self, name: str, mean: float, std: float, low: float | None = None, high: float | None = None,
                 size: int | None = None):
        super().__init__(name, size)
        self.mean = _number(mean, "mean", name)
        self.std = _number(std, "std", name)
        if self.std <= 0.0:
            raise StudyError(f"input '{name}': std = {std!r} must be > 0")
        self.low = None if low is None else _number(low, "low", name)
        self.high = None if high is None else _number(high, "high", name)
        a = -np.inf if self.low is None else (self.low - self.mean) / self.std
        b = np.inf if self.high is None else (self.high - self.mean) / self.std
        if not a < b:
            raise StudyError(f"input '{name}': low = {low!r} must be below high = {high!r}")
        if stats.norm.cdf(b) - stats.norm.cdf(a) < 1e-12:
            raise StudyError(f"input '{name}': [low, high] = [{low}, {high}] holds no probability of "
                             f"Normal({mean}, {std}) (more than 7 std from the mean); move the bounds or the mean")
        self._ab = (a, b)

    def spec(self):
        s = super().spec()
        s.pop("_ab", None)
        return s

    def ppf(self, u):
        a, b = self._ab
        return self.mean + self.std * stats.truncnorm.ppf(u, a, b)


class LogNormal(Input):
    """Log-normal: log(value) is Normal(log(``median``), ``sigma_log``); for positive inputs
    (stiffnesses, friction coefficients)."""

    kind = "lognormal"

    def __init__(self, name: str, median: float, sigma_log: float, size: int | None = None):
        super().__init__(name, size)
        self.median = _number(median, "median", name)
        self.sigma_log = _number(sigma_log, "sigma_log", name)
        if self.median <= 0.0:
            raise StudyError(f"input '{name}': median = {median!r} must be > 0 (a log-normal value is positive)")
        if self.sigma_log <= 0.0:
            raise StudyError(f"input '{name}': sigma_log = {sigma_log!r} must be > 0")

    def ppf(self, u):
        return self.median * np.exp(self.sigma_log * special.ndtri(u))


def check_inputs(inputs) -> list:
    """The inputs as a list; unique names; every item an :class:`Input`."""
    inputs = list(inputs)
    if not inputs:
        raise StudyError("a study needs at least one uncertain input (Normal, Uniform, TruncatedNormal, LogNormal)")
    seen = set()
    for x in inputs:
        if not isinstance(x, Input):
            raise StudyError(f"{x!r} is not a study input; use femast.studies.Normal, Uniform, TruncatedNormal or "
                             "LogNormal")
        if x.name in seen:
            raise StudyError(f"input '{x.name}' is given twice; input names must be unique")
        seen.add(x.name)
    return inputs
