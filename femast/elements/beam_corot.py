"""3D two-node corotational Euler-Bernoulli beam (the analogue of Abaqus B33).

Formulation (Crisfield 1990; Battini & Pacoste 2002, CMAME 191:1755):

* nodal triads T_a = R_a E0, with R_a the nodal rotation and E0 = [e1 e2 e3] the
  initial element frame (e1 along the element, e2 from the up-vector);
* corotated frame Rr = [r1 r2 r3]: r1 along the current chord, r3 = r1 x q / |r1 x q|,
  r2 = r3 x r1, with q = (T_1 e_y + T_2 e_y) / 2 the mean of the nodal y axes;
* local deformations: ubar = l - l0 and the local rotations
  theta_a = log(Rr^T T_a), a = 1, 2 (exact for any rigid rotation: a rigidly rotated
  element has zero local deformation);
* local response: the linear cubic Euler-Bernoulli beam, N = EA ubar / l0,
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
from numba import njit

from ..rotations import logm_so3, skew, ts_inv, ts_inv_T_times_derivative
from .base import ElementFamily, ElementResponse

# Columns of the per-element output "section_forces": end 1 then end 2, local axes.
SECTION_FORCE_NAMES = ("N", "Vy", "Vz", "T", "My", "Mz")


# Small dense products as plain loops: numba's `@` calls BLAS, whose per-call overhead
# dominates for 3x3 and 3x12 operands.
@njit(cache=True)
def _mm(A, B):
    n, k = A.shape
    m = B.shape[1]
    C = np.zeros((n, m))
    for i in range(n):
        for p in range(k):
            a = A[i, p]
            if a != 0.0:
                for j in range(m):
                    C[i, j] += a * B[p, j]
    return C


@njit(cache=True)
def _mv(A, v):
    n, k = A.shape
    out = np.zeros(n)
    for i in range(n):
        for p in range(k):
            out[i] += A[i, p] * v[p]
    return out


@njit(cache=True)
def _vm(v, A):
    k, m = A.shape
    out = np.zeros(m)
    for p in range(k):
        if v[p] != 0.0:
            for j in range(m):
                out[j] += v[p] * A[p, j]
    return out


@njit(cache=True)
def _dot(a, b):
    s = 0.0
    for i in range(a.shape[0]):
        s += a[i] * b[i]
    return s


@njit(cache=True)
def _cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


@njit(cache=True)
def beam_element(x1, x2, R1, R2, E0, l0, EA, GJ, EIy, EIz, f, K, sf):
    """Internal force ``f`` (12), tangent ``K`` (12x12) and section forces ``sf`` (2x6)
    of one corotational beam.  Returns the strain energy (J)."""
    T1 = _mm(R1, E0)
    T2 = _mm(R2, E0)
    q1 = T1[:, 1].copy()
    q2 = T2[:, 1].copy()
    d = x2 - x1
    l = math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
    e1 = d / l
    q = 0.5 * (q1 + q2)
    e3 = _cross(e1, q)
    e3 /= math.sqrt(e3[0] ** 2 + e3[1] ** 2 + e3[2] ** 2)
    e2 = _cross(e3, e1)
    Rr = np.empty((3, 3))
    Rr[:, 0] = e1
    Rr[:, 1] = e2
    Rr[:, 2] = e3
    th1 = logm_so3(_mm(Rr.T, T1))
    th2 = logm_so3(_mm(Rr.T, T2))
    q1c = _dot(q, e1)
    q2c = _dot(q, e2)

    # local response (7 dofs: ubar, theta1, theta2)
    ubar = (l * l - l0 * l0) / (l + l0)
    N = EA * ubar / l0
    kt = GJ / l0
    ky = 2.0 * EIy / l0
    kz = 2.0 * EIz / l0
    m1 = np.array([kt * (th1[0] - th2[0]), ky * (2 * th1[1] + th2[1]), kz * (2 * th1[2] + th2[2])])
    m2 = np.array([kt * (th2[0] - th1[0]), ky * (th1[1] + 2 * th2[1]), kz * (th1[2] + 2 * th2[2])])
    Ti1 = ts_inv(th1)
    Ti2 = ts_inv(th2)
    mt1 = _mv(Ti1.T, m1)
    mt2 = _mv(Ti2.T, m2)
    M = mt1 + mt2
    alpha = M[1] + M[0] * q1c / q2c
    c = M[0] / (2.0 * q2c)
    FD = (-alpha * e3 + M[2] * e2) / l
    fx2 = N * e1 - FD
    qe1 = _cross(q1, e3)
    qe2 = _cross(q2, e3)
    fw1 = _mv(Rr, mt1) - c * qe1
    fw2 = _mv(Rr, mt2) - c * qe2
    for i in range(3):
        f[i] = -fx2[i]
        f[3 + i] = fw1[i]
        f[6 + i] = fx2[i]
        f[9 + i] = fw2[i]

    # ---- consistent tangent: chain rule with 3x12 Jacobians ----
    # d(x2 - x1)
    Dl = np.zeros((3, 12))
    for i in range(3):
        Dl[i, i] = -1.0
        Dl[i, 6 + i] = 1.0
    J_l = _vm(e1, Dl)
    G = np.zeros((3, 12))
    G[2, :] = _vm(e2, Dl) / l
    G[1, :] = -_vm(e3, Dl) / l
    G[0, :] = q1c * G[1, :]
    for i in range(3):
        G[0, 3 + i] += 0.5 * qe1[i]
        G[0, 9 + i] += 0.5 * qe2[i]
    G[0, :] /= q2c
    Wr = _mm(Rr, G)
    J_e1 = -_mm(skew(e1), Wr)
    J_e2 = -_mm(skew(e2), Wr)
    J_e3 = -_mm(skew(e3), Wr)
    J_q1 = np.zeros((3, 12))
    J_q2 = np.zeros((3, 12))
    J_q1[:, 3:6] = -skew(q1)
    J_q2[:, 9:12] = -skew(q2)
    J_q = 0.5 * (J_q1 + J_q2)
    J_q1c = _vm(e1, J_q) + _vm(q, J_e1)
    J_q2c = _vm(e2, J_q) + _vm(q, J_e2)
    # local rotations
    A1 = -G.copy()
    A2 = -G.copy()
    RrT = Rr.T.copy()
    A1[:, 3:6] += RrT
    A2[:, 9:12] += RrT
    J_th1 = _mm(Ti1, A1)
    J_th2 = _mm(Ti2, A2)
    J_N = (EA / l0) * J_l
    J_m1 = np.empty((3, 12))
    J_m2 = np.empty((3, 12))
    J_m1[0] = kt * (J_th1[0] - J_th2[0])
    J_m2[0] = -J_m1[0]
    J_m1[1] = ky * (2 * J_th1[1] + J_th2[1])
    J_m2[1] = ky * (J_th1[1] + 2 * J_th2[1])
    J_m1[2] = kz * (2 * J_th1[2] + J_th2[2])
    J_m2[2] = kz * (J_th1[2] + 2 * J_th2[2])
    J_mt1 = _mm(Ti1.T, J_m1) + _mm(ts_inv_T_times_derivative(th1, m1), J_th1)
    J_mt2 = _mm(Ti2.T, J_m2) + _mm(ts_inv_T_times_derivative(th2, m2), J_th2)
    J_M = J_mt1 + J_mt2
    J_alpha = J_M[1] + (q1c / q2c) * J_M[0] + (M[0] / q2c) * J_q1c - (M[0] * q1c / (q2c * q2c)) * J_q2c
    J_FD = np.empty((3, 12))
    for i in range(3):
        J_FD[i] = (-e3[i] * J_alpha - alpha * J_e3[i] + e2[i] * J_M[2] + M[2] * J_e2[i] - FD[i] * J_l) / l
    J_fx2 = np.empty((3, 12))
    for i in range(3):
        J_fx2[i] = e1[i] * J_N + N * J_e1[i] - J_FD[i]
    J_c = J_M[0] / (2.0 * q2c) - (M[0] / (2.0 * q2c * q2c)) * J_q2c
    S_e3 = skew(e3)
    J_fw1 = _mm(Rr, J_mt1) + mt1[0] * J_e1 + mt1[1] * J_e2 + mt1[2] * J_e3
    J_fw2 = _mm(Rr, J_mt2) + mt2[0] * J_e1 + mt2[1] * J_e2 + mt2[2] * J_e3
    for i in range(3):
        J_fw1[i] -= qe1[i] * J_c
        J_fw2[i] -= qe2[i] * J_c
    J_fw1 -= c * (_mm(skew(q1), J_e3) - _mm(S_e3, J_q1))
    J_fw2 -= c * (_mm(skew(q2), J_e3) - _mm(S_e3, J_q2))
    for j in range(12):
        for i in range(3):
            K[i, j] = -J_fx2[i, j]
            K[3 + i, j] = J_fw1[i, j]
            K[6 + i, j] = J_fx2[i, j]
            K[9 + i, j] = J_fw2[i, j]

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
    return 0.5 * (N * ubar + _dot(m1, th1) + _dot(m2, th2))


@njit(cache=True)
def beam_family_kernel(nodes, x, R, E0, l0, EA, GJ, EIy, EIz, f, K, sf, energy):
    """All elements of a beam family at once (see :func:`beam_element`)."""
    for e in range(nodes.shape[0]):
        a = nodes[e, 0]
        b = nodes[e, 1]
        energy[e] = beam_element(x[a], x[b], R[a], R[b], E0[e], l0[e], EA[e], GJ[e], EIy[e], EIz[e],
                                 f[e], K[e], sf[e])


def element_frame(x1, x2, up):
    """Initial element frame E0 = [e1 e2 e3] (columns): e1 along the element, e2 the
    up-vector made orthogonal to e1, e3 = e1 x e2.  Returns None if ``up`` is parallel
    to the element."""
    e1 = np.asarray(x2, float) - np.asarray(x1, float)
    e1 = e1 / np.linalg.norm(e1)
    up = np.asarray(up, float)
    e2 = up - (up @ e1) * e1
    n = np.linalg.norm(e2)
    if n < 1e-8 * max(np.linalg.norm(up), 1e-300):
        return None
    e2 /= n
    return np.column_stack([e1, e2, np.cross(e1, e2)])


class BeamFamily(ElementFamily):
    """A batch of corotational B33-like beams.

    Parameters are arrays over elements: ``E0`` (n,3,3) initial frames, ``l0`` (m),
    ``EA`` (N), ``GJ`` (N m^2), ``EIy``, ``EIz`` (N m^2), ``section_names``.
    ``Iz`` resists bending in the plane of the element axis and its up-vector.
    """

    name = "beam"
    active_dofs = (0, 1, 2, 3, 4, 5)
    n_state = 0
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
        self.labels = np.arange(1, len(self.nodes) + 1) if labels is None else np.asarray(labels)

    def evaluate(self, x, R, state, ctx=None):
        n = self.n_elements
        f = np.zeros((n, 12))
        K = np.zeros((n, 12, 12))
        sf = np.zeros((n, 2, 6))
        energy = np.zeros(n)
        beam_family_kernel(self.nodes, np.ascontiguousarray(x), np.ascontiguousarray(R), self.E0, self.l0,
                           self.EA, self.GJ, self.EIy, self.EIz, f, K, sf, energy)
        return ElementResponse(f=f, k=K, state=state, output={"section_forces": sf}, energy=energy)
