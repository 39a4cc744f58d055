"""The devices a cable runs over (what a model script writes): frictionless pulleys, sheaves
with bearing friction, capstan drums, latches, clamps and user laws; each becomes a law kind and a
parameter row of :mod:`._device_laws` for :class:`~femast.elements.cable_devices.CableDeviceFamily`.
See ``docs/cable_devices.md`` for which physical object each device is."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ._device_laws import CAPSTAN, CLAMP, FREE, LATCH, LATCH_MU_K, LATCH_RHO, N_PARAM, SHEAVE, USER
from .latch_law import LatchParameters, _as_param_array, validate_latch_array


@dataclass(frozen=True)
class Pulley:
    """A frictionless pulley at a node, or (``mu > 0``) a capstan drum (see :class:`Drum`).

    radius : m (0: a point pulley; > 0: the cable leaves on the tangent points and wraps the
    pulley, see :mod:`._cable_geometry`).  mu : Coulomb friction coefficient between the cable and
    a surface it *slides on* (0: frictionless; > 0: the capstan law ``exp(-mu phi) <= T_out/T_in
    <= exp(mu phi)`` with the wrap angle phi from the current geometry: right for a fixed drum, a
    fairlead or a cable sliding in a groove, not for a sheave that turns: use :class:`Sheave`).
    mu_s, mu_k : static and kinetic coefficients instead of the one ``mu`` (mu_s >= mu_k >= 0;
    mu_k defaults to mu_s): the cable starts to slide at mu_s, slides on at mu_k and grips again
    when it stops or reverses."""

    radius: float = 0.0
    mu: float = 0.0
    mu_s: float | None = None
    mu_k: float | None = None


@dataclass(frozen=True)
class Drum(Pulley):
    """A capstan drum: a fixed (non-rotating) drum or surface the cable slides on, Coulomb friction
    ``mu`` between cable and drum (the capstan law, Euler-Eytelwein; ``Pulley(radius, mu)`` is the
    same device).  radius : m (0: a point drum)."""


@dataclass(frozen=True)
class Sheave:
    """A sheave: a wheel of radius ``radius`` (m) that turns on a pin of radius ``pin_radius`` (m)
    in a bearing with (journal) friction coefficient ``mu``; the cable does not slip on the wheel.

    The bearing's friction torque ``mu pin_radius |F|``, with ``|F| = sqrt(T_in^2 + T_out^2 - 2
    T_in T_out cos phi)`` the resultant of the two tensions on the pin (phi the wrap angle), holds
    the torque ``(T_out - T_in) radius`` of the tension difference: the wheel sticks while
    ``|T_out - T_in| <= rho |F|`` and turns with ``T_out - T_in = +- rho |F|``, ``rho = mu
    pin_radius / radius``.  A quarter wrap loses about ``1.4 rho`` of the tension (a capstan of the
    same mu: ``exp(mu pi/2) - 1``, 60 times more for mu = 0.3 and pin_radius / radius = 0.1).
    mu = 0 (default): a frictionless sheave (:class:`Pulley` of the same radius, bit for bit).

    point : True treats the sheave as a point in the cable's geometry (the radius then only sets
        ``rho``); False (default) wraps the cable round it as a :class:`Pulley` of that radius.
    mu_s, mu_k : static and kinetic bearing friction instead of the one ``mu`` (as :class:`Pulley`)."""

    radius: float
    pin_radius: float = 0.0
    mu: float = 0.0
    point: bool = False
    mu_s: float | None = None
    mu_k: float | None = None


def friction_coefficients(mu, mu_s, mu_k, who):
    """(mu_s, mu_k) from the one coefficient ``mu`` (static = kinetic) or the pair (mu_k defaults to
    mu_s), checked: finite, mu_s >= mu_k >= 0 (the convention of the ball joints)."""
    if mu_s is not None and mu:
        raise ModelError(
            f"{who}: give mu (static = kinetic) or mu_s (and mu_k), not both (mu = {mu!r}, mu_s = {mu_s!r})"
        )
    s = mu if mu_s is None else mu_s
    k = s if mu_k is None else mu_k
    s, k = (float(v) if isinstance(v, (np.floating, np.integer)) else v for v in (s, k))
    for what, v in (("mu" if mu_s is None else "mu_s", s), ("mu_k", k)):
        if not (isinstance(v, (int, float, np.floating, np.integer)) and np.isfinite(v) and v >= 0.0):
            raise ModelError(f"{who}: {what} = {v!r} must be a finite friction coefficient >= 0")
    if k > s:
        raise ModelError(
            f"{who}: kinetic mu_k = {k!r} above static mu_s = {s!r}; a device slips at mu_s and slides on at mu_k <= mu_s"
        )
    return float(s), float(k)


def geometry_radius(dev) -> float:
    """Radius (m) with which a device enters the cable geometry (0: a point)."""
    if isinstance(dev, Pulley):
        return float(dev.radius)
    if isinstance(dev, Sheave):
        return 0.0 if dev.point else float(dev.radius)
    return 0.0


def _sheave_params(dev, k, name, p):
    who = f"{name} device {k} (Sheave)"
    for what, v in (("radius", dev.radius), ("pin_radius", dev.pin_radius), ("mu", dev.mu)):
        if not (isinstance(v, (int, float, np.floating, np.integer)) and np.isfinite(v) and v >= 0.0):
            raise ModelError(f"{who}: {what} = {v!r} must be a finite number >= 0")
    if not dev.radius > 0.0:
        raise ModelError(f"{who}: radius = {dev.radius!r} m must be > 0 (the wheel's radius)")
    if not dev.pin_radius < dev.radius:
        raise ModelError(
            f"{who}: pin_radius = {dev.pin_radius!r} m must be smaller than the radius {dev.radius!r} m (the pin "
            "runs inside the wheel)"
        )
    mu_s, mu_k = friction_coefficients(dev.mu, dev.mu_s, dev.mu_k, who)
    rho_s, rho_k = mu_s * dev.pin_radius / dev.radius, mu_k * dev.pin_radius / dev.radius
    if not rho_s < 1.0:
        raise ModelError(
            f"{who}: mu pin_radius / radius = {rho_s:.6g} must be < 1 (a sheave that could never turn); check mu "
            "(a friction coefficient) and the radii (m)"
        )
    radius = 0.0 if dev.point else float(dev.radius)
    if rho_s == 0.0:
        return FREE, p, radius
    p[0], p[1] = rho_k, rho_s
    return SHEAVE, p, radius


@dataclass(frozen=True)
class Latch:
    """A roller latch of Stohlman & Pellegrino (Eqs. 5, 14) at a node; the bead is on the cable.

    params : :class:`~femast.elements.latch_law.LatchParameters` (default the paper's fit).
    bead : material coordinate Lb of the bead, m (unstretched length from node 0); ``None`` with
        :meth:`CableDeviceFamily.pretensioned` puts it at ``x0`` in the initial geometry.
    x0 : initial bead position, m (default ``-x_backstop``: latched, on the backstop).
    hysteresis_force, hysteresis_length : the latch hysteresis option of :mod:`femast.elements.latch_law` (N, m).
    mu_s, mu_k : static and kinetic friction between rollers and bead (default both ``params.mu``,
        the paper's one coefficient): the static band of Eq. 14 uses mu_s, a sliding bead mu_k.
    sheave : a :class:`Sheave` at the same node (the pulley of ADAM's pulley-and-latch unit): its
        bearing friction ``rho |F|`` adds to the latch's jump (its radius sets only rho: the node
        stays a point).  None (default): a frictionless pulley there, as the paper's element.
    The section before the latch runs through the backstop (as in :class:`CableLatchFamily`)."""

    params: LatchParameters | None = None
    bead: float | None = None
    x0: float | None = None
    hysteresis_force: float = 0.0
    hysteresis_length: float = 3e-4
    mu_s: float | None = None
    mu_k: float | None = None
    sheave: Sheave | None = None


@dataclass(frozen=True)
class Clamp:
    """A clamp: the cable is fixed to the node (no sliding)."""


@dataclass(frozen=True)
class UserDevice:
    """A device with a user law: a numba ``@njit`` function

        law(sigma, T_in, T_out, s, phi, p) -> (r, dr/dT_in, dr/dT_out, dr/ds, dr/dphi)

    (floats; N, m, rad) following the contract of :mod:`._device_laws`: r is the unbalanced force of
    the branch on which the cable slides in direction sigma (+1: the out side pulls, ds < 0; -1: the
    in side pulls); the device sticks while r(+1) <= 0 <= r(-1).  params : up to 12 floats, passed as
    ``p``.  All user devices of one family share one law function (dispatch on ``p`` for several)."""

    law: object
    params: tuple = ()


def kind_and_params(dev, k, name):
    """(law kind, parameter row (N_PARAM,), geometry radius m) of device ``dev`` (index k of cable ``name``)."""
    p = np.zeros(N_PARAM)
    if isinstance(dev, Pulley):
        who = f"{name} device {k} ({type(dev).__name__})"
        if not (np.isfinite(dev.radius) and dev.radius >= 0.0):
            raise ModelError(f"{who}: radius = {dev.radius!r} must be finite and >= 0 (m)")
        if not (np.isfinite(dev.mu) and dev.mu >= 0.0):
            raise ModelError(f"{who}: mu = {dev.mu!r} must be finite and >= 0 (friction coefficient)")
        mu_s, mu_k = friction_coefficients(dev.mu, dev.mu_s, dev.mu_k, who)
        if mu_s > 0.0:
            p[0], p[1] = mu_k, mu_s
            return CAPSTAN, p, float(dev.radius)
        return FREE, p, float(dev.radius)
    if isinstance(dev, Sheave):
        return _sheave_params(dev, k, name, p)
    if isinstance(dev, Latch):
        arr = _as_param_array(dev.params)
        validate_latch_array(arr, f"{name} device {k} (Latch)")
        p[:6] = arr
        p[7] = dev.hysteresis_force
        p[8] = dev.hysteresis_length
        if dev.mu_s is not None or dev.mu_k is not None:
            mu_s = arr[3] if dev.mu_s is None else dev.mu_s
            p[3], p[LATCH_MU_K] = friction_coefficients(0.0, mu_s, dev.mu_k, f"{name} device {k} (Latch)")
        else:
            p[LATCH_MU_K] = arr[3]
        if dev.sheave is not None:
            if not isinstance(dev.sheave, Sheave):
                raise ModelError(f"{name} device {k} (Latch): sheave must be a Sheave, got {type(dev.sheave).__name__}")
            q = np.zeros(N_PARAM)
            if _sheave_params(dev.sheave, k, name, q)[0] == SHEAVE:
                p[LATCH_RHO], p[LATCH_RHO + 1] = q[0], q[1]
        if not (np.isfinite(p[7]) and p[7] >= 0.0 and np.isfinite(p[8]) and p[8] > 0.0):
            raise ModelError(f"{name} device {k} (Latch): hysteresis_force >= 0 N and hysteresis_length > 0 m needed")
        return LATCH, p, 0.0
    if isinstance(dev, Clamp):
        return CLAMP, p, 0.0
    if isinstance(dev, UserDevice):
        q = np.asarray(dev.params, dtype=float).ravel()
        if q.size > N_PARAM or not np.all(np.isfinite(q)):
            raise ModelError(f"{name} device {k} (UserDevice): give at most {N_PARAM} finite parameters")
        p[: q.size] = q
        return USER, p, 0.0
    raise ModelError(
        f"{name} device {k}: {dev!r} is not a device; use Pulley, Sheave, Drum, Latch, Clamp or UserDevice"
    )


LATCH_NAMES = ("r", "x_backstop", "k", "mu", "h", "R", None, "hysteresis_force", "hysteresis_length")


def set_device_values(P, kinds, devices, values, name):
    """Per-element device parameters (``device_values`` of :class:`CableDeviceFamily`) written into the
    parameter rows ``P`` (n_el, n_devices, N_PARAM), validated per element."""
    n_el = P.shape[0]
    if not isinstance(values, dict):
        raise ModelError(f"{name}: device_values must be a dict {{device index: {{parameter: values}}}}")
    for k, params in values.items():
        if not (isinstance(k, (int, np.integer)) and 0 <= k < len(devices)):
            raise ModelError(f"{name}: device_values has device {k!r}; the devices are 0..{len(devices) - 1}")
        dev = devices[k]
        if isinstance(dev, Latch):
            cols = {nm: ((i,), 1.0) for i, nm in enumerate(LATCH_NAMES) if nm}
            cols.update(mu=((3, LATCH_MU_K), 1.0), mu_s=((3,), 1.0), mu_k=((LATCH_MU_K,), 1.0))
        elif isinstance(dev, Pulley) and kinds[k] == CAPSTAN:
            cols = {"mu": ((0, 1), 1.0), "mu_s": ((1,), 1.0), "mu_k": ((0,), 1.0)}
        elif isinstance(dev, Sheave) and kinds[k] == SHEAVE:
            c = dev.pin_radius / dev.radius  # rho = mu r_pin / r
            cols = {"mu": ((0, 1), c), "mu_s": ((1,), c), "mu_k": ((0,), c)}
        else:
            raise ModelError(
                f"{name} device {k} ({type(dev).__name__}): has no per-element parameters (a "
                "Latch, a Drum or Pulley with mu > 0 and a Sheave with mu > 0 have)"
            )
        for nm, v in dict(params).items():
            if nm not in cols:
                raise ModelError(
                    f"{name} device {k} ({type(dev).__name__}): unknown parameter {nm!r}; use {', '.join(cols)}"
                )
            try:
                arr = np.broadcast_to(np.asarray(v, dtype=float), (n_el,))
            except (TypeError, ValueError):
                raise ModelError(
                    f"{name} device {k}: {nm} must be a number or one per element ({n_el}), got shape {np.shape(v)}"
                ) from None
            idx, scale = cols[nm]
            for i in idx:
                P[:, k, i] = arr * scale
        c = dev.pin_radius / dev.radius if isinstance(dev, Sheave) and kinds[k] == SHEAVE else 1.0  # rho per mu
        for el in range(n_el):  # construction only, not a hot path
            where = f"{name} device {k} ({type(dev).__name__}), element {el}"
            if isinstance(dev, Latch):
                validate_latch_array(P[el, k, :6], where)
                if not (
                    np.isfinite(P[el, k, 7]) and P[el, k, 7] >= 0.0 and np.isfinite(P[el, k, 8]) and P[el, k, 8] > 0.0
                ):
                    raise ModelError(f"{where}: hysteresis_force >= 0 N and hysteresis_length > 0 m needed")
                mu_s, mu_k = P[el, k, 3], P[el, k, LATCH_MU_K]
            else:
                mu_k, mu_s = P[el, k, 0], P[el, k, 1]
                if not (np.isfinite(mu_s) and mu_s > 0.0):
                    raise ModelError(f"{where}: mu (mu_s) must be finite and > 0 (got {mu_s / c:.6g})")
                if kinds[k] == SHEAVE and not mu_s < 1.0:
                    raise ModelError(
                        f"{where}: mu pin_radius / radius = {mu_s:.6g} must be < 1 (mu = {mu_s / c:.6g}; "
                        "a bearing's journal friction is well below 1)"
                    )
            if not (np.isfinite(mu_k) and 0.0 <= mu_k <= mu_s):
                raise ModelError(
                    f"{where}: kinetic mu_k must lie in [0, mu_s] (static {mu_s / c:.6g}, kinetic {mu_k / c:.6g})"
                )


__all__ = [
    "Pulley",
    "Drum",
    "Sheave",
    "Latch",
    "Clamp",
    "UserDevice",
    "geometry_radius",
    "kind_and_params",
    "friction_coefficients",
    "set_device_values",
]
