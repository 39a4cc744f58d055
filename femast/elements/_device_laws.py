"""Device laws of a cable over devices (Stohlman & Pellegrino, Sec. II.B.2, Eq. 5): the numba side.

Private module: the public face is :mod:`femast.elements.cable_devices`.

The device contract
-------------------
A device sits at an interior node of the cable, between the section before it ("in", tension
T_in) and the section after it ("out", T_out).  ``s`` (m) is the material coordinate of the cable
at the device (unstretched length from node 0).  A device either grips the cable (stick: ``s``
stays at its committed value) or lets it slide.  Sliding in direction ``sigma = +1`` means the
out side pulls the cable through (``ds < 0``), ``sigma = -1`` the in side (``ds > 0``).  A law is

    law(kind, sigma, T_in, T_out, s, phi, p, static) -> (r, dr/dT_in, dr/dT_out, dr/ds, dr/dphi)

with ``r`` the unbalanced force (N) of branch ``sigma``: the device slides on branch sigma where
``r = 0``, and it sticks while ``r(+1) <= 0 <= r(-1)`` (the static band).  ``phi`` is the wrap
angle (rad) from the current geometry and ``p`` the device's parameter row.  ``static``: the band
of a device at rest (static friction, ``mu_s``) rather than the law of one that slides (kinetic,
``mu_k``); a device slips when its static band is exceeded, slides on at the kinetic law, and
sticks again when it stops or reverses (rate independent; ``mu_s = mu_k`` is one coefficient).
A user law has the signature without ``kind`` and ``static`` (see
:class:`femast.elements.cable_devices.UserDevice`): one coefficient.

Built-in laws:

* capstan drum (Euler-Eytelwein: a cable sliding on a fixed drum or surface):
  ``r = T_out - T_in exp(sigma mu phi)``; the band is ``exp(-mu phi) <= T_out / T_in <= exp(mu phi)``;
* sheave (a wheel turning on a pin in a bearing with journal friction mu_b): the bearing's
  friction torque ``mu_b r_pin |F|`` on the resultant ``|F| = sqrt(T_in^2 + T_out^2 - 2 T_in T_out
  cos phi)`` of the two tensions holds the torque ``(T_out - T_in) r``:
  ``r = T_out - T_in - sigma rho |F|`` with ``rho = mu_b r_pin / r``; the band is
  ``|T_out - T_in| <= rho |F|``;
* latch (Stohlman & Pellegrino, Eqs. 5, 14): ``r = T_out - T_in - dT_sigma(x)``, ``x = Lb - s``; the backstop
  bounds ``s <= Lb + x_backstop``.  Optional hysteresis as in :mod:`femast.elements.latch_law`, and the bearing
  friction of a sheave at the same node (ADAM's pulley-and-latch unit): ``- sigma rho |F|`` more.

Frictionless pulleys (equal strains on both sides, which is equal tensions when taut and a
proportional share of the slack when slack, as in :mod:`._cable_kernels`) and clamps (never
slide) are handled by the solver itself.
"""

from __future__ import annotations

import math

from numba import njit

from ._cable_kernels import branch_scalar_mu

FREE = 0  # frictionless pulley
CAPSTAN = 1  # pulley with Coulomb friction (capstan law)
LATCH = 2  # roller latch of Stohlman & Pellegrino
CLAMP = 3  # fixed clamp: no sliding
USER = 4  # a user law
SHEAVE = 5  # sheave turning on a pin with bearing friction

N_PARAM = 12
"""Length of a device's parameter row (the layout of each kind is in ``device_params``)."""

# capstan row: [mu_k, mu_s, ...]; sheave row: [rho_k, rho_s, ...] (rho = mu_b r_pin / r)
# latch parameter row: [r, x_backstop, k, mu_s, h, R, Lb, Fh, ell, mu_k, rho_k, rho_s] (rho: the
# bearing friction of a sheave at the latch, as in the pulley-and-latch unit of ADAM; 0: none)
LATCH_LB = 6
LATCH_MU_K = 9
LATCH_RHO = 10


@njit(cache=True)
def _bearing(sigma, T_in, T_out, phi, rho):
    """A sheave's bearing: r = T_out - T_in - sigma rho |F|, |F| = sqrt(T_in^2 + T_out^2 - 2 T_in T_out
    cos phi); returns (r, dr/dT_in, dr/dT_out, dr/ds = 0, dr/dphi)."""
    c = math.cos(phi)
    F2 = T_in * T_in + T_out * T_out - 2.0 * T_in * T_out * c
    F = math.sqrt(F2) if F2 > 0.0 else 0.0
    if F <= 1e-300:  # both sides slack: no resultant, no friction
        return T_out - T_in, -1.0, 1.0, 0.0, 0.0
    a = sigma * rho / F
    return (
        T_out - T_in - sigma * rho * F,
        -1.0 - a * (T_in - T_out * c),
        1.0 - a * (T_out - T_in * c),
        0.0,
        -a * T_in * T_out * math.sin(phi),
    )


@njit(cache=True)
def builtin_law(kind, sigma, T_in, T_out, s, phi, p, static):
    """The built-in laws (module note): returns (r, dr/dT_in, dr/dT_out, dr/ds, dr/dphi), N and N/m,
    N/rad; ``static``: the static coefficient (the band of a device at rest)."""
    if kind == CAPSTAN:
        mu = p[1] if static else p[0]
        E = math.exp(sigma * mu * phi)
        return T_out - T_in * E, -E, 1.0, 0.0, -T_in * E * sigma * mu
    if kind == SHEAVE:
        return _bearing(sigma, T_in, T_out, phi, p[1] if static else p[0])
    if kind == LATCH:
        x = p[LATCH_LB] - s
        D, dD = branch_scalar_mu(x, sigma, p[0:6], p[3] if static else p[LATCH_MU_K], p[7], p[8])
        rho = p[LATCH_RHO + 1] if static else p[LATCH_RHO]
        if rho > 0.0:  # a sheave's bearing at the latch (the unit's pulley)
            r, a, b, _, d = _bearing(sigma, T_in, T_out, phi, rho)
            return r - D, a, b, dD, d
        return T_out - T_in - D, -1.0, 1.0, dD, 0.0
    return T_out - T_in, -1.0, 1.0, 0.0, 0.0


@njit(cache=True)
def no_user_law(sigma, T_in, T_out, s, phi, p):
    """Placeholder user law of families without user devices (a frictionless joint)."""
    return T_out - T_in, -1.0, 1.0, 0.0, 0.0


@njit(cache=True)
def s_max_of(kind, p):
    """Largest material coordinate the device allows, m (the latch backstop; else +inf)."""
    if kind == LATCH:
        return p[LATCH_LB] + p[1]
    return math.inf


@njit(cache=True)
def max_step(kind, s, p):
    """Largest change of s (m) in one Newton step of a sliding device: inside a latch's roller
    contact zone, one cell of the grid the single-latch element marches on (so the bead stops at
    the *first* equilibrium in its direction of motion, Stohlman & Pellegrino, Sec. II.B.2); else +inf."""
    if kind == LATCH:
        r = p[0]
        h = p[4]
        R = p[5]
        c2 = (r + R) * (r + R) - (h + r) * (h + r)
        xct = math.sqrt(c2) if c2 > 0.0 else 0.0
        x = p[LATCH_LB] - s
        cell = 2.0 * xct / 256.0
        if abs(x) < xct + cell:
            return cell
    return math.inf
