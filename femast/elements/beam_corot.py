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

from ..rotations import logm_so3_into, ts_inv_into, ts_inv_T_times_derivative_into
from ._stack import stack_buffer
from .base import ElementFamily, ElementResponse

# Columns of the per-element output "section_forces": end 1 then end 2, local axes.
SECTION_FORCE_NAMES = ("N", "Vy", "Vz", "T", "My", "Mz")


# ---------------------------------------------------------------------------------------------
# The kernel.  Every quantity of the element depends on the nodal translations only through the
# chord d = x2 - x1, so its Jacobians are taken with respect to the 9 independent variations
# [dd, dw1, dw2] (columns 0:3, 3:6, 6:9) and expanded to the 12 element DOFs at the end
# (d/dx1 = -d/dd, d/dx2 = d/dd).  Plain loops with fixed trip counts over scratch arrays on the
# stack: no allocation per element, few small functions to compile.


@njit(cache=True)
def beam_family_kernel(nodes, x, R, E0s, l0s, EAs, GJs, EIys, EIzs, length_factor, fs, Ks, sfs, energy):
    """Internal forces ``fs`` (n, 12), tangents ``Ks`` (n, 12, 12), section forces ``sfs``
    (n, 2, 6) and strain energies ``energy`` (J) of all the corotational beams of a family.

    ``length_factor`` (dimensionless, per element): the axially stress-free length is
    ``l0 * factor`` (a length error and a thermal strain, femast/model/thermal.py): ubar = l - l0 factor,
    N = EA ubar / l0 (strain on l0, so dN/dl = EA / l0 is unchanged); bending and torsion keep l0.

    One loop over the elements with the element's work written out in its body (not a call)
    and every scratch array on the stack (:mod:`._stack`): the compiler then keeps values in
    registers (issue 8: 1.6x faster than a per-element function with heap scratch)."""
    T1 = carray(stack_buffer(9), (3, 3))
    T2 = carray(stack_buffer(9), (3, 3))
    Rr = carray(stack_buffer(9), (3, 3))
    Ti1 = carray(stack_buffer(9), (3, 3))
    Ti2 = carray(stack_buffer(9), (3, 3))
    Kh1 = carray(stack_buffer(9), (3, 3))
    Kh2 = carray(stack_buffer(9), (3, 3))
    A = carray(stack_buffer(9), (3, 3))
    th1 = carray(stack_buffer(3), (3,))
    th2 = carray(stack_buffer(3), (3,))
    m1 = carray(stack_buffer(3), (3,))
    m2 = carray(stack_buffer(3), (3,))
    mt1 = carray(stack_buffer(3), (3,))
    mt2 = carray(stack_buffer(3), (3,))
    qe1 = carray(stack_buffer(3), (3,))
    qe2 = carray(stack_buffer(3), (3,))
    q = carray(stack_buffer(3), (3,))
    # 3x9 Jacobians with respect to [dd, dw1, dw2] and 9-vectors (rows of scalars)
    G = carray(stack_buffer(27), (3, 9))
    Wr = carray(stack_buffer(27), (3, 9))
    Je1 = carray(stack_buffer(27), (3, 9))
    Je2 = carray(stack_buffer(27), (3, 9))
    Je3 = carray(stack_buffer(27), (3, 9))
    Jth1 = carray(stack_buffer(27), (3, 9))
    Jth2 = carray(stack_buffer(27), (3, 9))
    Jm1 = carray(stack_buffer(27), (3, 9))
    Jm2 = carray(stack_buffer(27), (3, 9))
    Jmt1 = carray(stack_buffer(27), (3, 9))
    Jmt2 = carray(stack_buffer(27), (3, 9))
    Jfx2 = carray(stack_buffer(27), (3, 9))
    Jfw1 = carray(stack_buffer(27), (3, 9))
    Jfw2 = carray(stack_buffer(27), (3, 9))
    Jq1c = carray(stack_buffer(9), (9,))
    Jq2c = carray(stack_buffer(9), (9,))
    Jal = carray(stack_buffer(9), (9,))
    Jc = carray(stack_buffer(9), (9,))
    for e in range(nodes.shape[0]):
        x1 = x[nodes[e, 0]]
        x2 = x[nodes[e, 1]]
        R1 = R[nodes[e, 0]]
        R2 = R[nodes[e, 1]]
        E0 = E0s[e]
        l0 = l0s[e]
        EA = EAs[e]
        GJ = GJs[e]
        EIy = EIys[e]
        EIz = EIzs[e]
        f = fs[e]
        K = Ks[e]
        sf = sfs[e]
        # nodal triads T_a = R_a E0
        for i in range(3):
            for j in range(3):
                s1 = 0.0
                s2 = 0.0
                for k in range(3):
                    s1 += R1[i, k] * E0[k, j]
                    s2 += R2[i, k] * E0[k, j]
                T1[i, j] = s1
                T2[i, j] = s2
        # corotated frame Rr = [e1 e2 e3]
        d0 = x2[0] - x1[0]
        d1 = x2[1] - x1[1]
        d2 = x2[2] - x1[2]
        l = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        Rr[0, 0] = d0 / l
        Rr[1, 0] = d1 / l
        Rr[2, 0] = d2 / l
        for i in range(3):
            q[i] = 0.5 * (T1[i, 1] + T2[i, 1])
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
        # local rotations theta_a = log(Rr^T T_a)
        for a in range(2):
            Ta = T1 if a == 0 else T2
            for i in range(3):
                for j in range(3):
                    A[i, j] = Rr[0, i] * Ta[0, j] + Rr[1, i] * Ta[1, j] + Rr[2, i] * Ta[2, j]
            logm_so3_into(A, th1 if a == 0 else th2)
        q1c = q[0] * Rr[0, 0] + q[1] * Rr[1, 0] + q[2] * Rr[2, 0]
        q2c = q[0] * Rr[0, 1] + q[1] * Rr[1, 1] + q[2] * Rr[2, 1]

        # local response (7 dofs: ubar, theta1, theta2)
        lf = l0 * length_factor[e]
        ubar = (l * l - lf * lf) / (l + lf)
        N = EA * ubar / l0
        kt = GJ / l0
        ky = 2.0 * EIy / l0
        kz = 2.0 * EIz / l0
        m1[0] = kt * (th1[0] - th2[0])
        m1[1] = ky * (2.0 * th1[1] + th2[1])
        m1[2] = kz * (2.0 * th1[2] + th2[2])
        m2[0] = -m1[0]
        m2[1] = ky * (th1[1] + 2.0 * th2[1])
        m2[2] = kz * (th1[2] + 2.0 * th2[2])
        ts_inv_into(th1, Ti1)
        ts_inv_into(th2, Ti2)
        for i in range(3):
            mt1[i] = Ti1[0, i] * m1[0] + Ti1[1, i] * m1[1] + Ti1[2, i] * m1[2]
            mt2[i] = Ti2[0, i] * m2[0] + Ti2[1, i] * m2[1] + Ti2[2, i] * m2[2]
        M0 = mt1[0] + mt2[0]
        M1 = mt1[1] + mt2[1]
        M2 = mt1[2] + mt2[2]
        alpha = M1 + M0 * q1c / q2c
        c = M0 / (2.0 * q2c)
        # qe_a = q_a x e3 (q_a = T_a[:, 1])
        for a in range(2):
            Ta = T1 if a == 0 else T2
            qe = qe1 if a == 0 else qe2
            qe[0] = Ta[1, 1] * Rr[2, 2] - Ta[2, 1] * Rr[1, 2]
            qe[1] = Ta[2, 1] * Rr[0, 2] - Ta[0, 1] * Rr[2, 2]
            qe[2] = Ta[0, 1] * Rr[1, 2] - Ta[1, 1] * Rr[0, 2]
        for i in range(3):
            FDi = (-alpha * Rr[i, 2] + M2 * Rr[i, 1]) / l
            fx2 = N * Rr[i, 0] - FDi
            f[i] = -fx2
            f[6 + i] = fx2
            f[3 + i] = Rr[i, 0] * mt1[0] + Rr[i, 1] * mt1[1] + Rr[i, 2] * mt1[2] - c * qe1[i]
            f[9 + i] = Rr[i, 0] * mt2[0] + Rr[i, 1] * mt2[1] + Rr[i, 2] * mt2[2] - c * qe2[i]

        # ---- consistent tangent: chain rule with 3x9 Jacobians ----
        # spin of the corotated frame w_r = Rr G dd
        for k in range(3):
            G[1, k] = -Rr[k, 2] / l
            G[2, k] = Rr[k, 1] / l
            G[0, k] = q1c * G[1, k] / q2c
            G[0, 3 + k] = 0.5 * qe1[k] / q2c
            G[0, 6 + k] = 0.5 * qe2[k] / q2c
        # G[1:3] vanish in the spin columns, so there Wr[:, j] = e1 G[0, j]
        for i in range(3):
            for j in range(3):
                Wr[i, j] = Rr[i, 0] * G[0, j] + Rr[i, 1] * G[1, j] + Rr[i, 2] * G[2, j]
            for j in range(3, 9):
                Wr[i, j] = Rr[i, 0] * G[0, j]
        # J_ea = -skew(e_a) Wr: columns Wr[:, j] x e_a; in the spin columns G[0, j] (e1 x e_a)
        for a in range(3):
            Je = Je1 if a == 0 else (Je2 if a == 1 else Je3)
            for j in range(3):
                Je[0, j] = Wr[1, j] * Rr[2, a] - Wr[2, j] * Rr[1, a]
                Je[1, j] = Wr[2, j] * Rr[0, a] - Wr[0, j] * Rr[2, a]
                Je[2, j] = Wr[0, j] * Rr[1, a] - Wr[1, j] * Rr[0, a]
        for j in range(3, 9):
            for i in range(3):
                Je1[i, j] = 0.0
                Je2[i, j] = G[0, j] * Rr[i, 2]
                Je3[i, j] = -G[0, j] * Rr[i, 1]
        # J_q = (J_q1 + J_q2)/2, J_qa = -skew(q_a) in the columns of w_a;
        # J_q1c = e1^T J_q + q^T J_e1, J_q2c = e2^T J_q + q^T J_e2 (q . e3 = 0 in the spin columns)
        for j in range(3):
            Jq1c[j] = q[0] * Je1[0, j] + q[1] * Je1[1, j] + q[2] * Je1[2, j]
            Jq2c[j] = q[0] * Je2[0, j] + q[1] * Je2[1, j] + q[2] * Je2[2, j]
        for a in range(2):
            Ta = T1 if a == 0 else T2
            o = 3 + 3 * a
            # e^T (-skew(q_a)) / 2 = (q_a x e) / 2
            for b in range(2):
                Jv = Jq1c if b == 0 else Jq2c
                Jv[o + 0] = 0.5 * (Ta[1, 1] * Rr[2, b] - Ta[2, 1] * Rr[1, b])
                Jv[o + 1] = 0.5 * (Ta[2, 1] * Rr[0, b] - Ta[0, 1] * Rr[2, b])
                Jv[o + 2] = 0.5 * (Ta[0, 1] * Rr[1, b] - Ta[1, 1] * Rr[0, b])
        # local rotations: J_tha = Ti_a (-G + [Rr^T in the columns of w_a])
        for i in range(3):
            for j in range(3):
                Jth1[i, j] = -(Ti1[i, 0] * G[0, j] + Ti1[i, 1] * G[1, j] + Ti1[i, 2] * G[2, j])
                Jth2[i, j] = -(Ti2[i, 0] * G[0, j] + Ti2[i, 1] * G[1, j] + Ti2[i, 2] * G[2, j])
            for j in range(3, 9):
                Jth1[i, j] = -Ti1[i, 0] * G[0, j]
                Jth2[i, j] = -Ti2[i, 0] * G[0, j]
            for k in range(3):
                Jth1[i, 3 + k] += Ti1[i, 0] * Rr[k, 0] + Ti1[i, 1] * Rr[k, 1] + Ti1[i, 2] * Rr[k, 2]
                Jth2[i, 6 + k] += Ti2[i, 0] * Rr[k, 0] + Ti2[i, 1] * Rr[k, 1] + Ti2[i, 2] * Rr[k, 2]
        for j in range(9):
            Jm1[0, j] = kt * (Jth1[0, j] - Jth2[0, j])
            Jm2[0, j] = -Jm1[0, j]
            Jm1[1, j] = ky * (2.0 * Jth1[1, j] + Jth2[1, j])
            Jm2[1, j] = ky * (Jth1[1, j] + 2.0 * Jth2[1, j])
            Jm1[2, j] = kz * (2.0 * Jth1[2, j] + Jth2[2, j])
            Jm2[2, j] = kz * (Jth1[2, j] + 2.0 * Jth2[2, j])
        # J_mta = Ti_a^T J_ma + K_h(theta_a, m_a) J_tha
        ts_inv_T_times_derivative_into(th1, m1, Kh1)
        ts_inv_T_times_derivative_into(th2, m2, Kh2)
        for i in range(3):
            for j in range(9):
                Jmt1[i, j] = (Ti1[0, i] * Jm1[0, j] + Ti1[1, i] * Jm1[1, j] + Ti1[2, i] * Jm1[2, j]
                              + Kh1[i, 0] * Jth1[0, j] + Kh1[i, 1] * Jth1[1, j] + Kh1[i, 2] * Jth1[2, j])
                Jmt2[i, j] = (Ti2[0, i] * Jm2[0, j] + Ti2[1, i] * Jm2[1, j] + Ti2[2, i] * Jm2[2, j]
                              + Kh2[i, 0] * Jth2[0, j] + Kh2[i, 1] * Jth2[1, j] + Kh2[i, 2] * Jth2[2, j])
        r12 = q1c / q2c
        for j in range(9):
            JM0 = Jmt1[0, j] + Jmt2[0, j]
            Jal[j] = Jmt1[1, j] + Jmt2[1, j] + r12 * JM0 + (M0 / q2c) * Jq1c[j] - (M0 * r12 / q2c) * Jq2c[j]
            Jc[j] = JM0 / (2.0 * q2c) - (M0 / (2.0 * q2c * q2c)) * Jq2c[j]
        # forces at node 2: fx2 = N e1 - FD, FD = (-alpha e3 + M2 e2) / l
        kN = EA / l0
        for i in range(3):
            FDi = (-alpha * Rr[i, 2] + M2 * Rr[i, 1]) / l
            for j in range(9):
                JFD = (-Rr[i, 2] * Jal[j] - alpha * Je3[i, j] + Rr[i, 1] * (Jmt1[2, j] + Jmt2[2, j])
                       + M2 * Je2[i, j]) / l
                Jfx2[i, j] = N * Je1[i, j] - JFD
            for k in range(3):  # J_l = [e1, 0, 0]
                Jfx2[i, k] += (Rr[i, 0] * kN + FDi / l) * Rr[k, 0]
        # moments: fw_a = Rr mt_a - c (q_a x e3)
        e3q1 = T1[0, 1] * Rr[0, 2] + T1[1, 1] * Rr[1, 2] + T1[2, 1] * Rr[2, 2]
        e3q2 = T2[0, 1] * Rr[0, 2] + T2[1, 1] * Rr[1, 2] + T2[2, 1] * Rr[2, 2]
        for a in range(2):
            Ta = T1 if a == 0 else T2
            Jmt = Jmt1 if a == 0 else Jmt2
            mt = mt1 if a == 0 else mt2
            qe = qe1 if a == 0 else qe2
            Jfw = Jfw1 if a == 0 else Jfw2
            qa0 = Ta[0, 1]
            qa1 = Ta[1, 1]
            qa2 = Ta[2, 1]
            for j in range(9):
                # - c q_a x J_e3[:, j]
                x0 = qa1 * Je3[2, j] - qa2 * Je3[1, j]
                x1_ = qa2 * Je3[0, j] - qa0 * Je3[2, j]
                x2_ = qa0 * Je3[1, j] - qa1 * Je3[0, j]
                for i in range(3):
                    Jfw[i, j] = (Rr[i, 0] * Jmt[0, j] + Rr[i, 1] * Jmt[1, j] + Rr[i, 2] * Jmt[2, j]
                                 + mt[0] * Je1[i, j] + mt[1] * Je2[i, j] + mt[2] * Je3[i, j] - qe[i] * Jc[j])
                Jfw[0, j] -= c * x0
                Jfw[1, j] -= c * x1_
                Jfw[2, j] -= c * x2_
            # + c skew(e3) J_qa, J_qa = -skew(q_a) in the columns of w_a:
            # -c skew(e3) skew(q_a) = -c (q_a e3^T - (e3 . q_a) I)
            o = 3 + 3 * a
            for i in range(3):
                qai = Ta[i, 1]
                for k in range(3):
                    Jfw[i, o + k] -= c * qai * Rr[k, 2]
                Jfw[i, o + i] += c * (e3q1 if a == 0 else e3q2)
        # expand to the 12 DOFs: rows [-fx2, fw1, fx2, fw2], columns [-dd, dw1, dd, dw2]
        for i in range(3):
            for k in range(3):
                a = Jfx2[i, k]
                b = Jfx2[i, 3 + k]
                g = Jfx2[i, 6 + k]
                K[i, k] = a
                K[i, 3 + k] = -b
                K[i, 6 + k] = -a
                K[i, 9 + k] = -g
                K[6 + i, k] = -a
                K[6 + i, 3 + k] = b
                K[6 + i, 6 + k] = a
                K[6 + i, 9 + k] = g
                a = Jfw1[i, k]
                K[3 + i, k] = -a
                K[3 + i, 3 + k] = Jfw1[i, 3 + k]
                K[3 + i, 6 + k] = a
                K[3 + i, 9 + k] = Jfw1[i, 6 + k]
                a = Jfw2[i, k]
                K[9 + i, k] = -a
                K[9 + i, 3 + k] = Jfw2[i, 3 + k]
                K[9 + i, 6 + k] = a
                K[9 + i, 9 + k] = Jfw2[i, 6 + k]

        # section forces, local axes: N (tension +), shear from end-moment equilibrium,
        # torsion and bending moments as acting on the beam section at each end
        Vy = (m1[2] + m2[2]) / l0
        Vz = -(m1[1] + m2[1]) / l0
        sf[0, 0] = N
        sf[0, 1] = Vy
        sf[0, 2] = Vz
        sf[0, 3] = -m1[0]
        sf[0, 4] = -m1[1]
        sf[0, 5] = -m1[2]
        sf[1, 0] = N
        sf[1, 1] = Vy
        sf[1, 2] = Vz
        sf[1, 3] = m2[0]
        sf[1, 4] = m2[1]
        sf[1, 5] = m2[2]
        energy[e] = 0.5 * (N * ubar + m1[0] * th1[0] + m1[1] * th1[1] + m1[2] * th1[2]
                      + m2[0] * th2[0] + m2[1] * th2[1] + m2[2] * th2[2])


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
    return np.array([[e0, y0, e1_ * y2 - e2_ * y1],
                     [e1_, y1, e2_ * y0 - e0 * y2],
                     [e2_, y2, e0 * y1 - e1_ * y0]])


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
    self_equilibrated = True   # internal nodal forces: zero resultant force and moment (issue 16 check)
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
        self.length_factor = np.ones(len(self.nodes))   # stress-free length / l0 (femast/model/thermal.py)
        self.labels = np.arange(1, len(self.nodes) + 1) if labels is None else np.asarray(labels)

    def evaluate(self, x, R, state, ctx=None):
        n = self.n_elements
        f = np.empty((n, 12))  # the kernel writes every entry
        K = np.empty((n, 12, 12))
        sf = np.empty((n, 2, 6))
        energy = np.empty(n)
        beam_family_kernel(self.nodes, np.ascontiguousarray(x), np.ascontiguousarray(R), self.E0, self.l0,
                           self.EA, self.GJ, self.EIy, self.EIz, self.length_factor, f, K, sf, energy)
        return ElementResponse(f=f, k=K, state=state, output={"section_forces": sf}, energy=energy)
