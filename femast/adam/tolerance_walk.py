"""The length tolerances of an ADAM mast's longerons, added up over its bays in closed form: the
deployed tip's axial error, tilt and lateral error as a random walk (``docs/shape_accuracy.md``).

Each longeron of bay j at corner k has a length error d_jk, independent and uniform in [-a, a]
(``a``: the tolerance, m).  Members are rigid, frames are rigid squares of side b, bays have
height l.  A bay sets the pose of its top frame relative to its bottom frame by three numbers: the
rise h of the frame's centre and its tilt, a small rotation vector w = (w_x, w_y), from the plane
z = h + s_x x + s_y y through the top ends of the four longerons (w = (s_y, -s_x)).  Corners are
numbered counter-clockwise from (+b/2, +b/2), as in :func:`femast.adam.build.corner_xy`.

**Tied joints** (the paper's two-way tie, ``seat="tied"``): the four longeron ends pull the frame
to the plane that fits them best (the warping of the frame is orthogonal to its rigid motions, so
the rigid part of the misfit is its least-squares projection)::

    h = (d0 + d1 + d2 + d3) / 4                  E h = 0,   Var h = a^2 / 12
    s_x = (d0 - d1 - d2 + d3) / (2 b)            Var s_x = Var s_y = a^2 / (3 b^2)
    s_y = (d0 + d1 - d2 - d3) / (2 b)            E |w|^2 = 2 a^2 / (3 b^2)

**Seated joints** (``seat="seated"``): a seat only pushes.  The cables pull the frame down onto
the longeron ends; it rests on the upper hull of the four ends: on the *ridge*, the diagonal pair
whose mean height is larger, and it rocks about that diagonal only as far as it must to clear the
other two ends (the cables hold it level otherwise).  With S the ridge's mean height, v the
difference of the ridge's two ends and e = (d_p - S)_+ - (d_m - S)_+ for the two other corners
p, m (p on the positive side of the across direction)::

    h = max((d0 + d2) / 2, (d1 + d3) / 2)
      E h = E |U1 - U2| / 2 = 7 a / 30        (U = mean of two errors, triangular on [-a, a])
      Var h = E U^2 - (E h)^2 = a^2 / 6 - (7 a / 30)^2 = 101 a^2 / 900
            (E max(U1, U2)^2 = E U^2: max^2 and min^2 have one distribution)
    slope along the ridge  v / (sqrt 2 b),   E v^2 = 2 a^2 / 3 (the ridge's choice leaves it unbiased)
    slope across the ridge e / (b / sqrt 2), E e^2 = a^2 / 20 (integrated over the triangular S and
                                             the two other errors, given that their mean is below S)
    E |w|^2 = a^2 / (3 b^2) + a^2 / (10 b^2) = 13 a^2 / (30 b^2)

The seated mast is therefore *longer* on average than the nominal one (7 a / 30 per bay: the frame
sits on the longer diagonal), and its tilt walks more slowly than the tied mast's (sqrt(13/20)).

**The walk.**  Over n bays, to first order in the errors, the tip's axial error is sum_j h_j, its
tilt W = sum_j w_j, and its lateral error u = l sum_j (n - j + c) (w_j x e_z), j = 1..n: the tilt of
bay j turns the n - j bays above it, and bay j's own top frame moves sideways by c l w_j.  c = 1/2:
a bay tilts about its mid-height (the side's two cable diagonals stay equal, which puts the top
batten's midpoint half a bay height over; a one-bay FE model gives 0.4995).  The bays are
independent, so (central limit theorem) the axial error is normal, N(n E h, n Var h), and W and u
are isotropic normal vectors (the seated bay's two ridges are equally likely: isotropic on
average) with per-component variances

    sigma_W^2 = n E|w|^2 / 2,       sigma_u^2 = l^2 (E|w|^2 / 2) sum_{k=0}^{n-1} (k + c)^2,

so |W| and |u| follow Rayleigh laws: their q-quantile is sigma sqrt(-2 ln(1 - q)).  The q-quantile
of |axial| solves Phi((x - m) / s) - Phi((-x - m) / s) = q.

**The lean (second order).**  Bay j stands tilted by the walk's own tilt W_(j-1) below it (its
upper part by W_(j-1) + w_j), so its height is shorter by (l / 2) |W|^2: with E |W_j|^2 = j E|w|^2,
the tip comes down on average by (l E|w|^2 / 2) (n (n - 1) / 2 + c n), with a spread whose variance
is (l E|w|^2)^2 n^4 / 24 to leading order (Var sum_j |W_j|^2 = (E|w|^2)^2 sum_ij min(i, j)^2 for the
normal walk), added to the first-order axial error (``lean=True``, the default).  It is 2 um at
40 bays and 140 um at 350 bays (tied joints): the 350-bay axial 95th percentile is 634 um with
it, 529 um without.  The FE model has it; comparing with the FE, keep it.

For the tolerances of the shape-accuracy study (a = 0.05 mm, b = 0.25 m, l = 0.171 m) at the 95th
percentile, tied joints, first order: 40 bays 179 um axial, 369 arcsec tilt, 7.06 mm lateral;
350 bays 529 um, 1091 arcsec, 182.7 mm (with c = 1, a bay tilting about its base, the lateral
errors would be 7.19 mm and 183.1 mm; with the lean, the 350-bay axial error is 634 um).  Seated
joints: 40 bays 640 um, 297 arcsec, 5.69 mm; 350 bays 4.52 mm, 879 arcsec, 147.3 mm (with the
lean).  ``python -m femast.benchmarks.tolerance_walk`` prints them beside a Monte Carlo of the
chained bays.

Only the longerons' errors enter: battens, arm and latch cables move frames within their plane or
change cable tensions, which rigid frames on rigid longerons do not feel to first order (the FE
study shows what they add).  Units: SI (m, rad).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .parameters import BayParameters

SEATS = ("tied", "seated")
#: The part of a bay's height between the pivot of its own tilt and its top frame (1/2: the bay tilts
#: about its mid-height; 1: about its bottom frame).
MID_HEIGHT = 0.5


def _check(seat: str, tolerance: float) -> None:
    if seat not in SEATS:
        raise ModelError(f"tolerance walk: seat = {seat!r}; use 'tied' or 'seated'")
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise ModelError(f"tolerance walk: tolerance = {tolerance!r} m must be a finite number > 0")
    if tolerance > 0.01:
        raise ModelError(f"tolerance walk: tolerance = {tolerance:g} m is implausible for a longeron; give it in m")


def bay_pose(dL, b: float, seat: str = "seated") -> tuple:
    """Rise h (m) and tilt w = (w_x, w_y) (rad) of a bay's top frame from its four longerons' length
    errors ``dL`` (..., 4) in m, rigid members (module docstring).  Returns (h (...,), w (..., 2))."""
    d = np.asarray(dL, dtype=float)
    if d.shape[-1:] != (4,):
        raise ModelError(f"bay_pose: dL must have 4 values (one per corner) in its last axis, got shape {d.shape}")
    _check(seat, max(float(np.abs(d).max(initial=0.0)), 1e-300))
    if seat == "tied":
        h = d.mean(axis=-1)
        sx = (d[..., 0] - d[..., 1] - d[..., 2] + d[..., 3]) / (2 * b)
        sy = (d[..., 0] + d[..., 1] - d[..., 2] - d[..., 3]) / (2 * b)
    else:
        s02, s13 = 0.5 * (d[..., 0] + d[..., 2]), 0.5 * (d[..., 1] + d[..., 3])
        ridge02 = s02 >= s13
        h = np.where(ridge02, s02, s13)
        # along the ridge: from its second end to its first; across: to the corner that follows the first
        first, second = np.where(ridge02, d[..., 0], d[..., 1]), np.where(ridge02, d[..., 2], d[..., 3])
        plus, minus = np.where(ridge02, d[..., 1], d[..., 2]), np.where(ridge02, d[..., 3], d[..., 0])
        along = (first - second) / (math.sqrt(2.0) * b)
        across = (np.maximum(plus - h, 0.0) - np.maximum(minus - h, 0.0)) * math.sqrt(2.0) / b
        r = 1.0 / math.sqrt(2.0)  # unit vectors: corner 0 at (+r, +r), corner 1 at (-r, +r)
        a_x, a_y = np.where(ridge02, r, -r), r
        c_x, c_y = np.where(ridge02, -r, -r), np.where(ridge02, r, -r)
        sx = along * a_x + across * c_x
        sy = along * a_y + across * c_y
    return h, np.stack([sy, -sx], axis=-1)


def bay_moments(tolerance: float, b: float, seat: str = "seated") -> dict:
    """Moments of one bay with longeron errors uniform in [-tolerance, tolerance] (m), frame side b
    (m): {"mean_h" (m), "var_h" (m^2), "tilt_ms": E |w|^2 (rad^2)} (module docstring)."""
    a = float(tolerance)
    _check(seat, a)
    if seat == "tied":
        return {"mean_h": 0.0, "var_h": a * a / 12.0, "tilt_ms": 2.0 * a * a / (3.0 * b * b)}
    return {"mean_h": 7.0 * a / 30.0, "var_h": 101.0 * a * a / 900.0, "tilt_ms": 13.0 * a * a / (30.0 * b * b)}


def lateral_weight(n_bays: int, pivot: float = MID_HEIGHT) -> float:
    """sum_{k=0}^{n-1} (k + pivot)^2: the lateral error's variance per unit of l^2 times a bay's
    per-component tilt variance."""
    n = int(n_bays)
    return (n - 1) * n * (2 * n - 1) / 6.0 + pivot * n * (n - 1) + n * pivot * pivot


def abs_normal_quantile(mean: float, sd: float, q: float) -> float:
    """q-quantile of |X| for X normal with ``mean`` and standard deviation ``sd``."""
    from scipy import optimize, stats

    if sd <= 0:
        return abs(mean)

    def f(x):
        return stats.norm.cdf((x - mean) / sd) - stats.norm.cdf((-x - mean) / sd) - q

    hi = abs(mean) + 10 * sd
    return float(optimize.brentq(f, 0.0, hi, xtol=1e-14 * hi))


def rayleigh_quantile(sigma: float, q: float) -> float:
    """q-quantile of |X| for X an isotropic 2-D normal vector with per-component deviation sigma."""
    return float(sigma * math.sqrt(-2.0 * math.log1p(-q)))


@dataclass(frozen=True)
class ToleranceWalk:
    """The deployed tip errors of an n-bay mast as a random walk (m, rad): the axial error is
    normal (``axial_mean``, ``axial_sd``); tilt and lateral error are isotropic normal vectors with
    per-component deviations ``tilt_sigma`` and ``lateral_sigma``."""

    n_bays: int
    seat: str
    tolerance: float
    axial_mean: float
    axial_sd: float
    tilt_sigma: float
    lateral_sigma: float
    pivot: float

    def quantiles(self, q: float = 0.95) -> dict:
        """{"axial" (m), "tilt" (rad), "lateral" (m)}: the q-quantiles of |axial|, |tilt|, |lateral|."""
        if not 0.0 < q < 1.0:
            raise ModelError(f"ToleranceWalk.quantiles: q = {q!r} must lie in (0, 1) (0.95 for the 95th percentile)")
        return {
            "axial": abs_normal_quantile(self.axial_mean, self.axial_sd, q),
            "tilt": rayleigh_quantile(self.tilt_sigma, q),
            "lateral": rayleigh_quantile(self.lateral_sigma, q),
        }

    def cdf(self, what: str, x) -> np.ndarray:
        """P(|what| <= x) for what in ("axial", "tilt", "lateral"), x in m or rad."""
        from scipy import stats

        x = np.asarray(x, dtype=float)
        if what == "axial":
            if self.axial_sd == 0:
                return (x >= abs(self.axial_mean)).astype(float)
            return stats.norm.cdf((x - self.axial_mean) / self.axial_sd) - stats.norm.cdf(
                (-x - self.axial_mean) / self.axial_sd
            )
        sigma = {"tilt": self.tilt_sigma, "lateral": self.lateral_sigma}.get(what)
        if sigma is None:
            raise ModelError(f"ToleranceWalk.cdf: what = {what!r}; use 'axial', 'tilt' or 'lateral'")
        return -np.expm1(-0.5 * (np.maximum(x, 0.0) / sigma) ** 2)


def tolerance_walk(
    n_bays: int,
    tolerance: float = 0.05e-3,
    params: BayParameters | None = None,
    seat: str | None = None,
    pivot: float = MID_HEIGHT,
    lean: bool = True,
) -> ToleranceWalk:
    """The closed-form random walk of the longerons' length errors (uniform in +-``tolerance``, m)
    over ``n_bays`` bays of ``params`` (frame side b, bay height l; default BayParameters()); ``seat``
    defaults to ``params.seat`` when the parameters have one, else "tied".  ``pivot``: the part of
    a bay's height between the pivot of its own tilt and its top frame; ``lean``: add the second-order
    shortening of the bays leaning with the walk's own tilt to the axial error (module docstring;
    False: the first-order walk)."""
    if not (isinstance(n_bays, (int, np.integer)) and n_bays >= 1):
        raise ModelError(f"tolerance_walk: n_bays = {n_bays!r} must be an integer >= 1")
    p = params or BayParameters()
    seat = seat or getattr(p, "seat", "tied")
    mom = bay_moments(tolerance, p.b, seat)
    n = int(n_bays)
    m = mom["tilt_ms"]
    per_component = m / 2.0
    # second order: the bays lean with the walk's own tilt, cos(Theta) shortens each one
    lean_mean = 0.5 * p.l * m * (0.5 * n * (n - 1) + pivot * n) if lean else 0.0
    lean_var = (p.l * m) ** 2 * n**4 / 24.0 if lean else 0.0
    return ToleranceWalk(
        n_bays=n,
        seat=seat,
        tolerance=float(tolerance),
        axial_mean=n * mom["mean_h"] - lean_mean,
        axial_sd=math.sqrt(n * mom["var_h"] + lean_var),
        tilt_sigma=math.sqrt(n * per_component),
        lateral_sigma=p.l * math.sqrt(per_component * lateral_weight(n, pivot)),
        pivot=float(pivot),
    )


__all__ = [
    "SEATS",
    "MID_HEIGHT",
    "ToleranceWalk",
    "abs_normal_quantile",
    "bay_moments",
    "bay_pose",
    "lateral_weight",
    "rayleigh_quantile",
    "tolerance_walk",
]
