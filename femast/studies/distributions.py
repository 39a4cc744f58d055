"""Uncertain inputs of a study: a name, a distribution and a size.

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

Correlation between the members of one input (``member_correlation=``; a Gaussian copula, as
between scalar inputs): a number rho gives every pair of members the correlation rho
(equicorrelation: members cut from one batch share part of their error; -1/(n-1) < rho < 1);
an (n, n) matrix gives any structure, e.g. :func:`exponential_correlation` of the members'
positions (neighbours alike, far members independent).  The correlation is that of the normal
scores ``Phi^-1(F(x))`` (for a Normal input, of the values themselves); each member keeps its
distribution.  The input stays one group in the Sobol' indices (the groups stay independent), but
the Latin-hypercube strata and Sobol' balance of its columns are lost.

    Normal("dL_m", 0.0, 0.05e-3, size=40, member_correlation=0.5)
    Normal("dL_m", 0.0, 0.05e-3, size=40, member_correlation=exponential_correlation(z_m, 2.0))
"""

from __future__ import annotations

import math

import numpy as np
from scipy import special  # (scipy.stats where needed: 0.45 s to import, and every femast command pays

# the import of this package)
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


def exponential_correlation(positions, length) -> np.ndarray:
    """Correlation matrix ``exp(-|x_i - x_j| / length)`` of members at ``positions`` ((n,) or (n, d),
    m) with correlation length ``length`` (m, > 0): for ``member_correlation=``."""
    x = np.asarray(positions, dtype=float)
    x = x[:, None] if x.ndim == 1 else x
    L = _number(length, "correlation length", "exponential_correlation")
    if x.ndim != 2 or len(x) < 1 or not np.all(np.isfinite(x)):
        raise StudyError(
            f"exponential_correlation: positions must be finite, shape (n,) or (n, d) in m; got "
            f"shape {np.shape(positions)}"
        )
    if not L > 0.0:
        raise StudyError(f"exponential_correlation: length = {length!r} m must be > 0")
    d = np.linalg.norm(x[:, None, :] - x[None, :, :], axis=2)
    return np.exp(-d / L)


def _member_cholesky(rho, size, name):
    """(stored spec, Cholesky factor) of a member correlation (module docstring)."""
    if rho is None:
        return None, None
    if size is None:
        raise StudyError(
            f"input '{name}': member_correlation needs a per-member input (size=n); between scalar "
            "inputs give Study(correlation={('a', 'b'): rho})"
        )
    if np.ndim(rho) == 0:
        r = _number(rho, "member_correlation", name)
        lo = -1.0 / (size - 1) if size > 1 else -1.0
        if not lo < r < 1.0:
            raise StudyError(
                f"input '{name}': member_correlation = {rho!r} must lie in ({lo:.4g}, 1) for {size} "
                "members (equicorrelation)"
            )
        C, spec = np.full((size, size), r), r
        np.fill_diagonal(C, 1.0)
    else:
        try:
            C = np.asarray(rho, dtype=float)
        except (TypeError, ValueError):
            raise StudyError(
                f"input '{name}': member_correlation must be a number or an ({size}, {size}) matrix of numbers"
            ) from None
        if C.shape != (size, size):
            raise StudyError(
                f"input '{name}': member_correlation must be ({size}, {size}) (one row per member); got shape {C.shape}"
            )
        if not np.all(np.isfinite(C)):
            raise StudyError(f"input '{name}': member_correlation has non-finite entries")
        if not (np.allclose(C, C.T, rtol=0, atol=1e-12) and np.allclose(np.diag(C), 1.0, rtol=0, atol=1e-12)):
            raise StudyError(f"input '{name}': member_correlation must be symmetric with ones on its diagonal")
        spec = C.tolist()
    try:
        L = np.linalg.cholesky(C)
    except np.linalg.LinAlgError:
        raise StudyError(
            f"input '{name}': member_correlation is not a valid correlation matrix (not positive "
            "definite); lower the coefficients (or shorten the correlation length)"
        ) from None
    return spec, L


class Input:
    """Base of the uncertain inputs: ``name`` (an identifier: the factory's keyword), ``size``
    (None: one scalar; n: n values, per member), ``member_correlation`` (None: independent members;
    a number or an (n, n) matrix: module docstring)."""

    kind = "input"

    def __init__(self, name: str, size: int | None = None, member_correlation=None):
        if not isinstance(name, str) or not name.isidentifier():
            raise StudyError(
                f"input name {name!r} is not a Python identifier; use letters, digits and _ "
                "(it is the keyword the model factory receives)"
            )
        self.name = name
        if size is not None:
            if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or size < 1:
                raise StudyError(
                    f"input '{name}': size = {size!r} must be a whole number >= 1 (the number of "
                    "members drawn independently), or None for one shared value"
                )
            size = int(size)
        self.size = size
        spec, self._member_chol = _member_cholesky(member_correlation, size, name)
        if spec is not None:
            self.member_correlation = spec  # in the spec (a resumed study must be the same)

    @property
    def dims(self) -> int:
        """Columns of the unit cube the input uses."""
        return 1 if self.size is None else self.size

    def ppf(self, u: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def value(self, u: np.ndarray):
        """The value(s) for the unit numbers ``u`` ((n, dims)): (n,) for a scalar input, (n, size)
        for a per-member one."""
        u = np.clip(np.asarray(u, dtype=float), EPS, 1.0 - EPS)
        if self._member_chol is not None:  # Gaussian copula between the members
            u = np.clip(special.ndtr(special.ndtri(u) @ self._member_chol.T), EPS, 1.0 - EPS)
        x = self.ppf(u)
        return x[:, 0] if self.size is None else x

    @property
    def nominal(self) -> float:
        """The median (used to build the model once before the study, to check it)."""
        return float(self.ppf(np.array([0.5]))[0])

    def spec(self) -> dict:
        """Plain description (stored in the study's manifest: a resumed study must be the same)."""
        return {
            "kind": self.kind,
            "name": self.name,
            "size": self.size,
            **{k: v for k, v in vars(self).items() if k not in ("name", "size") and not k.startswith("_")},
        }

    def __repr__(self):
        args = ", ".join(f"{k}={v!r}" for k, v in self.spec().items() if k not in ("kind", "name") and v is not None)
        return f"{type(self).__name__}({self.name!r}, {args})"


class Normal(Input):
    """Normal distribution: ``mean`` and standard deviation ``std`` (> 0), in the input's unit."""

    kind = "normal"

    def __init__(self, name: str, mean: float, std: float, size: int | None = None, member_correlation=None):
        super().__init__(name, size, member_correlation)
        self.mean = _number(mean, "mean", name)
        self.std = _number(std, "std", name)
        if self.std <= 0.0:
            raise StudyError(
                f"input '{name}': std = {std!r} must be > 0 (a fixed value is not uncertain: pass it "
                "to the model directly)"
            )

    def ppf(self, u):
        return self.mean + self.std * special.ndtri(u)


class Uniform(Input):
    """Uniform distribution on [low, high] (low < high), in the input's unit."""

    kind = "uniform"

    def __init__(self, name: str, low: float, high: float, size: int | None = None, member_correlation=None):
        super().__init__(name, size, member_correlation)
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

    def __init__(
        self,
        name: str,
        mean: float,
        std: float,
        low: float | None = None,
        high: float | None = None,
        size: int | None = None,
        member_correlation=None,
    ):
        super().__init__(name, size, member_correlation)
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
        from scipy import stats

        if stats.norm.cdf(b) - stats.norm.cdf(a) < 1e-12:
            raise StudyError(
                f"input '{name}': [low, high] = [{low}, {high}] holds no probability of "
                f"Normal({mean}, {std}) (more than 7 std from the mean); move the bounds or the mean"
            )
        self._ab = (a, b)

    def ppf(self, u):
        from scipy import stats

        a, b = self._ab
        return self.mean + self.std * stats.truncnorm.ppf(u, a, b)


class LogNormal(Input):
    """Log-normal: log(value) is Normal(log(``median``), ``sigma_log``); for positive inputs
    (stiffnesses, friction coefficients)."""

    kind = "lognormal"

    def __init__(self, name: str, median: float, sigma_log: float, size: int | None = None, member_correlation=None):
        super().__init__(name, size, member_correlation)
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
            raise StudyError(
                f"{x!r} is not a study input; use femast.studies.Normal, Uniform, TruncatedNormal or LogNormal"
            )
        if x.name in seen:
            raise StudyError(f"input '{x.name}' is given twice; input names must be unique")
        seen.add(x.name)
    return inputs
