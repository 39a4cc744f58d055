"""Numba kernels of the seated ball joint (see :mod:`femast.elements.ball_joint`, ``seat="seated"``).

One element, local DOF order [xa(3), wa(3), xb(3), wb(3)] (translations, spatial spins); node a is
the ball (longeron end), node b the socket (corner).  The state row is the tied joint's
(:mod:`femast.elements._ball_joint_kernels`): the friction part is the same law.

Socket frame: the body frame of node b.  ``e`` (unit, body frame of b) is the seat axis, pointing
from the seat into the longeron: the direction in which the ball lifts off.  With ``p`` the
position of the ball centre relative to the socket centre, ``r = R_b^T p`` in the socket frame,
``g_n = r . e`` the axial gap (> 0: lifted off the seat) and ``r_t = r - g_n e`` the radial offset.

Penalty energy ``E(r)`` of the socket (k: k_pen, k_o: k_open, c_a: axial clearance up to the
retainer, c_r: radial clearance):

* axial: ``k g_n^2 / 2`` for g_n <= 0 (seated: compression), ``k_o g_n^2 / 2`` for
  0 < g_n <= c_a (open), ``k_o c_a g_n - k_o c_a^2 / 2 + k (g_n - c_a)^2 / 2`` beyond (retainer);
* radial: ``k |r_t|^2 / 2`` when c_r = 0 (no play), else ``k_o |r_t|^2 / 2 + k (|r_t| - c_r)_+^2 / 2``.

The contact force of the socket on the ball is ``-R_b dE/dr``; the normal force of the seat (or of the
retainer) is ``N = k |g_n|`` (seated) or ``k (g_n - c_a)`` (retainer), zero while open.
"""

from __future__ import annotations

import math

from numba import carray, njit

from ..rotations import ts_inv_into
from ._ball_joint_kernels import (
    ERR_NOT_FINITE,
    I_DISS,
    I_GAMMA,
    I_M,
    I_Q,
    I_SLIP,
    N_STATE,
    friction_return,
    relative_increment_into,
)
from ._mat3 import mm, mm_atbt, mm_bt, mtv, mv, skew_into
from ._stack import stack_buffer

#: State row of a seated joint: the tied joint's 15 values, then the contact status of the seat the
#: trial was answered with and the status the law gives at the trial (axial branch 0 open / 1 seated
#: / 2 on the retainer, + 3 if the ball touches the socket wall; they differ only in a held
#: iteration, :func:`seated_joint_element`), the axial gap g_n (m) and the radial gap |r_t| - c_r (m).
N_STATE_SEATED = N_STATE + 4
I_STATUS = N_STATE
I_TRUE_STATUS = N_STATE + 1
I_GAP = N_STATE + 2
I_RGAP = N_STATE + 3
#: Length of a seated joint's output row: the tied joint's 11, then the seat's axial force N (the
#: seat's or the retainer's, >= 0), the axial gap g_n (m), the axial status (1 seated, 0 open, 2 on
#: the retainer) and the wall contact (1 touching the socket wall).
N_OUT = 15
OPEN, SEATED, RETAINED = 0, 1, 2


@njit(cache=True)
def radial_gap(r, e, gn, c_r):
    """|r_t| - c_r (m): the ball's radial distance from the socket wall (< 0 inside its play)."""
    rho2 = 0.0
    for i in range(3):
        t = r[i] - gn * e[i]
        rho2 += t * t
    return math.sqrt(rho2) - c_r


#: A seated ball lifts off its seat only when its axial gap exceeds this many units of round-off of the
#: nodes' positions (:func:`seat_hold_gap`).
HOLD_ULPS = 8.0


@njit(cache=True)
def seat_hold_gap(xa, xb):
    """The axial gap (m) a seated ball must exceed to open its seat: HOLD_ULPS units of round-off of the
    larger of the two nodes' distances from the origin (at least 1 m)."""
    s = 1.0
    for x in (xa, xb):
        s = max(s, math.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]))
    return HOLD_ULPS * 2.220446049250313e-16 * s


@njit(cache=True)
def seat_status(r, e, c_r, c_a):
    """Contact status of the seat at ``r`` (socket frame): axial branch + 3 x wall contact."""
    gn = r[0] * e[0] + r[1] * e[1] + r[2] * e[2]
    axial = SEATED if gn <= 0.0 else (OPEN if gn <= c_a else RETAINED)
    wall = 0
    if c_r > 0.0:
        rho2 = 0.0
        for i in range(3):
            t = r[i] - gn * e[i]
            rho2 += t * t
        wall = 1 if math.sqrt(rho2) > c_r else 0
    return axial + 3 * wall


@njit(cache=True)
def seat_law(r, e, k, k_o, c_r, c_a, status, g, Kl):
    """Gradient ``g`` (3) and Hessian ``Kl`` (3x3) of the socket's penalty energy at ``r`` (module
    docstring), socket frame, on the branches of ``status`` (:func:`seat_status`; a held iteration
    passes the previous status).  Returns (energy J, axial gap g_n m, axial force N (N: the seat's
    compression or the retainer's pull, negative when a held branch is stretched the other way),
    dN/dg_n (N/m))."""
    gn = r[0] * e[0] + r[1] * e[1] + r[2] * e[2]
    rt = carray(stack_buffer(3), (3,))
    for i in range(3):
        rt[i] = r[i] - gn * e[i]
    for i in range(3):
        g[i] = 0.0
        for j in range(3):
            Kl[i, j] = 0.0
    axial = status % 3
    if axial == SEATED:
        fa, ka, E, N, dN = k * gn, k, 0.5 * k * gn * gn, -k * gn, -k
    elif axial == OPEN:
        fa, ka, E, N, dN = k_o * gn, k_o, 0.5 * k_o * gn * gn, 0.0, 0.0
    else:
        over = gn - c_a
        fa = k_o * c_a + k * over
        ka, E, N, dN = k, k_o * c_a * gn - 0.5 * k_o * c_a * c_a + 0.5 * k * over * over, k * over, k
    for i in range(3):
        g[i] += fa * e[i]
        for j in range(3):
            Kl[i, j] += ka * e[i] * e[j]
    # radial
    rho = math.sqrt(rt[0] ** 2 + rt[1] ** 2 + rt[2] ** 2)
    kr = k if c_r == 0.0 else k_o
    for i in range(3):
        g[i] += kr * rt[i]
        for j in range(3):
            Kl[i, j] += kr * ((1.0 if i == j else 0.0) - e[i] * e[j])
    E += 0.5 * kr * rho * rho
    if status >= 3 and rho > 0.0:  # on the wall (held: the same law on either side of it)
        s = rho - c_r
        E += 0.5 * k * s * s
        for i in range(3):
            ti = rt[i] / rho
            g[i] += k * s * ti
            for j in range(3):
                tj = rt[j] / rho
                pij = (1.0 if i == j else 0.0) - e[i] * e[j]
                Kl[i, j] += k * ((s / rho) * (pij - ti * tj) + ti * tj)
    return E, gn, N, dN


@njit(cache=True)
def seated_joint_element(
    xa, xb, Ra, Rb, d0, e, k_pen, k_o, c_r, c_a, k_s, mu_s, mu_k, B, st, f, K, new, out, prev, has_prev, may_release
):
    """Forces ``f`` (12), tangent ``K`` (12x12), trial state ``new`` (:data:`N_STATE_SEATED`) and output
    ``out`` (:data:`N_OUT`) of one seated joint.  Friction (:func:`friction_return`) on the seat's
    normal force: limits mu_s B N and mu_k B N.  Returns (strain energy J, error code, held).

    A seat whose contact status (:func:`seat_status`) would release a contact that the previous
    iterate was answered with (``prev``, or the committed state in the first iteration) releases it
    only if ``may_release``: when every seat of the family has settled (:func:`seats_settled`);
    otherwise it is answered on the old branches (``held``; the family marks the response
    provisional, so Newton never accepts it).  Newton thus converges with the contacts it has, then
    the seats in tension open and Newton goes on: a contact search like Abaqus' severe
    discontinuity iterations.  A new contact (a seat closing, the ball reaching the wall or the
    retainer) is taken at once.
    Why: one Newton step from a stuck, pretensioned mast moves the rigid corner pieces by rotations
    whose second-order part (theta^2 r / 2 ~ 1 um) is ~1e5 N against the penalty; a seat opened on
    such a transient has no axial stiffness but k_open and the next iterate flies off.

    Internal forces (G = R_b dE/dr, the force of the ball on the socket; c = R_a d0; M = R_b m the
    friction moment): ``f_xa = G``, ``f_wa = c x G - M``, ``f_xb = -G``, ``f_wb = G x p + M``
    (the pair is moment-free about any point: the contact force acts through the ball centre).
    Tangent (A = R_b Kl R_b^T, h = dN/dg_n R_b e, dp = dx_a - dx_b - [c]x dw_a):

        dG   = A (dp + [p]x dw_b) - [G]x dw_b
        dM   = R_b C Ts^-T(theta) R_b^T (dw_b - dw_a) - [M]x dw_b
               + R_b n mu_k B h^T (dp + [p]x dw_b)                      (slip only)
    """
    # scratch on the stack (no allocation per joint); 3x3 products by ._mat3 (no BLAS call)
    buf = carray(stack_buffer(21), (7, 3))
    c, p, r, gl, m, n, th = buf[0], buf[1], buf[2], buf[3], buf[4], buf[5], buf[6]
    vec = carray(stack_buffer(9), (3, 3))
    G, M, Re = vec[0], vec[1], vec[2]
    mats = carray(stack_buffer(24 * 9), (24, 3, 3))
    Kl, C, Q, A, Afr, Ti, T1, T2, W = mats[0], mats[1], mats[2], mats[3], mats[4], mats[5], mats[6], mats[7], mats[8]
    Sc, Sp, SG, SM = mats[9], mats[10], mats[11], mats[12]
    dG_wa, dG_wb, ma_wa, ma_x, ma_wb, mb_x, mb_wa, mb_wb, M_wa, M_wb = (
        mats[13], mats[14], mats[15], mats[16], mats[17], mats[18], mats[19], mats[20], mats[21], mats[22]
    )  # fmt: skip
    T3 = mats[23]
    mv(Ra, d0, c)
    for i in range(3):
        p[i] = xa[i] + c[i] - xb[i]
    if not (math.isfinite(p.sum()) and math.isfinite(Ra.sum()) and math.isfinite(Rb.sum())):
        return 0.0, ERR_NOT_FINITE, False
    mtv(Rb, p, r)
    status = seat_status(r, e, c_r, c_a)
    ref = prev if has_prev else st
    answered = int(ref[I_STATUS])
    gn_now = r[0] * e[0] + r[1] * e[1] + r[2] * e[2]
    if answered % 3 == SEATED and status % 3 == OPEN and gn_now <= seat_hold_gap(xa, xb):
        status = SEATED + 3 * (status // 3)  # lifted off by round-off only: still seated
    # a contact that the last iterate was answered with (the committed state's in the first
    # iteration) is released only when ``may_release`` (every seat of the family has settled,
    # :func:`seats_settled`); until then the joint is answered on the old branches, provisionally.
    # A new contact is taken at once: a seat held open while the ball passes through it would let
    # the member float through its seat.
    rg_now = radial_gap(r, e, gn_now, c_r)
    held = False
    if status != answered and not may_release:
        held = (answered % 3 != OPEN and status % 3 != answered % 3) or (answered >= 3 and status < 3)
    branch = answered if held else status
    Ec, gn, N, dN = seat_law(r, e, k_pen, k_o, c_r, c_a, branch, gl, Kl)
    Nabs = abs(N)
    if N < 0.0:
        dN = -dN
    err = relative_increment_into(Ra, Rb, st, Q, th)
    slip, dgam, dD, Y = friction_return(st, th, k_s, mu_s * B * Nabs, mu_k * B * Nabs, prev, has_prev, m, C, n)
    mv(Rb, gl, G)
    mv(Rb, m, M)
    mm_bt(Kl, Rb, T1)
    mm(Rb, T1, A)  # A = Rb Kl Rb^T
    ts_inv_into(th, Ti)
    mm_atbt(Ti, Rb, T1)
    mm(C, T1, T2)
    mm(Rb, T2, Afr)  # Afr = Rb C Ts^-T Rb^T
    # d|N| through the contact: h (global, N/m per m of dp + [p]x dw_b); slip only
    for i in range(3):
        for j in range(3):
            W[i, j] = 0.0
    if slip == 1.0 and dN != 0.0:
        mv(Rb, e, Re)
        mv(Rb, n, T3[0])
        for i in range(3):
            for j in range(3):
                W[i, j] = T3[0, i] * mu_k * B * dN * Re[j]
    skew_into(c, Sc)
    skew_into(p, Sp)
    skew_into(G, SG)
    skew_into(M, SM)
    # blocks: derivative of G, of c x G, of G x p (w.r.t. xa, wa, xb, wb)
    mm(A, Sc, dG_wa)  # -(A Sc), negated below
    mm(A, Sp, dG_wb)
    for i in range(3):
        for j in range(3):
            dG_wa[i, j] = -dG_wa[i, j]
            dG_wb[i, j] = dG_wb[i, j] - SG[i, j]
    mm(SG, Sc, T1)
    mm(Sc, dG_wa, T2)
    mm(Sc, A, ma_x)
    mm(Sc, dG_wb, ma_wb)
    mm(Sp, A, T3)
    mm(T3, Sc, mb_wa)  # Sp A Sc
    mm(Sp, dG_wb, mb_wb)
    for i in range(3):
        for j in range(3):
            ma_wa[i, j] = T1[i, j] + T2[i, j]
            mb_x[i, j] = SG[i, j] - T3[i, j]
            mb_wa[i, j] = mb_wa[i, j] - T1[i, j]  # - SG Sc
            mb_wb[i, j] = -mb_wb[i, j]
    # friction moment: through theta, and (slip) through N
    mm(W, Sc, T1)
    mm(W, Sp, T2)
    for i in range(3):
        for j in range(3):
            M_wa[i, j] = -Afr[i, j] - T1[i, j]
            M_wb[i, j] = Afr[i, j] - SM[i, j] + T2[i, j]
    for i in range(12):
        f[i] = 0.0
        for j in range(12):
            K[i, j] = 0.0
    for i in range(3):
        f[i] = G[i]
        f[6 + i] = -G[i]
        f[3 + i] = (c[(i + 1) % 3] * G[(i + 2) % 3] - c[(i + 2) % 3] * G[(i + 1) % 3]) - M[i]
        f[9 + i] = (G[(i + 1) % 3] * p[(i + 2) % 3] - G[(i + 2) % 3] * p[(i + 1) % 3]) + M[i]
        for j in range(3):
            # translations of a and b: +-G
            K[i, j] = A[i, j]
            K[i, 3 + j] = dG_wa[i, j]
            K[i, 6 + j] = -A[i, j]
            K[i, 9 + j] = dG_wb[i, j]
            K[6 + i, j] = -A[i, j]
            K[6 + i, 3 + j] = -dG_wa[i, j]
            K[6 + i, 6 + j] = A[i, j]
            K[6 + i, 9 + j] = -dG_wb[i, j]
            # moment on a: c x G - M
            K[3 + i, j] = ma_x[i, j] - W[i, j]
            K[3 + i, 3 + j] = ma_wa[i, j] - M_wa[i, j]
            K[3 + i, 6 + j] = -ma_x[i, j] + W[i, j]
            K[3 + i, 9 + j] = ma_wb[i, j] - M_wb[i, j]
            # moment on b: G x p + M
            K[9 + i, j] = mb_x[i, j] + W[i, j]
            K[9 + i, 3 + j] = mb_wa[i, j] + M_wa[i, j]
            K[9 + i, 6 + j] = -mb_x[i, j] - W[i, j]
            K[9 + i, 9 + j] = mb_wb[i, j] + M_wb[i, j]
    for i in range(3):
        new[I_M + i] = m[i]
    new[I_STATUS] = branch
    new[I_TRUE_STATUS] = status
    new[I_GAP] = gn_now
    new[I_RGAP] = rg_now
    new[I_SLIP] = slip
    new[I_GAMMA] = st[I_GAMMA] + dgam
    new[I_DISS] = st[I_DISS] + dD
    for i in range(3):
        for j in range(3):
            new[I_Q + 3 * i + j] = Q[i, j]
    for i in range(3):
        out[i] = M[i]
        out[3 + i] = -G[i]  # the force on the socket's node as the tied joint reports it (f_b = F)
    out[6] = math.sqrt(G[0] ** 2 + G[1] ** 2 + G[2] ** 2)
    out[7] = Y
    out[8] = max(slip, 0.0)
    out[9] = new[I_GAMMA]
    out[10] = new[I_DISS]
    out[11] = Nabs
    out[12] = gn
    out[13] = status % 3
    out[14] = status // 3
    msq = m[0] ** 2 + m[1] ** 2 + m[2] ** 2
    return Ec + 0.5 * msq / k_s, err, held


@njit(cache=True)
def seats_settled(nodes, x, R, d0, e, c_r, state, prev, has_prev):
    """True when every seat's gaps (axial, and radial where there is play) moved by less than half
    their size since the previous iterate (the committed state in the first iteration), plus a floor
    of 1e-12 of the position (Newton's round-off): the iterates have settled, so seats in tension
    may open.  (A single seat's test is not enough: a seat released while the rest of the structure
    is still far from equilibrium frees its member, whose axial mode holds only k_open, and the next
    iterate sends it millimetres through the seat.)"""
    buf = carray(stack_buffer(9), (3, 3))
    c, p, r = buf[0], buf[1], buf[2]
    for el in range(nodes.shape[0]):
        a = nodes[el, 0]
        b = nodes[el, 1]
        ref = prev[el] if has_prev else state[el]
        mv(R[a], d0[el], c)
        for i in range(3):
            p[i] = x[a, i] + c[i] - x[b, i]
        mtv(R[b], p, r)
        gn = r[0] * e[el, 0] + r[1] * e[el, 1] + r[2] * e[el, 2]
        floor = 1e-12 * max(math.sqrt(x[b, 0] ** 2 + x[b, 1] ** 2 + x[b, 2] ** 2), 1.0)
        if abs(gn - ref[I_GAP]) > 0.5 * abs(gn) + floor:
            return False
        if c_r[el] > 0.0:
            rg = radial_gap(r, e[el], gn, c_r[el])
            if abs(rg - ref[I_RGAP]) > 0.5 * abs(rg) + floor:
                return False
    return True


@njit(cache=True)
def seated_joint_family_kernel(
    nodes,
    x,
    R,
    d0,
    e,
    k_pen,
    k_o,
    c_r,
    c_a,
    k_s,
    mu_s,
    mu_k,
    B,
    state,
    f,
    K,
    new,
    out,
    energy,
    err,
    held,
    prev,
    has_prev,
):
    """All seated joints of a family at once (see :func:`seated_joint_element`); ``held`` (n_el, bool)."""
    may_release = seats_settled(nodes, x, R, d0, e, c_r, state, prev, has_prev)
    for el in range(nodes.shape[0]):
        a = nodes[el, 0]
        b = nodes[el, 1]
        en, code, hold = seated_joint_element(
            x[a],
            x[b],
            R[a],
            R[b],
            d0[el],
            e[el],
            k_pen[el],
            k_o[el],
            c_r[el],
            c_a[el],
            k_s[el],
            mu_s[el],
            mu_k[el],
            B[el],
            state[el],
            f[el],
            K[el],
            new[el],
            out[el],
            prev[el if has_prev else 0],
            has_prev,
            may_release,
        )
        energy[el] = en
        err[el] = code
        held[el] = hold
