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

The ``*_into`` helpers and ``_eta`` are ``inline='always'``: they are inlined into the element
kernels that call them, so those kernels' scratch arrays stay on the stack (femast.elements._stack).
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


@njit(cache=True, inline="always")
def _quaternion(R):
    """The unit quaternion (q0, q1, q2, q3), q0 >= 0, of the rotation matrix ``R`` (Spurrier's
    method, accurate near 0 and pi)."""
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    m = max(tr, R[0, 0], R[1, 1], R[2, 2])
    if m == tr:
        q0 = 0.5 * math.sqrt(1.0 + tr)
        s = 0.25 / q0
        q1 = (R[2, 1] - R[1, 2]) * s
        q2 = (R[0, 2] - R[2, 0]) * s
        q3 = (R[1, 0] - R[0, 1]) * s
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
        q0 = (R[k, j] - R[j, k]) * s
        qj = (R[j, i] + R[i, j]) * s
        qk = (R[k, i] + R[i, k]) * s
        # scatter (qi, qj, qk) to the vector part (q1, q2, q3)
        if i == 0:
            q1, q2, q3 = qi, qj, qk
        elif i == 1:
            q1, q2, q3 = qk, qi, qj
        else:
            q1, q2, q3 = qj, qk, qi
    if q0 < 0.0:
        q0, q1, q2, q3 = -q0, -q1, -q2, -q3
    return q0, q1, q2, q3


@njit(cache=True, inline="always")
def logm_so3_into(R, out):
    """Rotation vector (rad, |v| <= pi) of the rotation matrix ``R`` written into ``out`` (3,),
    without allocating.  Uses the quaternion of R (Spurrier's method), accurate near 0 and pi."""
    q0, q1, q2, q3 = _quaternion(R)
    nv = math.sqrt(q1 * q1 + q2 * q2 + q3 * q3)
    if nv < 1e-300:
        out[0] = 0.0
        out[1] = 0.0
        out[2] = 0.0
        return
    f = 2.0 * math.atan2(nv, q0) / nv
    out[0] = f * q1
    out[1] = f * q2
    out[2] = f * q3


@njit(cache=True, inline="always")
def logm_so3_small_into(R, out):
    """:func:`logm_so3_into` for rotations that are mostly small (a corotational element's local
    rotations): below |v| = 0.02 rad, 2 atan(x) / (x q0) with x = tan(|v| / 2) = |q| / q0 by its
    series to x^8 (truncation x^10 / 11 < 1e-20 relative; against an exact logarithm of the same
    matrices both are within 6e-16), instead of atan2, which was 1/8 of the beam kernel's time;
    larger rotations go to :func:`logm_so3_into`."""
    q0, q1, q2, q3 = _quaternion(R)
    v2 = q1 * q1 + q2 * q2 + q3 * q3
    if v2 < 1e-4 * (q0 * q0):
        iq = 1.0 / q0
        x2 = v2 * (iq * iq)
        f = (2.0 * iq) * (1.0 - x2 * (1.0 / 3.0 - x2 * (1.0 / 5.0 - x2 * (1.0 / 7.0 - x2 * (1.0 / 9.0)))))
        out[0] = f * q1
        out[1] = f * q2
        out[2] = f * q3
    else:
        logm_so3_into(R, out)


@njit(cache=True)
def logm_so3(R):
    """Rotation vector (rad, |v| <= pi) of the rotation matrix ``R``.

    Uses the quaternion of R (Spurrier's method), accurate near 0 and near pi.
    """
    out = np.empty(3)
    logm_so3_into(R, out)
    return out


@njit(cache=True, inline="always")
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


@njit(cache=True, inline="always")
def ts_inv_into(theta, out):
    """Ts^-1(theta) = I - S/2 + eta S^2 written into the 3x3 ``out`` (S^2 = theta theta^T - t^2 I)."""
    t2 = theta[0] * theta[0] + theta[1] * theta[1] + theta[2] * theta[2]
    eta, _ = _eta(math.sqrt(t2))
    for i in range(3):
        for j in range(3):
            out[i, j] = eta * theta[i] * theta[j]
        out[i, i] += 1.0 - eta * t2
    out[0, 1] += 0.5 * theta[2]
    out[0, 2] -= 0.5 * theta[1]
    out[1, 0] -= 0.5 * theta[2]
    out[1, 2] += 0.5 * theta[0]
    out[2, 0] += 0.5 * theta[1]
    out[2, 1] -= 0.5 * theta[0]


@njit(cache=True)
def ts_inv(theta):
    """Ts^-1(theta): maps a spatial spin to the variation of the rotation vector."""
    out = np.empty((3, 3))
    ts_inv_into(theta, out)
    return out


@njit(cache=True, inline="always")
def ts_inv_T_times_derivative_into(theta, m, out):
    """d/dtheta [Ts^-T(theta) m] for fixed m written into the 3x3 ``out`` (Battini & Pacoste 2002, K_h)."""
    tt = theta[0] * theta[0] + theta[1] * theta[1] + theta[2] * theta[2]
    eta, deta_t = _eta(math.sqrt(tt))
    tm = theta[0] * m[0] + theta[1] * m[1] + theta[2] * m[2]
    for i in range(3):
        vi = (theta[i] * tm - m[i] * tt) * deta_t  # theta x (theta x m), times eta'(t)/t
        for j in range(3):
            out[i, j] = eta * (theta[i] * m[j] - 2.0 * m[i] * theta[j]) + vi * theta[j]
        out[i, i] += eta * tm
    # -skew(m) / 2
    out[0, 1] += 0.5 * m[2]
    out[0, 2] -= 0.5 * m[1]
    out[1, 0] -= 0.5 * m[2]
    out[1, 2] += 0.5 * m[0]
    out[2, 0] += 0.5 * m[1]
    out[2, 1] -= 0.5 * m[0]


@njit(cache=True)
def ts_inv_T_times_derivative(theta, m):
    """d/dtheta [Ts^-T(theta) m] for fixed m, a 3x3 matrix (Battini & Pacoste 2002, K_h)."""
    out = np.empty((3, 3))
    ts_inv_T_times_derivative_into(theta, m, out)
    return out


@njit(cache=True)
def _rotation_vectors(R, out):
    for i in range(R.shape[0]):
        logm_so3_into(R[i], out[i])


@njit(cache=True)
def apply_spins(R, W):
    """R[i] <- exp(skew(W[i])) R[i] for every node i with a nonzero spin W[i] (in place)."""
    E = np.empty((3, 3))
    C = np.empty((3, 3))
    for n in range(R.shape[0]):
        w0 = W[n, 0]
        w1 = W[n, 1]
        w2 = W[n, 2]
        if w0 == 0.0 and w1 == 0.0 and w2 == 0.0:
            continue
        t2 = w0 * w0 + w1 * w1 + w2 * w2
        if t2 < 1e-8:
            a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0
            b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0
        else:
            t = math.sqrt(t2)
            a = math.sin(t) / t
            b = (1.0 - math.cos(t)) / t2
        # exp = I + a S + b S^2,  S^2 = w w^T - t^2 I
        E[0, 0] = 1.0 + b * (w0 * w0 - t2)
        E[1, 1] = 1.0 + b * (w1 * w1 - t2)
        E[2, 2] = 1.0 + b * (w2 * w2 - t2)
        E[0, 1] = b * w0 * w1 - a * w2
        E[1, 0] = b * w0 * w1 + a * w2
        E[0, 2] = b * w0 * w2 + a * w1
        E[2, 0] = b * w0 * w2 - a * w1
        E[1, 2] = b * w1 * w2 - a * w0
        E[2, 1] = b * w1 * w2 + a * w0
        for i in range(3):
            for j in range(3):
                C[i, j] = E[i, 0] * R[n, 0, j] + E[i, 1] * R[n, 1, j] + E[i, 2] * R[n, 2, j]
        for i in range(3):
            for j in range(3):
                R[n, i, j] = C[i, j]


def rotation_vectors(R: np.ndarray) -> np.ndarray:
    """Rotation vectors (rad) of an array of rotation matrices (..., 3, 3)."""
    flat = np.ascontiguousarray(np.asarray(R, dtype=float).reshape(-1, 3, 3))
    out = np.empty((flat.shape[0], 3))
    _rotation_vectors(flat, out)
    return out.reshape(np.shape(R)[:-2] + (3,))
