"""Independent simulator of the latch pull-test rig of Stohlman & Pellegrino (Sec. III.B, Fig. 8), for test data.

Written from the paper's equations without :mod:`femast.elements.latch_law` or the ``latch-pull`` experiment,
so that data with partial reversals can test that model.  Differences in form on purpose:

* the latch law is evaluated in the paper's angle form, Eqs. 7-11 (``cos(theta) = x / (r + R)``,
  roller normal force ``F_n`` from Eq. 11, ``dT`` from Eq. 9 with the factor 2 on both terms),
  not the closed form of Eq. 14;
* the rig is a quasi-static simulation of the bead on a cable of stiffness ``k_cable`` (N/m)
  whose far end (the grip) follows a prescribed path: one cable is loaded per pass (``side`` +1:
  the outer cable pulls the bead out, -1: the inner cable, through the backstop, pulls it in),
  the other is slack.  Each grip increment finds the bead position by Coulomb stick/slip
  (static band ``[dT(dx<0), dT(dx>0)]``, Eq. 9 third case) with a march-and-bisect search; the
  backstop at ``x = -x_backstop`` takes any inward push;
* the recorded position is Eq. 15: the grip position minus the stretch of the loaded cable,
  ``x = c - dT / k_cable`` (the bead position while the cable is taut, the grip while it is slack).

Units: m, N, N/m inside; :func:`to_columns` gives the ``x_mm, dT_N, side`` columns.
"""

from __future__ import annotations

import math

import numpy as np


class SeedLatch:
    """Roller latch of Stohlman & Pellegrino, Sec. III.A (SI): r, R, h (m), k (N/m, one roller), mu (-), x_backstop (m)."""

    def __init__(self, r=1.1e-3, x_backstop=2.0e-3, k=1e5, mu=0.07, h=1.5e-3, R=2.4e-3):
        self.r, self.xb, self.k, self.mu, self.h, self.R = r, x_backstop, k, mu, h, R

    def dT(self, x: float, d: int) -> float:
        """Cable force jump T2 - T1 (N) that moves the bead at x (m) in direction d (+1 out, -1 in)."""
        rho = self.r + self.R
        if abs(x) >= rho:
            return 0.0  # zone (d): the rollers cannot reach the bead
        cos_t = x / rho  # Eq. 7
        sin_t = math.sqrt(1.0 - cos_t * cos_t)  # Eqs. 6 and 8
        delta = rho * sin_t - self.h - self.r  # Eq. 6 solved for the opening of one roller
        if delta <= 0.0:
            return 0.0
        F_pinch = self.k * delta  # Eq. 10
        F_n = F_pinch / (sin_t + d * self.mu * cos_t)  # Eq. 11 (friction opposes the motion)
        return -2.0 * F_n * (cos_t - d * self.mu * sin_t)  # Eq. 9, both rollers

    def band(self, x: float):
        """Static friction band (lo, hi) of dT (N) at x; lo = -inf on the backstop."""
        lo = -math.inf if x <= -self.xb else self.dT(x, -1)
        return lo, self.dT(x, +1)


def _first(f, a: float, b: float, step: float = 2e-7) -> float:
    """First x from a towards b where f(x) >= 0 (f(a) < 0), by marching then bisection."""
    sgn = 1.0 if b > a else -1.0
    x0 = a
    n = max(int(abs(b - a) / step), 1)
    for i in range(1, n + 1):
        x1 = a + sgn * min(i * step, abs(b - a))
        if f(x1) >= 0.0:
            lo, hi = x0, x1
            for _ in range(60):
                m = 0.5 * (lo + hi)
                if f(m) >= 0.0:
                    hi = m
                else:
                    lo = m
            return hi
        x0 = x1
    return b


def simulate(
    latch: SeedLatch, knots, side, n_per_m: float = 1.2e5, k_cable: float = 4e5, x_start=None, n_min: int = 60
):
    """Quasi-static pull test along a grip path.

    knots : grip positions (m, the bead position at which the loaded cable is just taut) visited
        in order; segments are sampled every ``1 / n_per_m`` m (at least ``n_min`` samples).
    side : loaded side of each segment (+1 outer cable, -1 inner cable), len(knots) - 1.
    x_start : initial bead position (default the backstop).
    Returns dict of arrays: ``c`` grip (m), ``x_bead`` (m), ``dT`` (N), ``x_meas`` (Eq. 15, m),
    ``side`` (+1/-1), ``slack`` (bool).
    """
    xb = -latch.xb if x_start is None else float(x_start)
    out = {k: [] for k in ("c", "x_bead", "dT", "x_meas", "side", "slack")}
    for a, b, s in zip(knots[:-1], knots[1:], side):
        n = max(int(abs(b - a) * n_per_m), n_min)
        for c in np.linspace(a, b, n + 1)[1:]:
            g = lambda x: s * k_cable * max(s * (c - x), 0.0)  # noqa: E731  cable force jump, N
            lo, hi = latch.band(xb)
            if g(xb) > hi:  # slides out to the first position where the latch holds it
                xb = _first(lambda x: latch.dT(x, +1) - g(x), xb, xb + 8e-3)
            elif g(xb) < lo:  # slides in, or onto the backstop
                xb = max(_first(lambda x: g(x) - latch.dT(x, -1), xb, -latch.xb - 1e-9), -latch.xb)
            dT = g(xb)
            out["c"].append(c)
            out["x_bead"].append(xb)
            out["dT"].append(dT)
            out["x_meas"].append(c - dT / k_cable)
            out["side"].append(s)
            out["slack"].append(dT == 0.0)
    return {k: np.asarray(v) for k, v in out.items()}


def to_columns(run: dict, noise_N: float = 0.5, noise_mm: float = 0.01, seed: int = 0, side: bool = True):
    """``latch-pull`` data columns (``x_mm``, ``dT_N`` and, if ``side``, ``side``) with Gaussian noise."""
    rng = np.random.default_rng(seed)
    n = run["dT"].size
    cols = {"x_mm": 1e3 * run["x_meas"] + rng.normal(0.0, noise_mm, n), "dT_N": run["dT"] + rng.normal(0.0, noise_N, n)}
    if side:
        cols["side"] = run["side"].astype(float)
    return cols


# ----------------------------------------------------------------------------- the test paths
def paths(latch: SeedLatch, k_cable: float = 4e5) -> dict:
    """Grip paths (knots m, sides, start) of the null cases: name -> (knots, side, x_start)."""
    xb = latch.xb
    stop = -xb
    hold_in = stop - 60.0 / k_cable  # inner cable pulls the seated bead with 60 N
    rel_out = latch.dT(-xb, +1)  # outer-cable force that lifts the bead off the backstop
    return {
        # hold on the backstop, unlatch out of contact, latch back into the backstop, hold
        "full strokes": ([stop, hold_in, stop, 4e-3, -1.2e-3, hold_in, stop], [-1, -1, +1, -1, -1, -1], None),
        # unlatching pass reversed behind the roller axis: the rollers pull the bead back, the
        # taut outer cable holds it on the latching branch down to the backstop
        "partial unlatching, zone (b)": (
            [stop, -0.8e-3, stop - 0.03e-3, -1.4e-3, stop - 0.03e-3, 4e-3],
            [+1, +1, +1, +1, +1],
            None,
        ),
        # reversed just in front of the roller axis: the outer cable goes slack and the bead stays;
        # the cable takes it up again on the way out
        "partial unlatching, zone (c)": ([stop, 0.12e-3, -1.0e-3, 4e-3], [+1, +1, +1], None),
        # latching pass reversed in zone (c) before the backstop: the rollers push the bead out
        # and the taut inner cable holds it on the unlatching branch
        "partial latching, zone (c)": ([4e-3, 0.5e-3, 4e-3, 0.9e-3, 4e-3], [-1, -1, -1, -1], 4e-3),
        # holds on the backstop: the inner cable pulls the seated bead, the outer cable pulls
        # it below the force that would lift it off
        "holds on the backstop": (
            [stop, hold_in, stop, stop + 0.8 * rel_out / k_cable, stop, stop - 30.0 / k_cable, stop],
            [-1, -1, +1, +1, -1, -1],
            None,
        ),
    }
