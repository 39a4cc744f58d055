"""Euler columns (critical loads, imperfect column, post-buckling) and the shallow two-bar
(von Mises) truss, exact for axially elastic bars.

Part of :mod:`femast.verification.references` (written from theory, no femast code)."""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

# =============================================================================
# 4. Euler columns
# =============================================================================

#: Effective-length factors K (P_cr = pi^2 EI / (K L)^2) and the characteristic
#: equation in q = L sqrt(P/EI) whose smallest positive root gives P_cr
#: (Timoshenko and Gere, "Theory of Elastic Stability", 2nd ed. 1961, ch. 2).
#: fixed-pinned: tan q = q, q = 4.493409...  (K = pi/q = 0.699155...).
EULER_SUPPORTS = {
    "pinned-pinned": (1.0, "sin q = 0"),
    "fixed-free": (2.0, "cos q = 0"),
    "fixed-pinned": (math.pi / 4.493409457909064, "tan q = q"),
    "fixed-fixed": (0.5, "q sin q = 2 (1 - cos q)"),
    "fixed-guided": (1.0, "sin q = 0  (clamped, other end clamped against rotation but free to sway)"),
}


def euler_critical_load(EI: float, L: float, support: str = "pinned-pinned") -> float:
    """Euler buckling load P_cr = pi^2 EI / (K L)^2 of a straight prismatic column.

    ``support`` is one of :data:`EULER_SUPPORTS`: 'pinned-pinned' (K = 1),
    'fixed-free' (cantilever, K = 2), 'fixed-pinned' (K = 0.6992, from
    tan q = q), 'fixed-fixed' (K = 0.5), 'fixed-guided' (sway, K = 1).
    Source: Timoshenko and Gere (1961), Theory of Elastic Stability, ch. 2.
    """
    try:
        K = EULER_SUPPORTS[support][0]
    except KeyError:
        raise ValueError(
            f"euler_critical_load: unknown support {support!r}; use one of {sorted(EULER_SUPPORTS)}"
        ) from None
    return math.pi**2 * EI / (K * L) ** 2


def imperfect_column_deflection(P: float, EI: float, L: float, e0: float, x=None):
    """Lateral deflection of a pinned-pinned column with a sinusoidal imperfection.

    Initial (stress-free) shape w0(x) = e0 sin(pi x / L); under an axial
    compressive load P < P_cr = pi^2 EI / L^2 the linearised equilibrium
    EI (w - w0)'' + P w = 0 gives the total deflection (Timoshenko and Gere
    1961, section 1.12, "amplification factor")::

        w(x) = w0(x) / (1 - P/P_cr)

    so the additional deflection is w - w0 = e0 (P/P_cr)/(1 - P/P_cr) sin(pi x/L).
    Returns the total deflection at ``x`` (default: midspan), i.e. measured
    from the straight line through the supports.  Valid for small deflections;
    it grows without bound as P -> P_cr (Southwell: (w-w0)/P is linear in w-w0).
    """
    Pcr = math.pi**2 * EI / L**2
    if P >= Pcr:
        raise ValueError(f"imperfect_column_deflection: P={P} >= P_cr={Pcr}: the linear amplification is unbounded")
    shape = 1.0 if x is None else np.sin(np.pi * np.asarray(x, dtype=float) / L)
    return e0 * shape / (1.0 - P / Pcr)


def euler_column_postbuckling(alpha: float):
    """Exact post-buckling (elastica) of a perfect pinned-pinned column.

    ``alpha`` is the end rotation (rad, 0 < alpha < pi); p = sin(alpha/2).
    Returns (P/P_cr, w_mid/L, shortening/L) with (Timoshenko and Gere 1961,
    section 2.7)::

        P/P_cr        = (2 K(p) / pi)^2
        w_mid / L     = p / K(p)
        shortening/L  = 2 - 2 E(p)/K(p)

    K, E complete elliptic integrals of parameter m = p^2.  Shows that the
    load rises only slowly above P_cr after bifurcation (e.g. P/P_cr = 1.0154
    at alpha = 20 degrees).
    """
    p = math.sin(0.5 * alpha)
    m = p * p
    K, Ee = float(ellipk(m)), float(ellipe(m))
    return (2.0 * K / math.pi) ** 2, p / K, 2.0 - 2.0 * Ee / K


# =============================================================================
# 5a. The shallow two-bar (von Mises) truss
# =============================================================================


def von_mises_truss_load(w, a: float, h: float, EA: float, strain: str = "engineering"):
    """Apex load P (downward positive) of the two-bar truss at apex deflection w.

    Two pin-jointed bars from supports (-a, 0) and (a, 0) to the apex (0, h);
    axial stiffness EA; a dead vertical load P at the apex, w its downward
    displacement (symmetric path; the bars stay straight).  Initial length
    L0 = sqrt(a^2 + h^2), current length l = sqrt(a^2 + (h - w)^2).
    Equilibrium at the apex is exact (no small-angle assumption)::

        'engineering' (Biot; corotational truss, N = EA (l - L0)/L0):
            P(w) = 2 EA (L0 - l)/L0 * (h - w)/l
        'green' (total Lagrangian, 2nd PK stress S = E * Green strain):
            P(w) = EA (L0^2 - l^2)(h - w) / L0^3 = EA (h^2 - (h-w)^2)(h-w) / L0^3

    The curve is explicit in w, so it covers the whole snap-through: P rises to
    a limit load, falls through zero at w = h (bars horizontal, P = 0), goes
    negative, returns to zero at w = 2h (mirror position) and rises again.
    Source: Crisfield (1991), "Non-linear Finite Element Analysis of Solids
    and Structures", Vol. 1, ch. 1 and 3 (shallow truss).  ``w`` may be an
    array.
    """
    w = np.asarray(w, dtype=float)
    L0 = math.hypot(a, h)
    z = h - w
    if strain == "engineering":
        l = np.sqrt(a * a + z * z)
        return 2.0 * EA * (L0 - l) / L0 * z / l
    if strain == "green":
        return EA * (h * h - z * z) * z / L0**3
    raise ValueError(f"von_mises_truss_load: strain={strain!r}; use 'engineering' or 'green'")


def von_mises_truss_limit_points(a: float, h: float, EA: float, strain: str = "engineering"):
    """Limit points of :func:`von_mises_truss_load`: ((w1, P1), (w2, P2)).

    w1 < h is the snap-through (maximum) point, w2 = 2h - w1 > h the minimum,
    with P2 = -P1 by symmetry of the curve about w = h.  For 'green' strain
    in closed form: h - w1 = h/sqrt(3), P1 = 2 EA h^3 / (3 sqrt(3) L0^3); for
    'engineering' strain dP/dw = 0 is solved by Brent's method.
    """
    L0 = math.hypot(a, h)
    if strain == "green":
        z = h / math.sqrt(3.0)
        P1 = 2.0 * EA * h**3 / (3.0 * math.sqrt(3.0) * L0**3)
    elif strain == "engineering":
        # dP/dz with P = 2 EA (L0 - l) z / (L0 l), l = sqrt(a^2 + z^2):
        # dP/dz = 2 EA / L0 * [ (L0 - l)/l - z^2 L0 / l^3 ]  -> zero in (0, h)
        def dPdz(z):
            l = math.hypot(a, z)
            return (L0 - l) / l - z * z * L0 / l**3

        z = brentq(dPdz, 1e-300, h, xtol=1e-15 * h, rtol=1e-15)
        P1 = float(von_mises_truss_load(h - z, a, h, EA, strain))
    else:
        raise ValueError(f"von_mises_truss_limit_points: strain={strain!r}; use 'engineering' or 'green'")
    w1 = h - z
    return (w1, P1), (2.0 * h - w1, -P1)
