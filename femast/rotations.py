"""Finite rotations: exponential and logarithm maps of SO(3) and the tangent operator.

Nodal rotations are stored as rotation matrices (total rotation from the initial
triad), updated multiplicatively by spatial spin increments, R <- exp(skew(dw)) R,
so no small-angle error accumulates and total rotations beyond 2 pi are exact.

Conventions (spatial / left spin): for R = exp(skew(theta)), a variation of the
rotation vector dtheta gives the spin dw with skew(dw) = dR R^T,

    dw = Ts(theta) dtheta,
    Ts(theta)   = I + (1 - cos t)/t^2 S + (t - sin t)/t^3 S^2,      t = |theta|, S = skew(theta)
    Ts^-1(theta) = I - S/2 + eta(t) S^2,   eta = (1 - (t/2) cot(t/2)) / t^2

(e.g. Battini & Pacoste 2002, CMAME 191:1755, Eqs. 14-17).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def skew(v):
    """The cross-product matrix [v]x, so that skew(v) @ u = v x u."""
    S = np.zeros((3, 3))
    S[0, 1] = -v[2]
    S[0, 2] = v[1]
    S[1, 0] = v[2]
    S[1, 2] = -v[0]
    S[2, 0] = -v[1]
    S[2, 1] = v[0]
    return S


@njit(cache=True)
def _sq(S):
    """S @ S for a 3x3 matrix, as loops (numba's @ calls BLAS: slow for 3x3)."""
    out = np.zeros((3, 3))
    for i in range(3):
        for j in range(3):
            for k in range(3):
                out[i, j] += S[i, k] * S[k, j]
    return out


@njit(cache=True)
def expm_so3(v):
    """Rotation matrix exp(skew(v)) of the rotation vector ``v`` (rad), Rodrigues' formula."""
    t2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    t = math.sqrt(t2)
    if t < 1e-4:
        # Taylor series, error below 1e-17.
        a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0
        b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0
    else:
        a = math.sin(t) / t
        b = (1.0 - math.cos(t)) / t2
    S = skew(v)
    return np.eye(3) + a * S + b * _sq(S)


@njit(cache=True)
def logm_so3(R):
    """Rotation vector (rad, |v| <= pi) of the rotation matrix ``R``.

    Uses the quaternion of R (Spurrier's method), accurate near 0 and near pi.
    """
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    q = np.empty(4)
    m = max(tr, R[0, 0], R[1, 1], R[2, 2])
    if m == tr:
        q[0] = 0.5 * math.sqrt(1.0 + tr)
        s = 0.25 / q[0]
        q[1] = (R[2, 1] - R[1, 2]) * s
        q[2] = (R[0, 2] - R[2, 0]) * s
        q[3] = (R[1, 0] - R[0, 1]) * s
    else:
        i = 0
        if R[1, 1] > R[i, i]:
            i = 1
        if R[2, 2] > R[i, i]:
            i = 2
        j = (i + 1) % 3
        k = (j + 1) % 3
        qi = 0.5 * math.sqrt(1.0 + R[i, i] - R[j, j] - R[k, k])
        s = 0.25 / qi
        q[0] = (R[k, j] - R[j, k]) * s
        q[1 + i] = qi
        q[1 + j] = (R[j, i] + R[i, j]) * s
        q[1 + k] = (R[k, i] + R[i, k]) * s
    if q[0] < 0.0:
        for c in range(4):
            q[c] = -q[c]
    nv = math.sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    out = np.zeros(3)
    if nv < 1e-300:
        return out
    angle = 2.0 * math.atan2(nv, q[0])
    for c in range(3):
        out[c] = angle * q[1 + c] / nv
    return out


@njit(cache=True)
def _eta(t):
    """eta(t) = (1 - (t/2) cot(t/2)) / t^2 and eta'(t)/t."""
    if t < 0.05:
        t2 = t * t
        eta = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
        deta_over_t = 1.0 / 360.0 + t2 / 7560.0 + t2 * t2 / 201600.0
        return eta, deta_over_t
    h = 0.5 * t
    cot = math.cos(h) / math.sin(h)
    g = 1.0 - h * cot
    dg = -0.5 * cot + 0.25 * t / (math.sin(h) ** 2)
    eta = g / (t * t)
    deta = dg / (t * t) - 2.0 * g / (t * t * t)
    return eta, deta / t


@njit(cache=True)
def ts_inv(theta):
    """Ts^-1(theta): maps a spatial spin to the variation of the rotation vector."""
    t = math.sqrt(theta[0] ** 2 + theta[1] ** 2 + theta[2] ** 2)
    eta, _ = _eta(t)
    S = skew(theta)
    return np.eye(3) - 0.5 * S + eta * _sq(S)


@njit(cache=True)
def ts_inv_T_times_derivative(theta, m):
    """d/dtheta [Ts^-T(theta) m] for fixed m, a 3x3 matrix (Battini & Pacoste 2002, K_h)."""
    t = math.sqrt(theta[0] ** 2 + theta[1] ** 2 + theta[2] ** 2)
    eta, deta_t = _eta(t)
    tm = theta[0] * m[0] + theta[1] * m[1] + theta[2] * m[2]
    tt = t * t
    v = theta * tm - m * tt  # theta x (theta x m)
    K = -0.5 * skew(m)
    for i in range(3):
        K[i, i] += eta * tm
        for j in range(3):
            K[i, j] += eta * (theta[i] * m[j] - 2.0 * m[i] * theta[j]) + v[i] * deta_t * theta[j]
    return K


def rotation_vectors(R: np.ndarray) -> np.ndarray:
    """Rotation vectors (rad) of an array of rotation matrices (..., 3, 3)."""
    flat = np.asarray(R, dtype=float).reshape(-1, 3, 3)
    out = np.empty((flat.shape[0], 3))
    for i in range(flat.shape[0]):
        out[i] = logm_so3(flat[i])
    return out.reshape(np.shape(R)[:-2] + (3,))
