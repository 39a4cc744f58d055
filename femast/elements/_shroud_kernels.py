"""numba kernels of the Dyneema shroud element: the rope law (the Rocaspect paper, Eqs. 25 and 27
inverted), its tangent rigidity, and the family kernel (forces, consistent tangent, the
loading/unloading option).

Private module: the public face is :mod:`femast.elements.shroud_cable` (equations in its docstring).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .shroud_hysteresis import friction_return

ERR_ZERO_LENGTH = 1
ERR_BEYOND_LAW = 2
ERR_NOT_FINITE = 3

# 5-point Gauss-Legendre rule on [0, 1] for the strain energy L0 * int_0^eps tau(e) de
_GX = np.array([0.04691007703066800, 0.23076534494715845, 0.5, 0.76923465505284155, 0.95308992296933200])
_GW = np.array(
    [0.11846344252809454, 0.23931433524968324, 0.28444444444444444, 0.23931433524968324, 0.11846344252809454]
)


@njit(cache=True)
def dyneema_tension(eps, k0, k1, k2):
    """Tension (N) of the rope law at strain eps (Eq. 27 inverted; 0 for eps < 0).
    Returns (tau, ok): ok False when eps is beyond the range where the law has a finite root."""
    if eps <= 0.0:
        return 0.0, True
    a = 1.0 - k1 * eps
    disc = a * a - 4.0 * k0 * k2 * eps * eps
    if disc < 0.0:
        return 0.0, False
    den = a + math.sqrt(disc)
    if den <= 0.0:
        return 0.0, False
    return 2.0 * k0 * eps / den, True


@njit(cache=True)
def dyneema_tangent_rigidity(tau, k0, k1, k2):
    """EA_t = d tau / d eps = g^2 / (k0 - k2 tau^2), N (derivative of tau = g(tau) eps)."""
    g = k0 + k1 * tau + k2 * tau * tau
    return g * g / (k0 - k2 * tau * tau)


@njit(cache=True)
def shroud_family_kernel(
    nodes, x, R, offsets, L0, law, hyst, state, parts, gx, gw, f, K, new, tau_out, eps_out, len_out, energy, err
):
    """All shroud elements in one call: forces f (n, 12), tangent K (n, 12, 12), trial state ``new``,
    tension, strain, length, strain energy and an error code per element (see module docstring).
    ``hyst`` (n, 2): [eta (-), k_s (N)] of the loading/unloading option (:mod:`.shroud_hysteresis`;
    eta = 0: off); ``state`` (n, 2) committed [strain, friction tension (N)] (read only; unused when
    off).  Serial on purpose: a family holds a few ropes (3 per mast), and ``parallel=True`` doubles
    the compile time (~11 s)."""
    for el in range(nodes.shape[0]):
        a = nodes[el, 0]
        b = nodes[el, 1]
        ra = R[a] @ offsets[el, 0]
        rb = R[b] @ offsets[el, 1]
        d = (x[b] + rb) - (x[a] + ra)
        l = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        if not math.isfinite(l):
            err[el] = ERR_NOT_FINITE
            continue
        if l <= 1e-12 * L0[el]:
            err[el] = ERR_ZERO_LENGTH
            continue
        e = d / l
        k0 = law[el, 0]
        k1 = law[el, 1]
        k2 = law[el, 2]
        eps = l / L0[el] - 1.0
        if eps < 0.0:
            tau = 0.0
            kt = 0.0
        else:
            tau, ok = dyneema_tension(eps, k0, k1, k2)
            if not ok:
                err[el] = ERR_BEYOND_LAW
                continue
            kt = dyneema_tangent_rigidity(tau, k0, k1, k2) / L0[el]
            if not (kt > 0.0):
                err[el] = ERR_BEYOND_LAW
                continue
        eta = hyst[el, 0]
        if eta > 0.0:  # loading/unloading: a friction tension in parallel, |tau_f| <= eta tau
            tf, dtf = friction_return(eps, tau, kt * L0[el], eta, hyst[el, 1], state[el, 0], state[el, 1])
            new[el, 0] = eps
            new[el, 1] = tf
            tau += tf
            kt += dtf / L0[el]
        tau_out[el] = tau
        eps_out[el] = eps
        len_out[el] = l
        # strain energy L0 int_0^eps tau de (Gauss-Legendre, exact to ~1e-12 for this smooth law)
        en = 0.0
        if eps > 0.0:
            for g in range(gx.shape[0]):
                t, ok = dyneema_tension(gx[g] * eps, k0, k1, k2)
                en += gw[g] * t
            en *= eps * L0[el]
        if eta > 0.0:  # the friction element's stick spring
            en += 0.5 * L0[el] * new[el, 1] ** 2 / hyst[el, 1]
        energy[el] = en
        # D = [-G_a, G_b], G = [I, -[r]x]; B = D^T e
        Dm = np.zeros((3, 12))
        for i in range(3):
            Dm[i, i] = -1.0
            Dm[i, 6 + i] = 1.0
        # -G_a rotation block = +[r_a]x ; G_b rotation block = -[r_b]x
        Dm[0, 4] = -ra[2]
        Dm[0, 5] = ra[1]
        Dm[1, 3] = ra[2]
        Dm[1, 5] = -ra[0]
        Dm[2, 3] = -ra[1]
        Dm[2, 4] = ra[0]
        Dm[0, 10] = rb[2]
        Dm[0, 11] = -rb[1]
        Dm[1, 9] = -rb[2]
        Dm[1, 11] = rb[0]
        Dm[2, 9] = rb[1]
        Dm[2, 10] = -rb[0]
        B = Dm.T @ e
        for i in range(12):
            f[el, i] = tau * B[i]
        Kel = np.zeros((12, 12))
        if parts & 1:
            for i in range(12):
                for j in range(12):
                    Kel[i, j] += kt * B[i] * B[j]
        if parts & 2:
            P = np.eye(3)
            for i in range(3):
                for j in range(3):
                    P[i, j] -= e[i] * e[j]
            Kel += (tau / l) * (Dm.T @ P @ Dm)
            # arms turning with the nodes: tau [e]x[r]x = tau (r e^T - (e . r) I), sign -/+ for a/b
            era = e[0] * ra[0] + e[1] * ra[1] + e[2] * ra[2]
            erb = e[0] * rb[0] + e[1] * rb[1] + e[2] * rb[2]
            for i in range(3):
                for j in range(3):
                    ia = ra[i] * e[j] - (era if i == j else 0.0)
                    ib = rb[i] * e[j] - (erb if i == j else 0.0)
                    Kel[3 + i, 3 + j] -= tau * ia
                    Kel[9 + i, 9 + j] += tau * ib
        for i in range(12):
            for j in range(12):
                K[el, i, j] = Kel[i, j]
