"""Device laws of a cable over devices (Stohlman & Pellegrino, Sec. II.B.2, Eq. 5): the numba side.

Private module: the public face is :mod:`femast.elements.cable_devices`.

The device contract
-------------------
A device sits at an interior node of the cable, between the section before it ("in", tension
T_in) and the section after it ("out", T_out).  ``s`` (m) is the material coordinate of the cable
at the device (unstretched length from node 0).  A device either grips the cable (stick: ``s``
stays at its committed value) or lets it slide.  Sliding in direction ``sigma = +1`` means the
out side pulls the cable through (``ds < 0``), ``sigma = -1`` the in side (``ds > 0``).  A law is

    law(kind, sigma, T_in, T_out, s, phi, p) -> (r, dr/dT_in, dr/dT_out, dr/ds, dr/dphi)

with ``r`` the unbalanced force (N) of branch ``sigma``: the device slides on branch sigma where
``r = 0``, and it sticks while ``r(+1) <= 0 <= r(-1)`` (the static band).  ``phi`` is the wrap
angle (rad) from the current geometry and ``p`` the device's parameter row.  A user law has the
same signature without ``kind`` (see :class:`femast.elements.cable_devices.UserDevice`).

Built-in laws:

* capstan pulley (Euler-Eytelwein): ``r = T_out - T_in exp(sigma mu phi)``; the band is
  ``exp(-mu phi) <= T_out / T_in <= exp(mu phi)``;
* latch (Stohlman & Pellegrino, Eqs. 5, 14): ``r = T_out - T_in - dT_sigma(x)``, ``x = Lb - s``; the backstop
  bounds ``s <= Lb + x_backstop``.  Optional hysteresis as in :mod:`femast.elements.latch_law`.

Frictionless pulleys (equal strains on both sides, which is equal tensions when taut and a
proportional share of the slack when slack, as in :mod:`._cable_kernels`) and clamps (never
slide) are handled by the solver itself.
"""

from __future__ import annotations

import math

from numba import njit

from ._cable_kernels import branch_scalar

FREE = 0  # frictionless pulley
CAPSTAN = 1  # pulley with Coulomb friction (capstan law)
LATCH = 2  # roller latch of Stohlman & Pellegrino
CLAMP = 3  # fixed clamp: no sliding
USER = 4  # a user law

N_PARAM = 10
"""Length of a device's parameter row (the layout of each kind is in ``device_params``)."""

# latch parameter row: [r, x_backstop, k, mu, h, R, Lb, Fh, ell, -]
LATCH_LB = 6


@njit(cache=True)
def builtin_law(kind, sigma, T_in, T_out, s, phi, p):
    """The built-in laws (module note): returns (r, dr/dT_in, dr/dT_out, dr/ds, dr/dphi), N and N/m, N/rad."""
    if kind == CAPSTAN:
        mu = p[0]
        E = math.exp(sigma * mu * phi)
        return T_out - T_in * E, -E, 1.0, 0.0, -T_in * E * sigma * mu
    if kind == LATCH:
        x = p[LATCH_LB] - s
        D, dD = branch_scalar(x, sigma, p[0:6], p[7], p[8])
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
