"""Loading and unloading of a Dyneema shroud: the rope's hysteresis as a law of the FE shroud.

The Rocaspect paper (Sec. IV-A, Fig. 4a) measures "a significant difference between loading and
unloading the shroud" and fits its polynomial (Eq. 25) to the average of the two curves.  A rope's
hysteresis comes from friction between its fibres and strands, whose normal force grows with the
tension.  The law here puts a friction element in parallel with the elastic rope law (the average
curve, :mod:`.shroud_law`):

    tau = tau_e(eps) + tau_f,        |tau_f| <= eta tau_e(eps)

with ``tau_e`` the tension of Eq. 25 (inverted, :func:`femast.elements._shroud_kernels.dyneema_tension`)
and ``tau_f`` the friction tension: it sticks (grows with a stick rigidity ``k_s`` times the strain
increment) until it reaches ``+-eta tau_e``, then slides.  Under monotone loading the rope follows
the loading branch ``(1 + eta) tau_e(eps)`` (after a short stick run of strain about ``eta tau_e /
k_s``), under unloading the unloading branch ``(1 - eta) tau_e(eps)``; a reversal crosses between
them along ``tau_e(eps) + tau_f``, ``d tau_f = k_s d eps``.  At zero strain the friction limit is zero:
the loop closes at zero load (a slack rope carries nothing), and its width grows with the load, as in
Fig. 4a.  Rate independent.  eta = 0 is the paper's law, bit for bit.

Return mapping from the committed state ``(eps_c, tau_f_c)`` (the rope's state: 2 values):

    tau_f* = tau_f_c + k_s (eps - eps_c);   tau_f = tau_f* if |tau_f*| <= eta tau_e(eps), else
    sign(tau_f*) eta tau_e(eps);   d tau_f / d eps = k_s (stick) or sign(tau_f*) eta d tau_e / d eps (slip).

Parameters (per rope): ``eta`` (dimensionless, 0 <= eta < 1: the loop half-width relative to the
tension) and ``k_s`` (N, an axial rigidity: the initial slope of a reversal is ``EA_t + k_s``; default
``stick_factor`` = 10 times the zero-tension rigidity k0 of the rope law).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..errors import ModelError

STICK_FACTOR = 10.0
"""Default stick rigidity k_s of the friction element, as a multiple of the law's k0 (N)."""


@njit(cache=True)
def friction_return(eps, tau_e, dtau_e, eta, k_s, eps_c, tf_c):
    """Friction tension tau_f (N) at strain ``eps`` from the committed ``(eps_c, tf_c)``, and
    d tau_f / d eps (N), for the elastic tension ``tau_e`` (N) and its slope ``dtau_e`` = d tau_e /
    d eps (N) (module note)."""
    lim = eta * tau_e
    trial = tf_c + k_s * (eps - eps_c)
    if abs(trial) <= lim:
        return trial, k_s
    s = 1.0 if trial > 0.0 else -1.0
    return s * lim, s * eta * dtau_e


def hysteresis_array(hysteresis, stick_rigidity, law, n_el, name) -> np.ndarray:
    """(n_el, 2) [eta, k_s (N)] checked, from scalars or per-rope values (``stick_rigidity`` None:
    :data:`STICK_FACTOR` times each rope's k0)."""
    try:
        eta = np.broadcast_to(np.asarray(hysteresis, dtype=float), (n_el,)).copy()
    except (TypeError, ValueError):
        raise ModelError(f"{name}: hysteresis must be a number or one per rope ({n_el}); got {hysteresis!r}") from None
    bad = np.flatnonzero(~(np.isfinite(eta) & (eta >= 0.0) & (eta < 1.0)))
    if bad.size:
        raise ModelError(
            f"{name} rope {bad[0] + 1}: hysteresis = {float(eta[bad[0]])!r} must be in [0, 1): the half-width of the "
            "loading/unloading loop relative to the tension (0: the paper's single curve)"
        )
    if stick_rigidity is None:
        ks = STICK_FACTOR * np.asarray(law, dtype=float)[:, 0]
    else:
        try:
            ks = np.broadcast_to(np.asarray(stick_rigidity, dtype=float), (n_el,)).copy()
        except (TypeError, ValueError):
            raise ModelError(
                f"{name}: stick_rigidity must be a number (N) or one per rope; got {stick_rigidity!r}"
            ) from None
    bad = np.flatnonzero(~(np.isfinite(ks) & (ks > 0.0)))
    if bad.size:
        raise ModelError(
            f"{name} rope {bad[0] + 1}: stick_rigidity = {float(ks[bad[0]])!r} N must be finite and > 0 (an axial "
            "rigidity: the slope of tension against strain at a reversal)"
        )
    return np.ascontiguousarray(np.column_stack([eta, ks]))


__all__ = ["friction_return", "hysteresis_array", "STICK_FACTOR"]
