"""Latch law of Stohlman & Pellegrino (section III.A, Eqs. 6-14): force jump across a roller latch.

The latch is two friction rollers (radius ``r``) on cantilever springs gripping a
spherical bead (radius ``R``) fixed on the cable, with a backstop behind the
rollers.  All quantities are SI (m, N, N/m); the paper's fit is given in mm and
N/mm and converted by :meth:`LatchParameters.adam_fit`.

Coordinates and signs (checked against Figs. 6, 7 and 10 of the paper)
-----------------------------------------------------------------------
* ``x`` (m) is the axial distance from the roller axis (the line through the two
  roller centres) to the bead centre, positive on the *outside* of the latch
  ("distance to latch" in Figs. 6 and 10).  ``dx > 0`` moves the bead out of the
  latch (unlatching), ``dx < 0`` moves it in (latching).
* The backstop is *behind* the rollers, at ``x = -x_backstop``.  The paper writes
  "x_backstop = 2.0 mm ... prevents further motion in the -x direction"; with
  rollers touching the bead only for ``|x| < 2.34 mm`` a backstop at ``+2.0 mm``
  would stop the bead before the roller axis and the latch could never latch,
  and the data of Figs. 6, 9 and 10 start at ``x = -2 mm``.  So ``x_backstop`` is
  read as the distance of the backstop behind the roller axis.
* ``dT = T2 - T1`` (N), Eq. 5, with section 1 on the backstop side (where the
  bead is when latched) and section 2 on the outside.  Equilibrium of the bead
  gives ``dT = -F_latch``, with ``F_latch`` the axial force of the rollers on the
  bead (positive outward).  Pulling the bead in needs ``dT < 0`` (T1 > T2), pulling
  it out needs ``dT > 0``.

Equations
---------
Contact (Eq. 6): ``x**2 + (h + delta + r)**2 = (r + R)**2``, so the opening of one
roller is (Eq. 10)::

    delta(x) = sqrt((r + R)**2 - x**2) - h - r      (contact when delta > 0)

``theta`` is the angle between the latch centre-line and the line of centres,
``cos(theta) = x / (r + R)`` (Eq. 7), ``sin(theta) = (h + delta + r) / (r + R)``
(Eq. 8).  Each roller pushes the bead with ``kappa * delta`` normal to the
centre-line (Eqs. 10-11), ``kappa = k``, and the friction ``|F_f| <= mu F_n``
opposes the motion.  With ``y = h + delta + r`` (Eq. 14)::

    dT_in(x)  = -2 k delta (x + mu y) / (y - mu x)     dx < 0  (latching)
    dT_out(x) = -2 k delta (x - mu y) / (y + mu x)     dx > 0  (unlatching)

and ``dT_in <= dT_out``.  When the bead does not move (stick), static friction
holds any ``dT`` in ``[dT_in(x), dT_out(x)]``; against the backstop the lower
bound is ``-inf`` (the backstop takes any inward pull).  No contact
(``|x| >= x_contact``) gives ``dT = 0``.

Corrections to the paper's text
----------------------------
* Eq. 9 is printed ``-2 F_n cos(theta) - mu F_n sin(theta)``; the factor 2 (two
  rollers) multiplies both terms, as Eqs. 12-13 confirm.
* "F_pinch is the sum of the vertical components of the forces on the bead"
  contradicts Eqs. 11-13, which balance ``F_pinch = k delta`` against *one*
  roller's force and then double it.  ``k`` is therefore the stiffness of one
  roller's cantilever (N/m), and the fitted ``k = 100 N/mm`` belongs to that
  reading.
* Section III.B says a latching test cannot hold a *negative* ``dT``.  With the
  signs of Eqs. 5 and 14 it is the other way round: a latching test pulls
  section 1 with section 2 slack, so ``dT = -T1 <= 0``; the positive part of the
  latching branch (just behind the roller axis, where the rollers snap the bead
  in) is the part that cannot be measured.

Zones (Fig. 6; the figure is not legible in the text extraction, this is our
reading of its three colours and four labels): (a) bead against the backstop,
fully latched (red); (b) in roller contact behind the roller axis,
``-x_backstop < x < 0`` (yellow); (c) in roller contact in front of the axis,
``0 <= x < x_contact`` (yellow); (d) no contact, unlatched (green).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
from numba import njit

from .._moved import renamed
from ..errors import ModelError

# Direction of motion of the bead.
LATCHING = -1  # dx < 0
UNLATCHING = +1  # dx > 0

ZONE_BACKSTOP = 0  # (a)
ZONE_BEHIND_AXIS = 1  # (b)
ZONE_IN_FRONT = 2  # (c)
ZONE_FREE = 3  # (d)
ZONE_LABELS = ("(a) at backstop", "(b) behind roller axis", "(c) in front of roller axis", "(d) no contact")


@dataclass(frozen=True)
class LatchParameters:
    """Parameters of the latch law (Stohlman & Pellegrino, Section III.A), SI units.

    r : roller radius, m.
    x_backstop : distance of the backstop behind the roller axis, m (backstop at x = -x_backstop).
    k : stiffness of one roller's cantilever, N/m (Eq. 10: F_pinch = k delta).
    mu : Coulomb friction coefficient between roller and bead (static = kinetic), -.
    h : half the initial roller separation (the gap is 2h), m.
    R : bead radius, m.
    """

    r: float = 1.1e-3
    x_backstop: float = 2.0e-3
    k: float = 100e3
    mu: float = 0.07
    h: float = 1.5e-3
    R: float = 2.4e-3

    @classmethod
    def adam_fit(cls) -> LatchParameters:
        """The fit of the ADAM latch by Stohlman & Pellegrino, Section III.C: r = 1.1 mm,
        x_backstop = 2.0 mm, k = 100 N/mm, mu = 0.07, h = 1.5 mm, R = 2.4 mm (returned in SI)."""
        return cls(r=1.1e-3, x_backstop=2.0e-3, k=100e3, mu=0.07, h=1.5e-3, R=2.4e-3)

    @classmethod
    def seed_fit(cls) -> LatchParameters:
        """Old name of :meth:`adam_fit`: warns, and is removed in femast 0.3."""
        renamed("LatchParameters.seed_fit()", "LatchParameters.adam_fit()")
        return cls.adam_fit()

    @classmethod
    def from_mm(cls, r, x_backstop, k, mu, h, R) -> LatchParameters:
        """Build from lengths in mm and k in N/mm (the paper's units)."""
        return cls(r=r * 1e-3, x_backstop=x_backstop * 1e-3, k=k * 1e3, mu=mu, h=h * 1e-3, R=R * 1e-3)

    def as_array(self) -> np.ndarray:
        """[r, x_backstop, k, mu, h, R] as a float array (SI), the layout of the kernels."""
        return np.array([self.r, self.x_backstop, self.k, self.mu, self.h, self.R], dtype=float)

    @property
    def contact_half_width(self) -> float:
        """x_contact = sqrt((r+R)^2 - (h+r)^2), m: rollers touch the bead for |x| < x_contact (Eq. 6)."""
        return contact_half_width(self)

    def validate(self, where: str = "latch") -> LatchParameters:
        """Raise :class:`ModelError` if the parameters cannot describe a working latch."""
        validate_latch_array(self.as_array(), where)
        return self


PARAM_NAMES = tuple(f.name for f in fields(LatchParameters))


def _as_param_array(params) -> np.ndarray:
    if params is None:
        params = LatchParameters.adam_fit()
    if isinstance(params, LatchParameters):
        return params.as_array()
    if isinstance(params, dict):
        return LatchParameters(**params).as_array()
    if isinstance(params, (list, tuple)) and params and all(isinstance(q, LatchParameters) for q in params):
        return np.stack([q.as_array() for q in params])
    p = np.asarray(params, dtype=float)
    if p.shape[-1] != 6:
        raise ModelError(f"latch parameters must be [r, x_backstop, k, mu, h, R] (6 values), got shape {p.shape}")
    return p


def validate_latch_array(p, where: str = "latch") -> None:
    """Check one latch parameter vector [r, x_backstop, k, mu, h, R] (SI); raise ModelError."""
    p = np.asarray(p, dtype=float)
    r, xb, k, mu, h, R = (float(v) for v in p)
    for name, v in zip(PARAM_NAMES, (r, xb, k, mu, h, R)):
        if math.isnan(v):
            raise ModelError(f"{where}: latch parameter {name} is NaN; give a number in SI units")
    for name, v in (("r", r), ("k", k), ("R", R)):
        if not (v > 0.0 and math.isfinite(v)):
            raise ModelError(f"{where}: latch parameter {name}={v!r} must be finite and > 0 (SI units: m, N/m)")
    if not (h >= 0.0 and math.isfinite(h)):
        raise ModelError(f"{where}: latch parameter h={h!r} (half the roller gap, m) must be finite and >= 0")
    if not (mu >= 0.0 and math.isfinite(mu)):
        raise ModelError(f"{where}: latch friction coefficient mu={mu!r} must be finite and >= 0")
    if not xb > 0.0:
        raise ModelError(
            f"{where}: x_backstop={xb!r} m must be > 0: the backstop sits behind the roller axis at "
            "x = -x_backstop (use numpy.inf for no backstop)"
        )
    if R <= h:
        raise ModelError(
            f"{where}: the rollers never touch the bead (bead radius R={R:g} m <= half gap h={h:g} m, "
            "Eq. 6 has no solution with delta > 0); check units (m) or increase R / decrease h"
        )
    xc = math.sqrt((r + R) ** 2 - (h + r) ** 2)
    if h + r - mu * xc <= 0.0:
        raise ModelError(
            f"{where}: the latch self-locks (h + r - mu x_contact = {h + r - mu * xc:g} m <= 0, "
            "the denominator of Eq. 14 vanishes): reduce mu or check the geometry"
        )


def contact_half_width(params=None) -> float:
    """Half-width of the contact zone, x_contact = sqrt((r+R)^2 - (h+r)^2), m (Eq. 6 with delta = 0)."""
    p = _as_param_array(params)
    r, _, _, _, h, R = p
    return float(math.sqrt(max((r + R) ** 2 - (h + r) ** 2, 0.0)))


# ----------------------------------------------------------------------------------------
# numba scalar kernels (single source of truth, also used by the cable element)


@njit(cache=True)
def latch_dT_scalar(x, sigma, r, xb, k, mu, h, R):
    """dT (N) and d(dT)/dx (N/m) of Eq. 14 at bead position x (m) for direction sigma
    (+1: dx > 0, unlatching; -1: dx < 0, latching).  Zero without contact."""
    rho = r + R
    if x >= rho or x <= -rho:
        return 0.0, 0.0
    y = math.sqrt(rho * rho - x * x)
    delta = y - h - r
    if delta <= 0.0:
        return 0.0, 0.0
    dy = -x / y
    num = x - sigma * mu * y
    den = y + sigma * mu * x
    dnum = 1.0 - sigma * mu * dy
    dden = dy + sigma * mu
    q = num / den
    dq = (dnum * den - num * dden) / (den * den)
    return -2.0 * k * delta * q, -2.0 * k * (dy * q + delta * dq)


@njit(cache=True)
def latch_opening_scalar(x, r, h, R):
    """Roller opening delta (m), Eq. 10, clipped at 0 (no contact)."""
    rho = r + R
    if x >= rho or x <= -rho:
        return 0.0
    d = math.sqrt(rho * rho - x * x) - h - r
    return d if d > 0.0 else 0.0


@njit(cache=True)
def _latch_dT_array(x, sigma, p, out, dout):
    for i in range(x.shape[0]):
        v, dv = latch_dT_scalar(x[i], sigma[i], p[i, 0], p[i, 1], p[i, 2], p[i, 3], p[i, 4], p[i, 5])
        out[i] = v
        dout[i] = dv


def _broadcast(x, sigma, params):
    p = _as_param_array(params)
    x = np.asarray(x, dtype=float)
    sigma = np.asarray(sigma, dtype=float)
    shape = np.broadcast_shapes(x.shape, sigma.shape, p.shape[:-1])
    xb = np.ascontiguousarray(np.broadcast_to(x, shape).ravel())
    sb = np.ascontiguousarray(np.broadcast_to(sigma, shape).ravel())
    pb = np.ascontiguousarray(np.broadcast_to(p, shape + (6,)).reshape(-1, 6))
    return shape, xb, sb, pb


def latch_force(x, direction, params=None, derivative: bool = False):
    """Force jump dT = T2 - T1 (N) of a *moving* bead, Stohlman & Pellegrino, Eq. 14.

    x : bead position, m (positive outside the latch, see module docstring); any shape.
    direction : +1 (``UNLATCHING``, dx > 0) or -1 (``LATCHING``, dx < 0), broadcast with x.
    params : :class:`LatchParameters`, dict, or [..., 6] array [r, x_backstop, k, mu, h, R] (SI);
        default the paper's fit.
    derivative : also return d(dT)/dx, N/m.

    The backstop is not applied here (see :func:`friction_band`); outside the contact
    zone dT = 0.
    """
    shape, xb, sb, pb = _broadcast(x, direction, params)
    if np.any(np.abs(sb) != 1.0):
        raise ModelError("latch_force: direction must be +1 (unlatching, dx > 0) or -1 (latching, dx < 0)")
    out = np.empty(xb.shape[0])
    dout = np.empty(xb.shape[0])
    _latch_dT_array(xb, sb, pb, out, dout)
    out = out.reshape(shape)
    if derivative:
        return out, dout.reshape(shape)
    return out


def roller_opening(x, params=None):
    """Opening of one roller delta (m), Eq. 10, 0 without contact; x in m."""
    p = _as_param_array(params)
    x = np.asarray(x, dtype=float)
    r, h, R = p[..., 0], p[..., 4], p[..., 5]
    rho = r + R
    y = np.sqrt(np.clip(rho**2 - x**2, 0.0, None))
    return np.where(np.abs(x) < rho, np.clip(y - h - r, 0.0, None), 0.0)


def friction_band(x, params=None):
    """Static-friction band (lo, hi) of dT (N) for a bead at rest at x (m).

    A bead that does not move holds any dT with lo <= dT <= hi, lo = dT_in(x) and
    hi = dT_out(x) of Eq. 14 (Eq. 9, third case).  Against the backstop
    (x <= -x_backstop) lo = -inf.  Without contact lo = hi = 0.
    """
    p = _as_param_array(params)
    lo = latch_force(x, LATCHING, p)
    hi = latch_force(x, UNLATCHING, p)
    at_stop = np.asarray(x, dtype=float) <= -p[..., 1] * (1.0 - 1e-12)
    lo = np.where(at_stop, -np.inf, lo)
    return lo, hi


def hysteresis_force(x, params=None, force: float = 0.0, length: float = 3e-4):
    """Extra friction H(x) (N) of the *latch hysteresis* option, for bead positions x (m).

    Stohlman & Pellegrino fit one curve near the latched state ("the model assumes no hysteresis in this
    region", Sec. III.C) and so predicts no residual rotation at zero moment (Sec. VIII).  The
    option adds a friction force that is largest with the bead seated on the backstop and
    fades over ``length`` (m) as the bead moves out, vanishing at the roller axis::

        H(x) = force w(x),   w = (exp(-(x + x_b)/length) - exp(-x_b/length)) / (1 - exp(-x_b/length))

    for -x_b <= x < 0, and 0 for x >= 0.  The static band becomes [dT_in - H, dT_out + H] and a
    sliding bead follows dT_sigma + sigma H.  Up to the factor that makes w vanish at the roller
    axis (exp(-x_b/length) = 1.3e-3 for x_b = 2 mm, length = 0.3 mm) this is the
    ``latch_hysteresis`` effect of :mod:`femast.effects.latch` (``F_h`` = force, ``ell`` = length).
    """
    p = _as_param_array(params)
    x = np.asarray(x, dtype=float)
    if force <= 0.0:
        return np.zeros(np.broadcast_shapes(x.shape, p.shape[:-1]))
    if not length > 0.0:
        raise ModelError(f"hysteresis_force: length = {length!r} m must be > 0")
    xb = p[..., 1]
    u = np.clip(x + xb, 0.0, None)
    e0 = np.exp(-xb / length)
    w = (np.exp(-u / length) - e0) / (1.0 - e0)
    return np.where(x < 0.0, force * w, 0.0)


def latch_zone(x, params=None):
    """Zone of Fig. 6 for bead positions x (m): 0 (a) at backstop, 1 (b) contact behind the
    roller axis, 2 (c) contact in front of it, 3 (d) no contact.  See ``ZONE_LABELS``."""
    p = _as_param_array(params)
    x = np.asarray(x, dtype=float)
    xb = p[..., 1]
    delta = roller_opening(x, p)
    zone = np.where(x < 0.0, ZONE_BEHIND_AXIS, ZONE_IN_FRONT)
    zone = np.where(delta > 0.0, zone, ZONE_FREE)
    zone = np.where(x <= -xb * (1.0 - 1e-9), ZONE_BACKSTOP, zone)
    return zone.astype(int)


def latch_energy(x, params=None):
    """Elastic energy of the two roller springs, k delta^2 (J), at bead position x (m)."""
    p = _as_param_array(params)
    d = roller_opening(x, p)
    return p[..., 2] * d * d


def quasi_static_branches(params=None, x_max: float | None = None, n: int = 801):
    """The two branches of Fig. 10 on a grid, for plotting and identification.

    Returns dict with ``x`` (m, from -x_backstop to x_max), ``latching`` and
    ``unlatching`` (dT of Eq. 14, N) and the zone of each point.
    """
    p = _as_param_array(params)
    if x_max is None:
        x_max = 2.0 * contact_half_width(p)
    x = np.linspace(-p[1], x_max, n)
    return {
        "x": x,
        "latching": latch_force(x, LATCHING, p),
        "unlatching": latch_force(x, UNLATCHING, p),
        "zone": latch_zone(x, p),
    }
