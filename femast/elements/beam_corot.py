"""3D two-node corotational Euler-Bernoulli beam (the analogue of Abaqus B33).

Formulation (Crisfield 1990; Battini & Pacoste 2002, CMAME 191:1755):

* nodal triads T_a = R_a E0, with R_a the nodal rotation and E0 = [e1 e2 e3] the
  initial element frame (e1 along the element, e2 from the up-vector);
* corotated frame Rr = [r1 r2 r3]: r1 along the current chord, r3 = r1 x q / |r1 x q|,
  r2 = r3 x r1, with q = (T_1 e_y + T_2 e_y) / 2 the mean of the nodal y axes;
* local deformations: ubar = l - l0 and the local rotations
  theta_a = log(Rr^T T_a), a = 1, 2 (exact for any rigid rotation: a rigidly rotated
  element has zero local deformation);
* local response: the linear cubic Euler-Bernoulli beam, N = EA ubar / l0 (ubar = l - l0 s with
  s the ``length_factor`` of a length error or thermal strain, 1 by default),
  torsion GJ / l0, bending 2EI / l0 [[2, 1], [1, 2]] about local y and z;
* global forces f = B^T f_l and the consistent tangent K = df/dd with respect to
  nodal translations and spatial spins (d = [dx1, dw1, dx2, dw2]), including every
  geometric term (chord, frame, and the Ts^-1 / K_h terms of the local rotations).

The tangent with spin variables is not symmetric away from equilibrium; it is the
exact derivative, which gives quadratic Newton convergence.  The derivation is in
docs/beam_element.md.
"""

from __future__ import annotations

import math

import numpy as np
from numba import carray, njit

from ..rotations import logm_so3_small_into, ts_inv_into, ts_inv_T_times_derivative_into
from ._stack import stack_buffer
from .base import ElementFamily, ElementResponse

# Columns of the per-element output "section_forces": end 1 then end 2, local axes.
SECTION_FORCE_NAMES = ("N", "Vy", "Vz", "T", "My", "Mz")


# ---------------------------------------------------------------------------------------------
# The kernel.  Every quantity of the element depends on the nodal translations only through the
# chord d = x2 - x1, so its Jacobians are taken with respect to the 9 independent variations
# [dd, dw1, dw2] (columns 0:3, 3:6, 6:9) and expanded to the 12 element DOFs at the end
# (d/dx1 = -d/dd, d/dx2 = d/dd).  The tangent is assembled from 3x3 blocks in the global frame
# (docs/beam_element.md, "The tangent in 3x3 blocks"): the spin of the corotated frame is a full
# 3x3 block in the dd columns and of rank one (about e1) in the spin columns, and the chain
# Ti^T (local stiffness) Ti + K_h Ti of the local rotations is collapsed into four 3x3 matrices
# before it meets the frame's Jacobian (~1000 instead of ~1800 multiply-adds per element,
# the tangent 1.5x faster, equal to the chain rule on 3x9 Jacobians to 2e-17 of max |K|).  Plain loops with fixed trip counts over scratch arrays on the
# stack: no allocation per element.  What is the same for both ends is written once, in a loop
# over the end a = 0, 1 with the end's arrays stacked (T[a], th[a], ...): numba's compile time
# grows with the size of the kernel's body (23 % fewer IR statements and about 25 % less
# compile time than with each end written out and the rotation helpers inlined twice, bit for bit
# the same results, as fast).

# local stiffness rows r = torsion, bending y, bending z: m_a[r] = k_r (C_SELF[r] th_a[r] +
# C_OTHER[r] th_b[r]), b the other end (torsion GJ/l0 [[1, -1], [-1, 1]], bending 2EI/l0 [[2, 1], [1, 2]])
_C_SELF = np.array([1.0, 2.0, 2.0])
_C_OTHER = np.array([-1.0, 1.0, 1.0])
_END_SIGN = np.array([-1.0, 1.0])  # section moment at end a = sign * m_a (acting on the section)


@njit(cache=True, error_model="numpy")
def beam_family_kernel(nodes, x, R, E0s, l0s, EAs, GJs, EIys, EIzs, length_factor, fs, Ks, sfs, energy):
    """Internal forces ``fs`` (n, 12), tangents ``Ks`` (n, 12, 12), section forces ``sfs``
    (n, 2, 6) and strain energies ``energy`` (J) of all the corotational beams of a family.

    ``length_factor`` (dimensionless, per element): the axially stress-free length is
    ``l0 * factor`` (a length error and a thermal strain, femast/model/thermal.py): ubar = l - l0 factor,
    N = EA ubar / l0 (strain on l0, so dN/dl = EA / l0 is unchanged); bending and torsion keep l0.

    One loop over the elements with the element's work written out in its body (not a call)
    and every scratch array on the stack (:mod:`._stack`): the compiler then keeps values in
    registers (1.6x faster than a per-element function with heap scratch)."""
    T = carray(stack_buffer(18), (2, 3, 3))  # nodal triads T_a = R_a E0
    Rr = carray(stack_buffer(9), (3, 3))  # corotated frame [e1 e2 e3]
    A = carray(stack_buffer(9), (3, 3))
    Ti = carray(stack_buffer(18), (2, 3, 3))  # Ts^-1(theta_a)
    Kh = carray(stack_buffer(9), (3, 3))
    th = carray(stack_buffer(6), (2, 3))  # local rotations theta_a
    m = carray(stack_buffer(6), (2, 3))  # local end moments m_a
    mt = carray(stack_buffer(6), (2, 3))  # Ti_a^T m_a
    qe = carray(stack_buffer(6), (2, 3))  # q_a x e3
    q = carray(stack_buffer(3), (3,))
    kr = carray(stack_buffer(3), (3,))  # GJ / l0, 2 EIy / l0, 2 EIz / l0
    Wd = carray(stack_buffer(9), (3, 3))  # frame spin per dd
    ga = carray(stack_buffer(6), (2, 3))  # frame spin about e1 per dw_a
    V = carray(stack_buffer(18), (2, 3, 3))  # Ti_a Rr^T
    P = carray(stack_buffer(9), (3, 3))
    Gm = carray(stack_buffer(36), (2, 2, 3, 3))
    Sg = carray(stack_buffer(18), (2, 3, 3))
    Lm = carray(stack_buffer(9), (3, 3))
    Y = carray(stack_buffer(9), (3, 3))
    JM = carray(stack_buffer(27), (3, 9))
    Jq = carray(stack_buffer(18), (2, 9))
    Jfx2 = carray(stack_buffer(27), (3, 9))
    Jal = carray(stack_buffer(9), (9,))
    Jc = carray(stack_buffer(9), (9,))
    fx = carray(stack_buffer(3), (3,))
    fl = carray(stack_buffer(3), (3,))
    fa = carray(stack_buffer(3), (3,))
    fb = carray(stack_buffer(3), (3,))
    for e in range(nodes.shape[0]):
        E0 = E0s[e]
        l0 = l0s[e]
        EA = EAs[e]
        f = fs[e]
        K = Ks[e]
        sf = sfs[e]
        # nodal triads T_a = R_a E0
        for a in range(2):
            Ra = R[nodes[e, a]]
            for i in range(3):
                for j in range(3):
                    s = 0.0
                    for k in range(3):
                        s += Ra[i, k] * E0[k, j]
                    T[a, i, j] = s
        # corotated frame Rr = [e1 e2 e3]
        x1 = x[nodes[e, 0]]
        x2 = x[nodes[e, 1]]
        ll = 0.0
        for i in range(3):
            d = x2[i] - x1[i]
            Rr[i, 0] = d
            ll += d * d
        l = math.sqrt(ll)
        for i in range(3):
            Rr[i, 0] = Rr[i, 0] / l
            q[i] = 0.5 * (T[0, i, 1] + T[1, i, 1])
        c0 = Rr[1, 0] * q[2] - Rr[2, 0] * q[1]
        c1 = Rr[2, 0] * q[0] - Rr[0, 0] * q[2]
        c2 = Rr[0, 0] * q[1] - Rr[1, 0] * q[0]
        n3 = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
        Rr[0, 2] = c0 / n3
        Rr[1, 2] = c1 / n3
        Rr[2, 2] = c2 / n3
        Rr[0, 1] = Rr[1, 2] * Rr[2, 0] - Rr[2, 2] * Rr[1, 0]
        Rr[1, 1] = Rr[2, 2] * Rr[0, 0] - Rr[0, 2] * Rr[2, 0]
        Rr[2, 1] = Rr[0, 2] * Rr[1, 0] - Rr[1, 2] * Rr[0, 0]
        # per end: local rotation theta_a = log(Rr^T T_a), Ts^-1(theta_a), qe_a = q_a x e3 (q_a = T_a[:, 1])
        for a in range(2):
            for i in range(3):
                for j in range(3):
                    A[i, j] = Rr[0, i] * T[a, 0, j] + Rr[1, i] * T[a, 1, j] + Rr[2, i] * T[a, 2, j]
            logm_so3_small_into(A, th[a])
            ts_inv_into(th[a], Ti[a])
            qe[a, 0] = T[a, 1, 1] * Rr[2, 2] - T[a, 2, 1] * Rr[1, 2]
            qe[a, 1] = T[a, 2, 1] * Rr[0, 2] - T[a, 0, 1] * Rr[2, 2]
            qe[a, 2] = T[a, 0, 1] * Rr[1, 2] - T[a, 1, 1] * Rr[0, 2]
        q1c = q[0] * Rr[0, 0] + q[1] * Rr[1, 0] + q[2] * Rr[2, 0]
        q2c = q[0] * Rr[0, 1] + q[1] * Rr[1, 1] + q[2] * Rr[2, 1]

        # local response (7 dofs: ubar, theta1, theta2)
        lf = l0 * length_factor[e]
        ubar = (l * l - lf * lf) / (l + lf)
        N = EA * ubar / l0
        kr[0] = GJs[e] / l0
        kr[1] = 2.0 * EIys[e] / l0
        kr[2] = 2.0 * EIzs[e] / l0
        for a in range(2):
            for r in range(3):
                m[a, r] = kr[r] * (_C_SELF[r] * th[a, r] + _C_OTHER[r] * th[1 - a, r])
        for a in range(2):
            for i in range(3):
                mt[a, i] = Ti[a, 0, i] * m[a, 0] + Ti[a, 1, i] * m[a, 1] + Ti[a, 2, i] * m[a, 2]
        M0 = mt[0, 0] + mt[1, 0]
        M1 = mt[0, 1] + mt[1, 1]
        M2 = mt[0, 2] + mt[1, 2]
        alpha = M1 + M0 * q1c / q2c
        c = M0 / (2.0 * q2c)
        for i in range(3):
            FDi = (-alpha * Rr[i, 2] + M2 * Rr[i, 1]) / l
            fx2 = N * Rr[i, 0] - FDi
            f[i] = -fx2
            f[6 + i] = fx2
            for a in range(2):
                f[3 + 6 * a + i] = Rr[i, 0] * mt[a, 0] + Rr[i, 1] * mt[a, 1] + Rr[i, 2] * mt[a, 2] - c * qe[a, i]

        # ---- consistent tangent, in 3x3 blocks of the global frame; columns [dd, dw1, dw2] ----
        # spin of the corotated frame Wr dv (Wr = Rr G): the 3x3 Wd in the dd columns, the rank-one
        # e1 g_a^T in those of w_a (g_a = qe_a / (2 q2c))
        il = 1.0 / l  # reciprocals: a division costs several multiplications' throughput
        iq = 1.0 / q2c
        r12 = q1c * iq
        for k in range(3):
            g1k = -Rr[k, 2] * il
            g2k = Rr[k, 1] * il
            g0k = r12 * g1k
            for i in range(3):
                Wd[i, k] = Rr[i, 0] * g0k + Rr[i, 1] * g1k + Rr[i, 2] * g2k
            for a in range(2):
                ga[a, k] = 0.5 * iq * qe[a, k]
        # local rotations: d theta_a = V_a (dw_a - Wr dv), V_a = Ti_a Rr^T
        for a in range(2):
            for i in range(3):
                for j in range(3):
                    V[a, i, j] = Ti[a, i, 0] * Rr[j, 0] + Ti[a, i, 1] * Rr[j, 1] + Ti[a, i, 2] * Rr[j, 2]
        # Rr d mt_a = Gm[a, a] (dw_a - Wr dv) + Gm[a, b] (dw_b - Wr dv), b the other end, with
        # Gm[a, a] = (V_a^T Ds + Rr K_h(theta_a, m_a)) V_a and Gm[a, b] = V_a^T Do V_b (Ds, Do: the
        # diagonal matrices kr C_SELF, kr C_OTHER of the local stiffness); Gm[b, a] = Gm[a, b]^T
        for a in range(2):
            ts_inv_T_times_derivative_into(th[a], m[a], Kh)
            for i in range(3):
                for k in range(3):
                    P[i, k] = (
                        V[a, k, i] * kr[k] * _C_SELF[k]
                        + Rr[i, 0] * Kh[0, k]
                        + Rr[i, 1] * Kh[1, k]
                        + Rr[i, 2] * Kh[2, k]
                    )
            for i in range(3):
                for j in range(3):
                    Gm[a, a, i, j] = P[i, 0] * V[a, 0, j] + P[i, 1] * V[a, 1, j] + P[i, 2] * V[a, 2, j]
        for i in range(3):
            for j in range(3):
                s = 0.0
                for k in range(3):
                    s += V[0, k, i] * kr[k] * _C_OTHER[k] * V[1, k, j]
                Gm[0, 1, i, j] = s
                Gm[1, 0, j, i] = s
        # Sg_a = Gm[a, 0] + Gm[a, 1]: Rr d mt_a = -Sg_a Wr dv + Gm[a, 0] dw_1 + Gm[a, 1] dw_2
        for a in range(2):
            for i in range(3):
                for j in range(3):
                    Sg[a, i, j] = Gm[a, 0, i, j] + Gm[a, 1, i, j]
        # JM = d(mt_1 + mt_2) in local components (rows M0, M1, M2): Rr^T (Rr d mt_1 + Rr d mt_2)
        for r in range(3):
            for j in range(3):
                Lm[r, j] = (
                    Rr[0, r] * (Sg[0, 0, j] + Sg[1, 0, j])
                    + Rr[1, r] * (Sg[0, 1, j] + Sg[1, 1, j])
                    + Rr[2, r] * (Sg[0, 2, j] + Sg[1, 2, j])
                )
        for r in range(3):
            for k in range(3):
                JM[r, k] = -(Lm[r, 0] * Wd[0, k] + Lm[r, 1] * Wd[1, k] + Lm[r, 2] * Wd[2, k])
            l0r = Lm[r, 0] * Rr[0, 0] + Lm[r, 1] * Rr[1, 0] + Lm[r, 2] * Rr[2, 0]  # (Rr^T Sg e1)_r
            for b in range(2):
                for k in range(3):
                    JM[r, 3 + 3 * b + k] = (
                        -l0r * ga[b, k]
                        + Rr[0, r] * (Gm[0, b, 0, k] + Gm[1, b, 0, k])
                        + Rr[1, r] * (Gm[0, b, 1, k] + Gm[1, b, 1, k])
                        + Rr[2, r] * (Gm[0, b, 2, k] + Gm[1, b, 2, k])
                    )
        # J_q1c, J_q2c: q . (Wr_j x e_b) = (e_b x q) . Wr_j in the dd columns, (q_a x e_b) / 2 in those of w_a
        for b in range(2):
            u0 = Rr[1, b] * q[2] - Rr[2, b] * q[1]
            u1 = Rr[2, b] * q[0] - Rr[0, b] * q[2]
            u2 = Rr[0, b] * q[1] - Rr[1, b] * q[0]
            for k in range(3):
                Jq[b, k] = u0 * Wd[0, k] + u1 * Wd[1, k] + u2 * Wd[2, k]
            for a in range(2):
                o = 3 + 3 * a
                Jq[b, o + 0] = 0.5 * (T[a, 1, 1] * Rr[2, b] - T[a, 2, 1] * Rr[1, b])
                Jq[b, o + 1] = 0.5 * (T[a, 2, 1] * Rr[0, b] - T[a, 0, 1] * Rr[2, b])
                Jq[b, o + 2] = 0.5 * (T[a, 0, 1] * Rr[1, b] - T[a, 1, 1] * Rr[0, b])
        a0 = M0 * iq
        a1 = a0 * r12
        h = 0.5 * iq
        h1 = h * a0
        for j in range(9):
            Jal[j] = JM[1, j] + r12 * JM[0, j] + a0 * Jq[0, j] - a1 * Jq[1, j]
            Jc[j] = h * JM[0, j] - h1 * Jq[1, j]
        # forces at node 2: fx2 = N e1 - FD, FD = (-alpha e3 + M2 e2) / l;
        # d fx2 = Wr dv x fx2 + (e3 dalpha - e2 dM2) / l + (kN e1 + FD / l) e1^T dd
        kN = EA / l0
        for i in range(3):
            FDi = (-alpha * Rr[i, 2] + M2 * Rr[i, 1]) * il
            fx[i] = N * Rr[i, 0] - FDi
            fl[i] = Rr[i, 0] * kN + FDi * il
            fa[i] = Rr[i, 2] * il  # e3 / l and e2 / l
            fb[i] = Rr[i, 1] * il
        # e1 x fx2 (the spin columns' Wr_j x fx2 = g_j e1 x fx2)
        c0 = Rr[1, 0] * fx[2] - Rr[2, 0] * fx[1]
        c1 = Rr[2, 0] * fx[0] - Rr[0, 0] * fx[2]
        c2 = Rr[0, 0] * fx[1] - Rr[1, 0] * fx[0]
        for k in range(3):
            w0 = Wd[0, k]
            w1 = Wd[1, k]
            w2 = Wd[2, k]
            x0 = w1 * fx[2] - w2 * fx[1]
            x1_ = w2 * fx[0] - w0 * fx[2]
            x2_ = w0 * fx[1] - w1 * fx[0]
            Jfx2[0, k] = x0 + (fa[0] * Jal[k] - fb[0] * JM[2, k]) + fl[0] * Rr[k, 0]
            Jfx2[1, k] = x1_ + (fa[1] * Jal[k] - fb[1] * JM[2, k]) + fl[1] * Rr[k, 0]
            Jfx2[2, k] = x2_ + (fa[2] * Jal[k] - fb[2] * JM[2, k]) + fl[2] * Rr[k, 0]
            for a in range(2):
                j = 3 + 3 * a + k
                g = ga[a, k]
                Jfx2[0, j] = c0 * g + (fa[0] * Jal[j] - fb[0] * JM[2, j])
                Jfx2[1, j] = c1 * g + (fa[1] * Jal[j] - fb[1] * JM[2, j])
                Jfx2[2, j] = c2 * g + (fa[2] * Jal[j] - fb[2] * JM[2, j])
        for i in range(3):
            for k in range(3):
                a_ = Jfx2[i, k]
                b_ = Jfx2[i, 3 + k]
                g_ = Jfx2[i, 6 + k]
                K[i, k] = a_
                K[i, 3 + k] = -b_
                K[i, 6 + k] = -a_
                K[i, 9 + k] = -g_
                K[6 + i, k] = -a_
                K[6 + i, 3 + k] = b_
                K[6 + i, 6 + k] = a_
                K[6 + i, 9 + k] = g_
        # moments: fw_a = Rr mt_a - c (q_a x e3):
        # d fw_a = Y_a Wr dv + Gm[a, 0] dw_1 + Gm[a, 1] dw_2 - qe_a dc - c (q_a e3^T - (e3 . q_a) I) dw_a,
        # Y_a = -skew(Rr mt_a) - c (q_a . e3) I + c e3 q_a^T - Sg_a (from d(Rr) mt_a = Wr dv x Rr mt_a
        # and c q_a x (Wr dv x e3), expanded)
        for a in range(2):
            v0 = Rr[0, 0] * mt[a, 0] + Rr[0, 1] * mt[a, 1] + Rr[0, 2] * mt[a, 2]
            v1 = Rr[1, 0] * mt[a, 0] + Rr[1, 1] * mt[a, 1] + Rr[1, 2] * mt[a, 2]
            v2 = Rr[2, 0] * mt[a, 0] + Rr[2, 1] * mt[a, 1] + Rr[2, 2] * mt[a, 2]
            e3q = T[a, 0, 1] * Rr[0, 2] + T[a, 1, 1] * Rr[1, 2] + T[a, 2, 1] * Rr[2, 2]
            for i in range(3):
                for j in range(3):
                    Y[i, j] = c * Rr[i, 2] * T[a, j, 1] - Sg[a, i, j]
                Y[i, i] -= c * e3q
            Y[0, 1] += v2
            Y[0, 2] -= v1
            Y[1, 0] -= v2
            Y[1, 2] += v0
            Y[2, 0] += v1
            Y[2, 1] -= v0
            row = 3 + 6 * a
            for i in range(3):
                y0 = Y[i, 0]
                y1 = Y[i, 1]
                y2 = Y[i, 2]
                # Y_a e1: the spin columns' Y_a Wr_j = g_j Y_a e1
                ye = y0 * Rr[0, 0] + y1 * Rr[1, 0] + y2 * Rr[2, 0]
                qi = qe[a, i]
                for k in range(3):
                    v = y0 * Wd[0, k] + y1 * Wd[1, k] + y2 * Wd[2, k] - qi * Jc[k]
                    K[row + i, k] = -v
                    K[row + i, 6 + k] = v
                    for b in range(2):
                        j = 3 + 3 * b + k
                        K[row + i, j + 3 * b] = ye * ga[b, k] + Gm[a, b, i, k] - qi * Jc[j]
                K[row + i, 3 + 6 * a + i] += c * e3q
                for k in range(3):
                    K[row + i, 3 + 6 * a + k] -= c * T[a, i, 1] * Rr[k, 2]

        # section forces, local axes: N (tension +), shear from end-moment equilibrium,
        # torsion and bending moments as acting on the beam section at each end
        Vy = (m[0, 2] + m[1, 2]) / l0
        Vz = -(m[0, 1] + m[1, 1]) / l0
        w = N * ubar
        for a in range(2):
            sf[a, 0] = N
            sf[a, 1] = Vy
            sf[a, 2] = Vz
            for r in range(3):
                sf[a, 3 + r] = _END_SIGN[a] * m[a, r]
                w += m[a, r] * th[a, r]
        energy[e] = 0.5 * w


def element_frame(x1, x2, up):
    """Initial element frame E0 = [e1 e2 e3] (columns): e1 along the element, e2 the
    up-vector made orthogonal to e1, e3 = e1 x e2.  Returns None if ``up`` is parallel
    to the element."""
    # plain floats: this runs once per element when a model is built (numpy's per-call
    # overhead on 3-vectors was 0.2 ms per element)
    a0, a1, a2 = (float(v) for v in x1)
    b0, b1, b2 = (float(v) for v in x2)
    u0, u1, u2 = (float(v) for v in up)
    e0, e1_, e2_ = b0 - a0, b1 - a1, b2 - a2
    n = math.sqrt(e0 * e0 + e1_ * e1_ + e2_ * e2_)
    e0, e1_, e2_ = e0 / n, e1_ / n, e2_ / n
    p = u0 * e0 + u1 * e1_ + u2 * e2_
    y0, y1, y2 = u0 - p * e0, u1 - p * e1_, u2 - p * e2_
    ny = math.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
    if ny < 1e-8 * max(math.sqrt(u0 * u0 + u1 * u1 + u2 * u2), 1e-300):
        return None
    y0, y1, y2 = y0 / ny, y1 / ny, y2 / ny
    return np.array([[e0, y0, e1_ * y2 - e2_ * y1], [e1_, y1, e2_ * y0 - e0 * y2], [e2_, y2, e0 * y1 - e1_ * y0]])


def element_frames(x1, x2, up):
    """:func:`element_frame` of many elements at once: (n, 3) ends and up-vectors -> (E0 (n, 3, 3),
    a bool (n,) of the elements whose up-vector is parallel to them).  The same operations in the
    same order on each element, so each frame is bit for bit :func:`element_frame`'s."""
    a0, a1, a2 = (np.ascontiguousarray(x1[:, k], dtype=float) for k in range(3))
    b0, b1, b2 = (np.ascontiguousarray(x2[:, k], dtype=float) for k in range(3))
    up = np.broadcast_to(np.asarray(up, dtype=float), np.shape(x1))
    u0, u1, u2 = (np.ascontiguousarray(up[:, k]) for k in range(3))
    e0, e1_, e2_ = b0 - a0, b1 - a1, b2 - a2
    n = np.sqrt(e0 * e0 + e1_ * e1_ + e2_ * e2_)
    e0, e1_, e2_ = e0 / n, e1_ / n, e2_ / n
    p = u0 * e0 + u1 * e1_ + u2 * e2_
    y0, y1, y2 = u0 - p * e0, u1 - p * e1_, u2 - p * e2_
    ny = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
    parallel = ny < 1e-8 * np.maximum(np.sqrt(u0 * u0 + u1 * u1 + u2 * u2), 1e-300)
    with np.errstate(invalid="ignore", divide="ignore"):
        y0, y1, y2 = y0 / ny, y1 / ny, y2 / ny
    E0 = np.empty((len(a0), 3, 3))
    E0[:, 0, 0], E0[:, 0, 1], E0[:, 0, 2] = e0, y0, e1_ * y2 - e2_ * y1
    E0[:, 1, 0], E0[:, 1, 1], E0[:, 1, 2] = e1_, y1, e2_ * y0 - e0 * y2
    E0[:, 2, 0], E0[:, 2, 1], E0[:, 2, 2] = e2_, y2, e0 * y1 - e1_ * y0
    return E0, parallel


class BeamFamily(ElementFamily):
    """A batch of corotational B33-like beams.

    Parameters are arrays over elements: ``E0`` (n,3,3) initial frames, ``l0`` (m),
    ``EA`` (N), ``GJ`` (N m^2), ``EIy``, ``EIz`` (N m^2), ``section_names``.
    ``Iz`` resists bending in the plane of the element axis and its up-vector.
    """

    name = "beam"
    self_equilibrated = True  # internal nodal forces: zero resultant force and moment (checked by the analysis)
    active_dofs = (0, 1, 2, 3, 4, 5)
    n_state = 0
    path_independent = True
    symmetric = False

    def __init__(self, nodes, E0, l0, EA, GJ, EIy, EIz, labels=None, name="beam"):
        self.name = name
        self.nodes = np.ascontiguousarray(nodes, dtype=np.int64)
        self.E0 = np.ascontiguousarray(E0, dtype=float)
        self.l0 = np.ascontiguousarray(l0, dtype=float)
        self.EA = np.ascontiguousarray(EA, dtype=float)
        self.GJ = np.ascontiguousarray(GJ, dtype=float)
        self.EIy = np.ascontiguousarray(EIy, dtype=float)
        self.EIz = np.ascontiguousarray(EIz, dtype=float)
        self.length_factor = np.ones(len(self.nodes))  # stress-free length / l0 (femast/model/thermal.py)
        self.labels = np.arange(1, len(self.nodes) + 1) if labels is None else np.asarray(labels)

    def evaluate(self, x, R, state, ctx=None):
        n = self.n_elements
        f = np.empty((n, 12))  # the kernel writes every entry
        K = np.empty((n, 12, 12))
        sf = np.empty((n, 2, 6))
        energy = np.empty(n)
        beam_family_kernel(
            self.nodes,
            np.ascontiguousarray(x),
            np.ascontiguousarray(R),
            self.E0,
            self.l0,
            self.EA,
            self.GJ,
            self.EIy,
            self.EIz,
            self.length_factor,
            f,
            K,
            sf,
            energy,
        )
        return ElementResponse(f=f, k=K, state=state, output={"section_forces": sf}, energy=energy)
