"""Residual analysis: noise floor, segmentation of the load path, residual signatures.

Noise floor
-----------
:func:`noise_floor` estimates the white-noise level of a channel from the second differences
of its residual along the path: for white noise ``e``, ``e[i+1] - 2 e[i] + e[i-1]`` has
variance ``6 sigma^2``, while a response that varies smoothly from one sample to the next
contributes little.  The median absolute deviation makes it robust to the few samples where
the residual jumps (a snap, a clearance being crossed).  It is computed on the residual of a
model, not on the raw channel, so the (large, curved) signal itself does not leak in.  It
assumes the path is sampled densely enough for the response to change little between rows;
on a coarse path it overestimates the noise (an upper bound).

Segments
--------
:func:`segment_path` splits the path along a signed scalar load ``s`` (the experiment's
``load_measure``) into overlapping kinds of segment:

* ``loading`` / ``unloading`` -- ``|s|`` increasing / decreasing (between reversals);
* ``reversal`` -- from a turning point of ``s`` until ``s`` has moved back by 15 % of its range
  (a turning point is confirmed when ``s`` moves back by more than ``max(5 % of the range,
  5 noise)``, so noise does not make reversals);
* ``near-zero load`` -- ``|s| < 10 %`` of ``max |s|``;
* ``peak`` -- around a turning point with ``|s| > 50 % max |s|``, the samples with ``|s|`` at
  least 85 % of the turning value;
* the experiment's own kinds (``extra_segments``).

Signatures
----------
:func:`signatures` regresses the whitened residual on simple functions of the path (the
direction of loading, the sign of the load, the load, its square-law nonlinearity, time,
time x load, a constant) one at a time and reports the fraction of the residual each explains;
this is the plain-language reading of what the model misses.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

#: Fractions of the load range / peak used by the segmentation (see the module docstring).
TURN_FRACTION = 0.05
REVERSAL_WINDOW = 0.15
NEAR_ZERO = 0.10
PEAK_LEVEL = 0.85
PEAK_MIN = 0.50


def noise_floor(r) -> float:
    """Robust white-noise standard deviation of a residual series r (n,), same unit as r."""
    r = np.asarray(r, dtype=float)
    if r.size < 5:
        return float(np.std(r)) if r.size else 0.0
    d2 = r[2:] - 2.0 * r[1:-1] + r[:-2]
    mad = np.median(np.abs(d2 - np.median(d2)))
    sigma = 1.4826 * mad / np.sqrt(6.0)
    if sigma <= 0.0:  # more than half the second differences vanish (piecewise-constant residual)
        nz = d2[d2 != 0.0]
        sigma = float(np.sqrt(np.mean(nz**2) / 6.0)) if nz.size else 0.0
    return float(sigma)


#: Share of the largest whitened residuals a ratio leaves out (:func:`robust_rms`).
TRIM = 0.02


def robust_rms(z) -> float:
    """RMS of a whitened residual z (any shape), robust to spikes and heavy tails.

    The ``TRIM`` (2 %) largest ``|z|`` are left out (at least one value from 25 values on) and the
    mean square of the rest is divided by its expectation for Gaussian noise, so white Gaussian
    noise of unit level gives 1.  Ratios of a model's error to the noise use it for their numerator,
    as the noise level uses a robust scale for its denominator (:func:`noise_floor`): spikes or a
    heavy tail make a model at the noise look much less above it (Student-t noise with 3 degrees
    of freedom, 66 rows: 1.14 on average, 95th percentile 1.52, where the plain RMS gives 1.29 and
    1.86; 500 rows: 1.08 and 1.18 against 1.30 and 1.59), while structure that acts on more than
    2 % of the rows -- a mechanism -- still shows (5 % would bring Student-t to 1.06 and 1.38 at 66
    rows but hide a latch hysteresis acting near the seated bead only).  Gaussian noise: 95th
    percentile 1.27 (66 rows), 1.10 (500 rows), which :func:`at_noise_threshold` allows for."""
    a = np.sort(np.abs(np.asarray(z, dtype=float).ravel()))
    n = a.size
    if n == 0:
        return 0.0
    k = int(TRIM * n) if n >= 25 else 0
    if k == 0:
        return float(np.sqrt(np.mean(a * a)))
    q = 1.0 - k / n  # kept share; Gaussian E[z^2 | |z| < c] with P(|z| < c) = q
    c = _norm_ppf(0.5 + 0.5 * q)
    m2 = 1.0 - 2.0 * c * np.exp(-0.5 * c * c) / np.sqrt(2.0 * np.pi) / q
    return float(np.sqrt(np.mean(a[: n - k] ** 2) / m2))


def _norm_ppf(p: float) -> float:
    from scipy.special import ndtri

    return float(ndtri(p))


#: Smallest threshold of "at the noise floor" (RMS error / estimated noise), see :func:`at_noise_threshold`.
AT_NOISE = 1.2
#: Fraction of pure-noise data sets of a given size that :func:`at_noise_threshold` calls "at the noise".
AT_NOISE_QUANTILE = 0.95


@lru_cache(maxsize=256)
def at_noise_threshold(n_rows: int, n_channels: int = 1) -> float:
    """Ratio RMS / estimated noise below which a model counts as *at the noise floor* for a data set
    of ``n_rows`` rows and ``n_channels`` channels: ``AT_NOISE`` (1.2), or more for short data sets.

    The noise is estimated from the residual itself (:func:`noise_floor`) and the ratio is
    :func:`robust_rms` of the whitened residual, so even a perfect model's ratio scatters: for 45 rows of one channel it exceeds 1.2 in 17 % of data sets (1.38 at the
    95th percentile), for 500 rows in none.  The threshold is the larger of ``AT_NOISE`` and the
    ``AT_NOISE_QUANTILE`` (95 %) quantile of that ratio for white noise of this size (Monte Carlo,
    2000 draws, fixed seed; from 400 rows on it is below 1.2 and not computed).  Long data sets
    (mast-top, latch-pull: hundreds of rows) keep 1.2; the FE experiments (40-80 rows) get 1.3-1.4.
    """
    n_rows, n_channels = int(n_rows), max(int(n_channels), 1)
    if n_rows >= 400 or n_rows < 5:
        return AT_NOISE
    rng = np.random.default_rng(20240607)
    z = rng.standard_normal((2000, n_channels, n_rows))
    d2 = z[..., 2:] - 2.0 * z[..., 1:-1] + z[..., :-2]
    mad = np.median(np.abs(d2 - np.median(d2, axis=-1, keepdims=True)), axis=-1)
    sigma = 1.4826 * mad / np.sqrt(6.0)  # noise_floor, vectorised (white noise: no zero MAD)
    ratio = np.array([robust_rms(zi / si[:, None]) for zi, si in zip(z, sigma)])
    return float(max(AT_NOISE, np.quantile(ratio, AT_NOISE_QUANTILE)))


def turning_points(s, h: float):
    """Turning points of s (n,) confirmed by a move back of at least h; returns (indices, direction).

    direction[i] is +1 where s is rising towards sample i, -1 where it is falling (the turning
    sample belongs to the run that ends there).  Before the first confirmed move the direction of
    the first run is used.
    """
    s = np.asarray(s, dtype=float)
    n = s.size
    tps = []
    d = 0
    i_max = i_min = i_ext = 0
    for i in range(1, n):
        if d == 0:
            if s[i] > s[i_max]:
                i_max = i
            if s[i] < s[i_min]:
                i_min = i
            if s[i] - s[i_min] >= h:
                d, i_ext = 1, i
                if i_min > 0:
                    tps.append(i_min)
            elif s[i_max] - s[i] >= h:
                d, i_ext = -1, i
                if i_max > 0:
                    tps.append(i_max)
        elif d == 1:
            if s[i] >= s[i_ext]:
                i_ext = i
            elif s[i_ext] - s[i] >= h:
                tps.append(i_ext)
                d, i_ext = -1, i
        else:
            if s[i] <= s[i_ext]:
                i_ext = i
            elif s[i] - s[i_ext] >= h:
                tps.append(i_ext)
                d, i_ext = 1, i
    direction = np.empty(n)
    bounds = [0] + [t + 1 for t in tps] + [n]
    first = d if not tps else (1.0 if s[tps[0]] > s[0] else -1.0)
    cur = first if first != 0 else 1.0
    for k in range(len(bounds) - 1):
        direction[bounds[k] : bounds[k + 1]] = cur
        cur = -cur
    return np.asarray(tps, dtype=int), direction


@dataclass(frozen=True)
class Segment:
    """A contiguous part of the path: rows ``start`` to ``stop - 1`` of kind ``kind``."""

    kind: str
    start: int
    stop: int

    @property
    def n(self) -> int:
        return self.stop - self.start


def _runs(mask, kind):
    mask = np.asarray(mask, bool)
    if not mask.any():
        return []
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.view(np.int8), [0]])))
    return [Segment(kind, int(a), int(b)) for a, b in zip(edges[::2], edges[1::2])]


def load_path(exp, data) -> np.ndarray:
    """The signed load that drives the segmentation (:func:`segment_path`) of an experiment's data
    (an :class:`~femast.experiments.Experiment` and its :class:`~femast.experiments.Measured`):
    ``exp.load_measure`` (else the first input
    column); a load with several axes ((n, k): a moment about two axes) is taken along its principal
    direction (:func:`principal_load`)."""
    if exp.load_measure is not None:
        s = np.asarray(exp.load_measure(data, exp.options), dtype=float)
        return principal_load(s) if s.ndim == 2 else s
    inputs = [c.name for c in exp.columns if c.required and c.name not in exp.channels]
    return data[inputs[0]] if inputs else np.arange(data.n, dtype=float)


def principal_load(L) -> np.ndarray:
    """(n,) a load of several axes (n, k) projected on its principal direction (the largest singular
    vector), signed so that its largest value is positive."""
    L = np.asarray(L, float)
    if L.ndim == 1 or L.shape[1] == 1:
        return L.reshape(len(L))
    if not np.any(L):
        return np.zeros(len(L))
    _, _, Vt = np.linalg.svd(L, full_matrices=False)
    s = L @ Vt[0]
    return s if s[np.argmax(np.abs(s))] > 0 else -s


def segment_path(s, noise_s: float = 0.0, extra=()):
    """Split the path of the signed load s (n,) into segments (see the module docstring).

    noise_s : noise of s (its unit), so that noise does not create reversals.
    extra : ``[(kind, mask)]`` of experiment-specific segments.
    Returns ``(segments, masks)``: the list of :class:`Segment` and ``{kind: (n,) bool}``.
    """
    s = np.asarray(s, dtype=float)
    n = s.size
    rng = float(np.ptp(s)) if n else 0.0
    smax = float(np.max(np.abs(s))) if n else 0.0
    masks = {}
    if rng > 0.0:
        tps, direction = turning_points(s, max(TURN_FRACTION * rng, 5.0 * noise_s))
        growing = direction * np.sign(s) > 0
        rev = np.zeros(n, bool)
        peak = np.zeros(n, bool)
        for t in tps:
            j = t
            while j < n and abs(s[j] - s[t]) <= REVERSAL_WINDOW * rng:
                rev[j] = True
                j += 1
            if abs(s[t]) >= PEAK_MIN * smax:
                lo = t
                while lo > 0 and s[lo - 1] * s[t] > 0 and abs(s[lo - 1]) >= PEAK_LEVEL * abs(s[t]):
                    lo -= 1
                hi = t
                while hi < n - 1 and s[hi + 1] * s[t] > 0 and abs(s[hi + 1]) >= PEAK_LEVEL * abs(s[t]):
                    hi += 1
                peak[lo : hi + 1] = True
        masks["loading"] = growing & ~rev
        masks["unloading"] = ~growing & ~rev
        masks["reversal"] = rev
        masks["near-zero load"] = np.abs(s) < NEAR_ZERO * smax
        masks["peak"] = peak
    for kind, m in extra:
        masks[kind] = np.asarray(m, bool)
    segments = [seg for kind, m in masks.items() for seg in _runs(m, kind)]
    return segments, masks


def _stats(rows, residuals, sigma, weights):
    """RMS in the error unit, ratio to the noise and mean (per channel) over the rows."""
    e2, z2, means = [], [], {}
    for c, r in residuals.items():
        rr = r[rows]
        sc = sigma[c][rows] if np.ndim(sigma[c]) else sigma[c]  # per-row noise (heteroscedastic) or one level
        e2.append((weights[c] * rr) ** 2)
        z2.append((rr / sc) ** 2)
        means[c] = float(np.mean(rr)) if rr.size else 0.0
    e2 = np.concatenate(e2)
    z2 = np.concatenate(z2)
    return float(np.sqrt(e2.mean())), float(np.sqrt(z2.mean())), means


def segment_report(segments, masks, residuals, sigma, weights, lines=None, min_rows: int = 3):
    """Error per segment and per kind of segment.

    residuals, sigma, weights : ``{channel: ...}`` residual arrays, noise levels, and factors to the
    error unit.  Returns ``(by_kind, worst)``: ``by_kind`` a list of dicts (kind, n, rms, ratio, mean)
    sorted worst first, ``worst`` the segments (kind, rows, file lines, n, rms, ratio, mean) sorted
    worst first, those shorter than ``min_rows`` left out.
    """
    by_kind = []
    for kind, m in masks.items():
        rows = np.flatnonzero(m)
        if rows.size < min_rows:
            continue
        rms, ratio, means = _stats(rows, residuals, sigma, weights)
        by_kind.append({"kind": kind, "n": int(rows.size), "rms": rms, "ratio": ratio, "mean": means})
    by_kind.sort(key=lambda d: -d["ratio"])
    worst = []
    for seg in segments:
        if seg.n < min_rows:
            continue
        rows = np.arange(seg.start, seg.stop)
        rms, ratio, means = _stats(rows, residuals, sigma, weights)
        d = {
            "kind": seg.kind,
            "start_row": seg.start,
            "end_row": seg.stop - 1,
            "n": seg.n,
            "rms": rms,
            "ratio": ratio,
            "mean": means,
        }
        if lines is not None:
            d["first_line"], d["last_line"] = int(lines[seg.start]), int(lines[seg.stop - 1])
        worst.append(d)
    worst.sort(key=lambda d: -d["ratio"])
    return by_kind, worst


#: Regressors of :func:`signatures` and what a residual that follows them suggests.
SIGNATURE_READINGS = {
    "offset": "a constant offset (a zero error of the measurement or of the unloaded state)",
    "load": "proportional to the load (a stiffness error: fit the parameters with --fit)",
    "sign of the load": "a step where the load changes sign (clearance / backlash)",
    "direction of loading": "a change of sign with the direction of loading (friction or hysteresis)",
    "load nonlinearity": "odd and growing faster than the load (a stiffness that changes with the load)",
    "time": "a slow change with time (a drift: temperature, creep, a zero shift)",
    "time x load": "a compliance that changes with time (pretension loss, creep)",
}


def signatures(s, direction, tau, residuals, sigma):
    """Fraction of the whitened residual explained by each path regressor (see the module docstring).

    s : (n,) signed load.  direction : (n,) +-1 direction of loading.  tau : (n,) normalised time.
    residuals, sigma : ``{channel: residual}``, ``{channel: noise}``.
    Returns a list of dicts ``{"name", "fraction", "reading"}``, largest fraction first; the
    fraction is of the residual sum of squares in excess of the noise (``n`` per channel).
    """
    s = np.asarray(s, float)
    smax = np.max(np.abs(s)) or 1.0
    u = s / smax
    regs = {
        "offset": np.ones_like(u),
        "load": u,
        "sign of the load": np.tanh(u / 0.02),
        "direction of loading": np.asarray(direction, float),
        "load nonlinearity": u * np.abs(u),
        "time": np.asarray(tau, float) - 0.5,
        "time x load": (np.asarray(tau, float) - 0.5) * u,
    }
    Z = np.column_stack([residuals[c] / sigma[c] for c in residuals])
    n = Z.shape[0]
    excess = max(float((Z**2).sum()) - n * Z.shape[1], 1e-12)
    out = []
    for name, g in regs.items():
        gg = float(g @ g)
        if gg <= 0:
            continue
        explained = float(((g @ Z) ** 2).sum() / gg)
        out.append(
            {
                "name": name,
                "fraction": min(explained / excess, 1.0) if excess > 1e-12 else 0.0,
                "reading": SIGNATURE_READINGS[name],
            }
        )
    out.sort(key=lambda d: -d["fraction"])
    return out
