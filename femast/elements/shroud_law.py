"""Tension-dependent stiffness of the Dyneema shrouds (the Rocaspect paper, Eqs. 23, 25, 27).

The constitutive law of the shroud element (:mod:`femast.elements.shroud_cable`), used also by the
analytic guyed-mast models of :mod:`femast.guyed` (it was ``femast/guyed/shroud.py``; the old path
still imports).

The paper writes the shroud spring coefficient as (Eq. 25)

    k(tau) = (k0 + k1 tau + k2 tau^2) / l

and identifies ``x_s = [k0, k1, k2] = [935353.664, 144.320, -0.000465]`` from a
0.5 m sample (Eq. 27, ``tau = k(tau) dl``).

Dimensions.  k is a spring stiffness (N/m) and l a length (m), so the numerator
is an axial rigidity ``EA(tau)`` in N: **k0 is in N, k1 is dimensionless and k2 is
in 1/N** (the paper calls all three "stiffness coefficients" without units).  With
the paper's values, EA = 0.935 MN at zero load and 1.108 MN at 1200 N.

Secant versus tangent.  Eq. 27 uses ``tau = k(tau) dl``, i.e. k is the *secant*
stiffness ``tau/dl``.  The passive stiffness of Eq. 24 needs ``d tau / d l``, the
*tangent* stiffness.  Differentiating ``tau = g(tau) eps`` with
``g = k0 + k1 tau + k2 tau^2`` and ``eps = dl / l`` gives

    EA_t = d tau / d eps = g^2 / (k0 - k2 tau^2)

which is 18 % above the secant value at 1200 N.  Since the strain is referred to the
unstretched length ``l_free = l / (1 + eps)``, ``d tau / d l = EA_t / l_free``; dividing
by the current length l as Eq. 25 does is a further O(eps) ~ 0.1 % difference.  :func:`shroud_stiffness` returns
the tangent value by default (consistent linearisation, what a finite-element model
gives); ``kind="secant"`` gives Eq. 25 as printed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._moved import renamed_attributes
from ..errors import ModelError
from .base import check_positive

#: The Rocaspect paper's shroud coefficients [k0 (N), k1 (-), k2 (1/N)], Section IV-A.
ROCASPECT_X_S = (935353.664, 144.320, -0.000465)


@dataclass(frozen=True)
class DyneemaLaw:
    """Progressive rope law ``EA(tau) = k0 + k1 tau + k2 tau^2`` (Eq. 25 numerator).

    k0 : axial rigidity at zero tension, N (> 0).
    k1 : dimensionless.
    k2 : 1/N.
    """

    k0: float = ROCASPECT_X_S[0]
    k1: float = ROCASPECT_X_S[1]
    k2: float = ROCASPECT_X_S[2]

    def __post_init__(self):
        check_positive("Dyneema law k0 (axial rigidity at zero tension)", self.k0, "N")
        for name in ("k1", "k2"):
            if not np.isfinite(getattr(self, name)):
                raise ModelError(f"Dyneema law {name}={getattr(self, name)!r} must be finite")

    @property
    def tau_max_valid(self) -> float:
        """Largest tension (N) for which the law is increasing and EA > 0 (inf if unbounded)."""
        lim = [np.inf]
        if self.k2 > 0:
            lim.append(np.sqrt(self.k0 / self.k2))  # k0 - k2 tau^2 > 0
        roots = np.roots([self.k2, self.k1, self.k0]) if self.k2 != 0 else np.roots([self.k1, self.k0])
        lim += [r.real for r in np.atleast_1d(roots) if abs(r.imag) < 1e-12 and r.real > 0]
        return float(min(lim))


def _tension(law: DyneemaLaw, tau):
    tau = np.asarray(tau, dtype=float)
    if np.any(tau < 0) or np.any(tau >= law.tau_max_valid):
        raise ModelError(
            f"shroud tension(s) {tau} N outside the range [0, {law.tau_max_valid:.4g}) N where the "
            "Dyneema law (Eq. 25) is increasing; check the units (N) or the coefficients"
        )
    return tau


def axial_rigidity_secant(law: DyneemaLaw, tau):
    """Secant axial rigidity ``tau / eps = k0 + k1 tau + k2 tau^2`` (Eq. 25 numerator), N."""
    tau = _tension(law, tau)
    return law.k0 + law.k1 * tau + law.k2 * tau**2


def axial_rigidity_tangent(law: DyneemaLaw, tau):
    """Tangent axial rigidity ``d tau / d eps = g^2 / (k0 - k2 tau^2)`` (derivative of Eq. 27's law), N."""
    g = axial_rigidity_secant(law, tau)
    tau = np.asarray(tau, dtype=float)
    return g**2 / (law.k0 - law.k2 * tau**2)


def shroud_stiffness(law: DyneemaLaw, tau, length, kind: str = "tangent"):
    """Spring coefficient k of a shroud of current length ``length`` (m) at tension ``tau`` (N), N/m (Eq. 25).

    ``kind="tangent"`` (default): ``d tau / d l = EA_t(tau) / l_free = EA_t(tau) (1 + eps) / l``, the
    derivative needed by Eq. 24, with the strain eps measured from the unstretched length as in
    the tensile test (Eq. 27).
    ``kind="secant"``: Eq. 25 as printed, ``(k0 + k1 tau + k2 tau^2) / l``.
    """
    length = check_positive("shroud length", length, "m")
    if kind == "tangent":
        # strain is measured from the unstretched length l_free = l / (1 + eps) (as dl / l0 in Eq. 27)
        return axial_rigidity_tangent(law, tau) * (1.0 + strain_from_tension(law, tau)) / length
    if kind == "secant":
        return axial_rigidity_secant(law, tau) / length
    raise ModelError(f"unknown stiffness kind {kind!r}; use 'tangent' or 'secant'")


def strain_from_tension(law: DyneemaLaw, tau):
    """Engineering strain ``eps = dl / l0 = tau / g(tau)`` of a rope at tension tau (N) (Eq. 27), dimensionless."""
    return np.asarray(tau, dtype=float) / axial_rigidity_secant(law, tau)


def tension_from_strain(law: DyneemaLaw, eps):
    """Tension (N) at strain ``eps`` (dimensionless): the root of ``k2 eps tau^2 + (k1 eps - 1) tau + k0 eps = 0``
    that is 0 at eps = 0 (inverse of :func:`strain_from_tension`).  A slack rope (eps <= 0) carries 0 N.

    Written as ``2 k0 eps / ((1 - k1 eps) + sqrt((1 - k1 eps)^2 - 4 k0 k2 eps^2))`` so that it is
    exact for k2 = 0 and free of cancellation at small strain.
    """
    eps = np.asarray(eps, dtype=float)
    e = np.maximum(eps, 0.0)
    a = 1.0 - law.k1 * e
    disc = a * a - 4.0 * law.k0 * law.k2 * e * e
    den = a + np.sqrt(np.maximum(disc, 0.0))
    if np.any((disc < 0) | (den <= 0)):
        raise ModelError(
            f"strain {eps} is beyond the range of the Dyneema law (Eq. 25); the rope would have no "
            "finite tension there: check the strain or the coefficients"
        )
    return 2.0 * law.k0 * e / den


#: old names, kept for one release (they warn): femast 0.3 removes them
__getattr__ = renamed_attributes(__name__, {"SEED_X_S": "ROCASPECT_X_S"})
