"""Numba kernels of the friction ball joint (see :mod:`femast.elements.ball_joint`).

One element, local DOF order [xa(3), wa(3), xb(3), wb(3)] (translations, spatial spins).

State row (``N_STATE`` = 15)::

    0:3   m      committed friction moment in the body frame of node b, N m
    3     slip   1.0 if the joint slipped in the committed increment, else 0.0
    4     gamma  accumulated slip (relative rotation by sliding), rad
    5     D      dissipated energy, J
    6:15  Q      committed relative rotation Q = R_a^T R_b, row-major

In a trial state, slip = -1.0 marks a joint taken as stuck for one Newton iteration because its
slip direction reversed since the previous iteration (:func:`ball_joint_element`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import carray, njit

from ..rotations import logm_so3_into, skew, ts_inv
from ._mat3 import mm_at
from ._stack import stack_buffer

N_STATE = 15
I_M = 0
I_SLIP = 3
I_GAMMA = 4
I_DISS = 5
I_Q = 6
REVERSED = -1.0  # slip flag of a trial state: slip reversed, taken as stuck for this iteration

# error codes of the kernel
OK = 0
ERR_NOT_FINITE = 1
ERR_BIG_INCREMENT = 2

# a relative-rotation increment this close to pi cannot be told from its complement
MAX_INCREMENT = 3.0  # rad


@njit(cache=True)
def relative_increment_into(Ra, Rb, st, Q, th):
    """Finite relative-rotation increment ``th = log(Q_c^T Q)`` (3), Q = R_a^T R_b (3x3, written too)
    (right, body-b form: Q = Q_c exp(theta)), Q_c the committed Q of state row ``st``; returns the
    error code.  No allocation (:mod:`._mat3`)."""
    Qc = carray(stack_buffer(9), (3, 3))
    D = carray(stack_buffer(9), (3, 3))
    mm_at(Ra, Rb, Q)
    for i in range(3):
        for j in range(3):
            Qc[i, j] = st[I_Q + 3 * i + j]
    mm_at(Qc, Q, D)
    logm_so3_into(D, th)
    tn = math.sqrt(th[0] ** 2 + th[1] ** 2 + th[2] ** 2)
    return ERR_BIG_INCREMENT if tn > MAX_INCREMENT else OK


@njit(cache=True)
def relative_increment(Ra, Rb, st):
    """:func:`relative_increment_into` returning (theta, error code)."""
    Q = np.empty((3, 3))
    th = np.empty(3)
    err = relative_increment_into(Ra, Rb, st, Q, th)
    return th, err


@njit(cache=True)
def friction_return(st, th, k_s, Ys, Yk, prev, has_prev, m, C, nv):
    """Static/kinetic Coulomb friction of a joint's moment: elastic predictor and radial return.

    st : the committed state row (moment ``st[I_M:I_M+3]`` and slip flag ``st[I_SLIP]``).
    th : (3) relative-rotation increment of the increment (body frame of node b), rad.
    Ys, Yk : static and kinetic limits mu_s B |F|, mu_k B |F| (N m), Ys >= Yk.
    Fills ``m`` (3, the moment, body frame of b), ``C`` (3x3, dm/dth) and, when slipping, ``nv``
    (3, the slip direction m_tr / |m_tr|).
    Returns (slip flag of the trial state, slip increment dgamma (rad), dissipation (J), limit (N m)).

    The limit that must be exceeded to slip is Yk if the joint slipped in the committed increment
    and keeps turning the same way (``m_c . th >= 0``: the straight elastic path from m_c stays
    outside |m| < Yk), Ys otherwise (it was stuck, or turned back into the stick region: a reversal).
    A slip returns to Yk (radial return: m = Yk n, dgamma = (|m_tr| - Yk) / k_s).  At a slip onset
    from Ys the dissipation adds (Ys - Yk)^2 / (2 k_s): the elastic energy released by the drop
    from Ys to Yk (so that work = stored energy + dissipation holds exactly in one-axis motion).
    With Ys = Yk this is the paper's one-coefficient law, to the bit.  ``prev``: see
    :func:`ball_joint_element` (slip reversal between Newton iterations)."""
    mtr0 = st[I_M] + k_s * th[0]
    mtr1 = st[I_M + 1] + k_s * th[1]
    mtr2 = st[I_M + 2] + k_s * th[2]
    nm = math.sqrt(mtr0**2 + mtr1**2 + mtr2**2)
    Y = Ys
    if Yk != Ys and st[I_SLIP] == 1.0 and st[I_M] * th[0] + st[I_M + 1] * th[1] + st[I_M + 2] * th[2] >= 0.0:
        Y = Yk  # slipping on: the kinetic limit
    # slip reversed since the previous iteration: stuck for this iteration (see ball_joint_element)
    reversed_ = False
    if has_prev and prev[I_SLIP] == 1.0 and nm > Y * (1.0 + 1e-12):
        reversed_ = mtr0 * prev[I_M] + mtr1 * prev[I_M + 1] + mtr2 * prev[I_M + 2] < 0.0
    for i in range(3):
        for j in range(3):
            C[i, j] = 0.0
    # relative tolerance: a point on the slip surface (|m_tr| = Y to round-off) sticks
    if nm <= Y * (1.0 + 1e-12) or reversed_:
        m[0] = mtr0
        m[1] = mtr1
        m[2] = mtr2
        for i in range(3):
            C[i, i] = k_s
        return (REVERSED if reversed_ else 0.0), 0.0, 0.0, Ys
    # return mapping (radial return = backward Euler on the circular slip surface)
    nv[0] = mtr0 / nm
    nv[1] = mtr1 / nm
    nv[2] = mtr2 / nm
    dgam = (nm - Yk) / k_s
    r = Yk * k_s / nm
    for i in range(3):
        m[i] = Yk * nv[i]
        for j in range(3):
            C[i, j] = r * ((1.0 if i == j else 0.0) - nv[i] * nv[j])
    dD = Yk * dgam
    if Y != Yk:
        dD += (Y - Yk) ** 2 / (2.0 * k_s)  # onset: the drop from the static to the kinetic limit
    return 1.0, dgam, dD, Yk


@njit(cache=True)
def ball_joint_element(xa, xb, Ra, Rb, d0, k_pen, k_s, mu_s, mu_k, B, st, f, K, new, out, prev, has_prev):
    """Forces ``f`` (12), tangent ``K`` (12x12), trial state ``new`` (15) and output ``out``
    (11: M (3, global), F (3, global), |F|, limit, slip, gamma, D) of one tied joint (the paper's
    two-way tie); static and kinetic coefficients ``mu_s``, ``mu_k`` (:func:`friction_return`).

    ``prev`` (15): the joint's trial state at the previous Newton iteration (``has_prev``).  A
    joint that slipped there and would now slip the opposite way (trial moment against the
    previous moment) is answered as stuck (m = m_tr, tangent k_s) for this one iteration, and its
    trial state is marked ``slip = REVERSED``: Newton's step then puts it back at its stuck
    equilibrium.  Without this the iterates of a joint whose equilibrium lies in the narrow stick
    band |m_tr| <= Y (width Y / k_s in rotation) jump across the band from one slip direction to
    the other for ever when the mode is soft (a longeron spinning between two slipping joints,
    held only by the joint springs: Newton's step is ~Y / k_spring, 1e3 times the band).
    Returns (strain energy in J, error code)."""
    # tie: node b sits at the point x_a + R_a d0 of node a (d0: initial offset, below the tolerance)
    c = Ra @ d0
    d = xb - xa - c
    F = k_pen * d
    Fn = math.sqrt(F[0] * F[0] + F[1] * F[1] + F[2] * F[2])
    if not (math.isfinite(Fn) and math.isfinite(Ra.sum()) and math.isfinite(Rb.sum())):
        return 0.0, ERR_NOT_FINITE
    th, err = relative_increment(Ra, Rb, st)
    C = np.empty((3, 3))
    m = np.empty(3)
    n = np.empty(3)
    G = np.zeros((3, 3))  # dm/dd (slip only): n (mu_k B dFn/dd)^T
    slip, dgam, dD, Y = friction_return(st, th, k_s, mu_s * B * Fn, mu_k * B * Fn, prev, has_prev, m, C, n)
    if slip == 1.0 and Fn > 0.0:
        g = (mu_k * B * k_pen / Fn) * F  # d|F|/dd * mu_k B
        for i in range(3):
            for j in range(3):
                G[i, j] = n[i] * g[j]
    Q = Ra.T @ Rb
    M = Rb @ m
    # dm/dw_b = C Ts^-T(th) Rb^T = -dm/dw_a ; spatial A = Rb C Ts^-T Rb^T
    A = Rb @ (C @ (ts_inv(th).T @ Rb.T))
    Gs = Rb @ G
    SM = skew(M)
    Sc = skew(c)
    Gc = Gs @ Sc  # d(M)/d(w_a) through |F| (eccentric tie)
    kSc = k_pen * Sc  # dF/dw_a
    SF = skew(F)
    # tie moment on node a: F x c; its derivative w.r.t. w_a
    Kcc = -(Sc @ kSc) - SF @ Sc
    for i in range(12):
        f[i] = 0.0
        for j in range(12):
            K[i, j] = 0.0
    for i in range(3):
        f[i] = -F[i]
        f[6 + i] = F[i]
        f[3 + i] = -M[i] + (F[(i + 1) % 3] * c[(i + 2) % 3] - F[(i + 2) % 3] * c[(i + 1) % 3])
        f[9 + i] = M[i]
        K[i, i] = k_pen
        K[6 + i, 6 + i] = k_pen
        K[i, 6 + i] = -k_pen
        K[6 + i, i] = -k_pen
        for j in range(3):
            a = A[i, j]
            b = A[i, j] - SM[i, j]
            g = Gs[i, j]
            # tie forces: F depends on w_a through the offset
            K[6 + i, 3 + j] = kSc[i, j]
            K[i, 3 + j] = -kSc[i, j]
            # row of node b's moment
            K[9 + i, 9 + j] = b
            K[9 + i, 3 + j] = -a + Gc[i, j]
            K[9 + i, 6 + j] = g
            K[9 + i, j] = -g
            # node a's moment is the opposite, plus the tie moment F x c
            K[3 + i, 9 + j] = -b
            K[3 + i, 3 + j] = a - Gc[i, j] + Kcc[i, j]
            K[3 + i, 6 + j] = -g - kSc[i, j]
            K[3 + i, j] = g + kSc[i, j]
    for i in range(3):
        new[I_M + i] = m[i]
    new[I_SLIP] = slip
    new[I_GAMMA] = st[I_GAMMA] + dgam
    new[I_DISS] = st[I_DISS] + dD
    for i in range(3):
        for j in range(3):
            new[I_Q + 3 * i + j] = Q[i, j]
    for i in range(3):
        out[i] = M[i]
        out[3 + i] = F[i]
    out[6] = Fn
    out[7] = Y
    out[8] = max(slip, 0.0)
    out[9] = new[I_GAMMA]
    out[10] = new[I_DISS]
    mm = m[0] ** 2 + m[1] ** 2 + m[2] ** 2
    return 0.5 * Fn * Fn / k_pen + 0.5 * mm / k_s, err


@njit(cache=True)
def ball_joint_family_kernel(
    nodes, x, R, d0, k_pen, k_s, mu_s, mu_k, B, state, f, K, new, out, energy, err, prev, has_prev
):
    """All joints of a family at once (see :func:`ball_joint_element`); ``prev`` (n_el, 15):
    the previous iteration's trial states (read only if ``has_prev``)."""
    for e in range(nodes.shape[0]):
        a = nodes[e, 0]
        b = nodes[e, 1]
        en, code = ball_joint_element(
            x[a],
            x[b],
            R[a],
            R[b],
            d0[e],
            k_pen[e],
            k_s[e],
            mu_s[e],
            mu_k[e],
            B[e],
            state[e],
            f[e],
            K[e],
            new[e],
            out[e],
            prev[e if has_prev else 0],
            has_prev,
        )
        energy[e] = en
        err[e] = code
