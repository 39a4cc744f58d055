"""Statistics of a study's outputs: percentiles with confidence intervals, convergence
of the estimates with the number of samples, first-order and total Sobol' indices.

* Percentile intervals are distribution-free order-statistic intervals: for the q-quantile xi_q
  of n independent samples, the number of samples below xi_q is Binomial(n, q), so
  [x_(l), x_(u)] (sorted, 1-based) covers xi_q with probability F(u - 1) - F(l - 1) (F the
  binomial cdf); l, u are the binomial's alpha/2 and 1 - alpha/2 quantiles (+1 for u), which
  gives at least the asked confidence (Conover, Practical Nonparametric Statistics, 3rd ed.,
  Sec. 3.2).  When n is too small for a bound, it is NaN (no claim).  (Quasi-random samples are
  not independent; their intervals are conservative.)
* Sobol' indices (independent inputs) from Saltelli's layout (runs A, B, AB^i):
  first order S_i = mean((f_B - f0) (f_ABi - f_A)) / V (Saltelli et al. 2010, Table 2 (b), with f_B
  centred on the mean f0 of f_A and f_B: the same expectation, and no variance ~f0^2 / n), total
  ST_i = mean((f_A - f_ABi)^2) / (2 V) (Jansen 1999; Saltelli et al. 2010, Table 2 (f)), with
  V the variance of f_A and f_B together.  Confidence intervals by bootstrap over base samples.
"""

from __future__ import annotations

import numpy as np

from ..errors import StudyError


def _values(x, what="x"):
    x = np.asarray(x, dtype=float).ravel()
    if x.size == 0:
        raise StudyError(f"{what}: no values (every sample failed, or none ran)")
    if not np.all(np.isfinite(x)):
        raise StudyError(f"{what}: {int(np.sum(~np.isfinite(x)))} values are not finite; leave failed samples out")
    return x


def order_statistic_ranks(n: int, q: float, confidence: float = 0.95) -> tuple:
    """1-based ranks (l, u) with P(x_(l) <= xi_q <= x_(u)) >= confidence; 0 or n + 1 when n is too
    small for that side (no bound)."""
    alpha = 1.0 - confidence
    from scipy import stats  # (here: importing scipy.stats costs every femast command 0.45 s)

    l = int(stats.binom.ppf(alpha / 2, n, q))  # P(B <= l - 1) <= alpha / 2
    if l >= 1 and stats.binom.cdf(l - 1, n, q) > alpha / 2:
        l -= 1
    u = int(stats.binom.ppf(1 - alpha / 2, n, q)) + 1  # P(B >= u) <= alpha / 2
    return max(l, 0), min(u, n + 1)


def percentile(x, q: float, confidence: float = 0.95) -> dict:
    """The ``q``-quantile (0 < q < 1; e.g. 0.99) of samples ``x`` with its distribution-free
    confidence interval: {'q', 'estimate', 'low', 'high', 'n', 'coverage'} (coverage: the exact
    probability of the interval; low/high NaN when n is too small)."""
    if not 0.0 < q < 1.0:
        raise StudyError(f"quantile q = {q!r} must lie in (0, 1) (0.99 for the 99th percentile)")
    x = np.sort(_values(x))
    n = len(x)
    l, u = order_statistic_ranks(n, q, confidence)
    lo = x[l - 1] if l >= 1 else np.nan
    hi = x[u - 1] if u <= n else np.nan
    from scipy import stats

    cover = stats.binom.cdf(u - 1, n, q) - (stats.binom.cdf(l - 1, n, q) if l >= 1 else 0.0)
    return {
        "q": q,
        "estimate": float(np.quantile(x, q)),
        "low": float(lo),
        "high": float(hi),
        "n": n,
        "coverage": float(cover),
    }


def upper_bound(x, q: float, confidence: float = 0.95) -> dict:
    """One-sided distribution-free upper confidence bound of the ``q``-quantile of samples ``x``:
    {'q', 'estimate', 'high', 'rank', 'n', 'coverage', 'needed'}.  x_(u) (sorted, 1-based) lies above
    xi_q when fewer than u samples fall below it: P = F(u - 1) (F the Binomial(n, q) cdf), and u is
    the smallest rank with F(u - 1) >= confidence.  'high' is NaN when n is too small; 'needed' is
    the least n for which the largest sample is a bound (1 - q^n >= confidence: 59 for the 95th
    percentile at 95 %)."""
    if not 0.0 < q < 1.0:
        raise StudyError(f"quantile q = {q!r} must lie in (0, 1) (0.95 for the 95th percentile)")
    from scipy import stats

    x = np.sort(_values(x))
    n = len(x)
    u = int(stats.binom.ppf(confidence, n, q)) + 1
    if u >= 2 and stats.binom.cdf(u - 2, n, q) >= confidence:
        u -= 1
    needed = int(np.ceil(np.log1p(-confidence) / np.log(q)))
    return {
        "q": q,
        "estimate": float(np.quantile(x, q)),
        "high": float(x[u - 1]) if u <= n else float("nan"),
        "rank": u,
        "n": n,
        "coverage": float(stats.binom.cdf(u - 1, n, q)) if u <= n else float("nan"),
        "needed": needed,
    }


def bootstrap_ci(x, statistic=np.mean, confidence: float = 0.95, resamples: int = 2000, seed: int = 0) -> dict:
    """Percentile bootstrap interval of ``statistic`` over samples ``x``: {'estimate', 'low', 'high'}."""
    x = _values(x)
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, len(x), size=(resamples, len(x)))
    b = np.array([statistic(x[i]) for i in idx])
    a = (1.0 - confidence) / 2
    return {
        "estimate": float(statistic(x)),
        "low": float(np.quantile(b, a)),
        "high": float(np.quantile(b, 1 - a)),
        "n": len(x),
    }


def convergence(x, q=(0.5, 0.95, 0.99), ns=None, confidence: float = 0.95) -> dict:
    """Estimates of the mean (with its normal 95 % interval) and of the quantiles ``q`` (with their
    order-statistic intervals) from the first n samples, for n in ``ns`` (default: doubling from 8
    to len(x)).  Returns {'n': array, 'mean': (m, 3) [estimate, low, high], 'q<q>': (m, 3) ...}."""
    x = _values(x)
    if ns is None:
        ns = [n for n in (8 * 2**k for k in range(40)) if n < len(x)] + [len(x)]
    ns = np.array(sorted(set(int(n) for n in ns if 1 <= n <= len(x))))
    from scipy import stats

    z = stats.norm.ppf(0.5 + confidence / 2)
    out = {"n": ns, "mean": np.zeros((len(ns), 3))}
    for qq in q:
        out[f"q{qq:g}"] = np.zeros((len(ns), 3))
    for i, n in enumerate(ns):
        xs = x[:n]
        m, se = xs.mean(), (xs.std(ddof=1) / np.sqrt(n) if n > 1 else np.nan)
        out["mean"][i] = m, m - z * se, m + z * se
        for qq in q:
            p = percentile(xs, qq, confidence)
            out[f"q{qq:g}"][i] = p["estimate"], p["low"], p["high"]
    return out


def _jansen(fA, fB, fAB):
    V = np.var(np.concatenate([fA, fB]), ddof=1)
    if not V > 0.0:
        return np.full(len(fAB), np.nan), np.full(len(fAB), np.nan), V
    # centred f_B: the same expectation (E[f_ABi - f_A] = 0) with a far smaller variance when the
    # output's mean is large against its spread (e.g. a deflection of 4 mm +- 0.1 mm)
    c = 0.5 * (np.mean(fA) + np.mean(fB))
    S = np.mean((fB[None, :] - c) * (fAB - fA[None, :]), axis=1) / V
    ST = 0.5 * np.mean((fA[None, :] - fAB) ** 2, axis=1) / V
    return S, ST, V


def sobol_indices(fA, fB, fAB, names=None, confidence: float = 0.95, resamples: int = 1000, seed: int = 0) -> dict:
    """First-order and total Sobol' indices of a scalar output from Saltelli's layout.

    fA, fB : (n,) outputs of the runs A and B; fAB : (k, n) outputs of the runs AB^i.
    Returns {'names', 'S1', 'ST', 'S1_low', 'S1_high', 'ST_low', 'ST_high', 'variance', 'n'}
    (intervals: bootstrap over the base samples)."""
    fA, fB = _values(fA, "f_A"), _values(fB, "f_B")
    fAB = np.asarray(fAB, dtype=float)
    if fAB.ndim != 2 or fAB.shape[1] != len(fA) or len(fB) != len(fA):
        raise StudyError(
            f"sobol_indices: f_AB must be (k, n) with n = {len(fA)} (the length of f_A and f_B); got {fAB.shape}"
        )
    k, n = fAB.shape
    if n < 2:
        raise StudyError("sobol_indices: at least 2 complete base samples are needed")
    S, ST, V = _jansen(fA, fB, fAB)
    if not V > 0.0:
        raise StudyError(
            "sobol_indices: the output does not vary over the samples (variance 0); its indices are not defined"
        )
    rng = np.random.default_rng(seed)
    bs, bt = np.zeros((resamples, k)), np.zeros((resamples, k))
    for r in range(resamples):
        i = rng.integers(0, n, n)
        bs[r], bt[r], _ = _jansen(fA[i], fB[i], fAB[:, i])
    a = (1.0 - confidence) / 2
    names = list(names) if names is not None else [f"x{i + 1}" for i in range(k)]
    return {
        "names": names,
        "S1": S,
        "ST": ST,
        "S1_low": np.nanquantile(bs, a, axis=0),
        "S1_high": np.nanquantile(bs, 1 - a, axis=0),
        "ST_low": np.nanquantile(bt, a, axis=0),
        "ST_high": np.nanquantile(bt, 1 - a, axis=0),
        "variance": float(V),
        "n": n,
    }


def sobol_convergence(fA, fB, fAB, ns=None) -> dict:
    """First-order and total indices from the first n base samples, n doubling from 8 (default):
    {'n': (m,), 'S1': (m, k), 'ST': (m, k)} (for the convergence of the indices with N)."""
    fA, fB, fAB = np.asarray(fA, float), np.asarray(fB, float), np.asarray(fAB, float)
    n = len(fA)
    if ns is None:
        ns = [m for m in (8 * 2**j for j in range(40)) if m < n] + [n]
    ns = np.array(sorted(set(int(m) for m in ns if 2 <= m <= n)))
    S1, ST = [], []
    for m in ns:
        a, b, _ = _jansen(fA[:m], fB[:m], fAB[:, :m])
        S1.append(a)
        ST.append(b)
    return {"n": ns, "S1": np.array(S1), "ST": np.array(ST)}


def component(values, index=None, name="output") -> np.ndarray:
    """A scalar series from an array output: ``values[:, *index]`` ((n,) when the output is scalar
    and index None)."""
    v = np.asarray(values, dtype=float)
    if index is None:
        if v.ndim != 1:
            raise StudyError(
                f"{name} has shape {v.shape[1:]} per sample; say which component (index=(step, "
                "component), e.g. (-1, 0))"
            )
        return v
    index = (index,) if np.isscalar(index) else tuple(index)
    try:
        return v[(slice(None),) + index]
    except IndexError:
        raise StudyError(f"{name}: index {index} is outside its shape {v.shape[1:]} per sample") from None
