"""numba kernels: section lengths, their gradients and Hessians, and device wrap angles of a cable
over point devices and pulleys of finite radius (Stohlman & Pellegrino, Sec. II.B.2 names "the size of
the pulley" as a limitation of its point-pulley model).

Private module: the public face is :mod:`femast.elements.cable_devices`.

Geometry of a pulley of radius r (m) centred at node c between the points P (node before) and
Q (node after), a = P - c, b = Q - c, d_a = |a|, d_b = |b|:

* the cable lies in the plane through P, c and Q (a self-aligning pulley), on the side of the
  pulley away from P and Q, and leaves on the two tangents from P and Q;
* tangent lengths t_a = sqrt(d_a^2 - r^2), t_b = sqrt(d_b^2 - r^2); tangent angles
  beta_a = arccos(r / d_a), beta_b = arccos(r / d_b); gamma = angle(a, b);
* wrap angle phi = 2 pi - gamma - beta_a - beta_b (r -> 0: the point-pulley turning angle
  pi - gamma);
* length of cable from P to Q: t_a + r phi + t_b; the wrapped arc is shared equally between the
  two sections: L_in = t_a + r phi / 2, L_out = t_b + r phi / 2 (exact for a frictionless pulley;
  with friction the stretch of the arc is that of the mean of the two tensions).

Hessians are analytic (derived from gamma = arccos(a_hat . b_hat)); the tests check them by
finite differences.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

GEO_OK = 0
GEO_ZERO_LENGTH = 1
GEO_NOT_FINITE = 2
GEO_INSIDE_PULLEY = 3  # a neighbouring point lies on or inside the pulley circle: no tangent
GEO_PLANE_UNDEFINED = 4  # P, c, Q collinear: the plane of a pulley of finite radius is undefined
GEO_ADJACENT_PULLEYS = 5  # two pulleys of finite radius next to each other (not supported)

SIN_MIN = 1e-9  # |sin gamma| below this: collinear


@njit(cache=True)
def angle_derivatives(a, b, ga, gb, Haa, Hab, Hbb, want_hess):
    """gamma = angle(a, b) in [0, pi] (rad), its gradients ga, gb (1/m) and (if want_hess) Hessian
    blocks (1/m^2).  Returns (gamma, sin gamma); the derivatives are left zero when sin gamma <
    SIN_MIN (the angle is not differentiable there)."""
    na = math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    nb = math.sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2])
    ah = a / na
    bh = b / nb
    cr0 = ah[1] * bh[2] - ah[2] * bh[1]
    cr1 = ah[2] * bh[0] - ah[0] * bh[2]
    cr2 = ah[0] * bh[1] - ah[1] * bh[0]
    s = math.sqrt(cr0 * cr0 + cr1 * cr1 + cr2 * cr2)
    c = ah[0] * bh[0] + ah[1] * bh[1] + ah[2] * bh[2]
    gamma = math.atan2(s, c)
    for i in range(3):
        ga[i] = 0.0
        gb[i] = 0.0
        for j in range(3):
            Haa[i, j] = 0.0
            Hab[i, j] = 0.0
            Hbb[i, j] = 0.0
    if s < SIN_MIN:
        return gamma, s
    pa = (bh - c * ah) / na
    pb = (ah - c * bh) / nb
    for i in range(3):
        ga[i] = -pa[i] / s
        gb[i] = -pb[i] / s
    if not want_hess:
        return gamma, s
    s3 = s * s * s
    for i in range(3):
        for j in range(3):
            dij = 1.0 if i == j else 0.0
            Caa = -(ah[i] * pa[j] + pa[i] * ah[j]) / na - c * (dij - ah[i] * ah[j]) / (na * na)
            Cbb = -(bh[i] * pb[j] + pb[i] * bh[j]) / nb - c * (dij - bh[i] * bh[j]) / (nb * nb)
            Cab = ((dij - bh[i] * bh[j]) / nb - ah[i] * pb[j]) / na
            Haa[i, j] = -Caa / s - c / s3 * pa[i] * pa[j]
            Hbb[i, j] = -Cbb / s - c / s3 * pb[i] * pb[j]
            Hab[i, j] = -Cab / s - c / s3 * pa[i] * pb[j]
    return gamma, s


@njit(cache=True)
def _radial(a, f1, f2, g, H, w):
    """Add w * (gradient, Hessian) of f(|a|) with f' = f1, f'' = f2 to g (3,) and H (3, 3)."""
    d = math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    for i in range(3):
        ai = a[i] / d
        g[i] += w * f1 * ai
        for j in range(3):
            aj = a[j] / d
            dij = 1.0 if i == j else 0.0
            H[i, j] += w * (f2 * ai * aj + f1 / d * (dij - ai * aj))


@njit(cache=True)
def _scatter(k, ga, gb, Haa, Hab, Hbb, G, H):
    """Add a function of (a, b) = (X[k-1] - X[k], X[k+1] - X[k]) given by its (a, b) gradient and
    Hessian blocks to the nodal gradient G (3 nn,) and Hessian H (3 nn, 3 nn)."""
    P = 3 * (k - 1)
    C = 3 * k
    Q = 3 * (k + 1)
    for i in range(3):
        G[P + i] += ga[i]
        G[Q + i] += gb[i]
        G[C + i] -= ga[i] + gb[i]
        for j in range(3):
            H[P + i, P + j] += Haa[i, j]
            H[Q + i, Q + j] += Hbb[i, j]
            H[P + i, Q + j] += Hab[i, j]
            H[Q + i, P + j] += Hab[j, i]
            H[P + i, C + j] -= Haa[i, j] + Hab[i, j]
            H[C + i, P + j] -= Haa[j, i] + Hab[j, i]
            H[Q + i, C + j] -= Hab[j, i] + Hbb[i, j]
            H[C + i, Q + j] -= Hab[i, j] + Hbb[j, i]
            H[C + i, C + j] += Haa[i, j] + Hab[i, j] + Hab[j, i] + Hbb[i, j]


@njit(cache=True)
def cable_geometry(X, radius, want_hess, L, G, H, phi, dphi):
    """Section lengths and wrap angles of one cable.

    X (nn, 3) node positions, m; radius (nn,) pulley radius at each node, m (0: a point; the end
    nodes must be 0).  Outputs: L (n,) section lengths, m; G (n, 3 nn) their gradients; H (n, 3 nn,
    3 nn) their Hessians (1/m; only if want_hess); phi (n - 1,) wrap angle at each interior node,
    rad; dphi (n - 1, 3 nn) its gradient, 1/m.  Returns an error code (GEO_*) and the node or
    section it concerns."""
    nn = X.shape[0]
    n = nn - 1
    for i in range(n):
        L[i] = 0.0
        for a in range(3 * nn):
            G[i, a] = 0.0
            if want_hess:
                for b in range(3 * nn):
                    H[i, a, b] = 0.0
    for k in range(n - 1):
        phi[k] = 0.0
        for a in range(3 * nn):
            dphi[k, a] = 0.0
    for k in range(nn):
        for c in range(3):
            if not math.isfinite(X[k, c]):
                return GEO_NOT_FINITE, k
    # chords of sections with no sized pulley at either end
    for i in range(n):
        if radius[i] > 0.0 and radius[i + 1] > 0.0:
            return GEO_ADJACENT_PULLEYS, i
        d0 = X[i + 1, 0] - X[i, 0]
        d1 = X[i + 1, 1] - X[i, 1]
        d2 = X[i + 1, 2] - X[i, 2]
        Li = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if not Li > 0.0:
            return GEO_ZERO_LENGTH, i
        if radius[i] > 0.0 or radius[i + 1] > 0.0:
            continue
        L[i] = Li
        e = np.array([d0, d1, d2]) / Li
        for c in range(3):
            G[i, 3 * i + c] -= e[c]
            G[i, 3 * (i + 1) + c] += e[c]
        if want_hess:
            for c in range(3):
                for d in range(3):
                    v = ((1.0 if c == d else 0.0) - e[c] * e[d]) / Li
                    H[i, 3 * i + c, 3 * i + d] += v
                    H[i, 3 * (i + 1) + c, 3 * (i + 1) + d] += v
                    H[i, 3 * i + c, 3 * (i + 1) + d] -= v
                    H[i, 3 * (i + 1) + c, 3 * i + d] -= v
    ga = np.empty(3)
    gb = np.empty(3)
    Haa = np.empty((3, 3))
    Hab = np.empty((3, 3))
    Hbb = np.empty((3, 3))
    gpa = np.zeros(3)
    gpb = np.zeros(3)
    Hpaa = np.zeros((3, 3))
    Hpbb = np.zeros((3, 3))
    for k in range(1, n):
        a = X[k - 1] - X[k]
        b = X[k + 1] - X[k]
        r = radius[k]
        sized = r > 0.0
        gamma, s = angle_derivatives(a, b, ga, gb, Haa, Hab, Hbb, want_hess and sized)
        if not sized:
            phi[k - 1] = math.pi - gamma
            for c in range(3):
                dphi[k - 1, 3 * (k - 1) + c] = -ga[c]
                dphi[k - 1, 3 * (k + 1) + c] = -gb[c]
                dphi[k - 1, 3 * k + c] = ga[c] + gb[c]
            continue
        da = math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
        db = math.sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2])
        if da <= r * (1.0 + 1e-9):
            return GEO_INSIDE_PULLEY, k - 1
        if db <= r * (1.0 + 1e-9):
            return GEO_INSIDE_PULLEY, k + 1
        if s < SIN_MIN:
            return GEO_PLANE_UNDEFINED, k
        ta = math.sqrt(da * da - r * r)
        tb = math.sqrt(db * db - r * r)
        ba = math.acos(r / da)
        bb = math.acos(r / db)
        ph = 2.0 * math.pi - gamma - ba - bb
        phi[k - 1] = ph
        # phi as a function of (a, b): -gamma - beta(|a|) - beta(|b|)
        for c in range(3):
            gpa[c] = -ga[c]
            gpb[c] = -gb[c]
            for d in range(3):
                Hpaa[c, d] = -Haa[c, d]
                Hpbb[c, d] = -Hbb[c, d]
        # beta' = r / (d t), beta'' = -r (t^2 + d^2) / (d^2 t^3)
        _radial(a, r / (da * ta), -r * (ta * ta + da * da) / (da * da * ta**3), gpa, Hpaa, -1.0)
        _radial(b, r / (db * tb), -r * (tb * tb + db * db) / (db * db * tb**3), gpb, Hpbb, -1.0)
        Hpab = -Hab
        gphi = np.zeros(3 * nn)
        Hdummy = np.zeros((3 * nn, 3 * nn))
        _scatter(k, gpa, gpb, Hpaa, Hpab, Hpbb, gphi, Hdummy)
        for c in range(3 * nn):
            dphi[k - 1, c] = gphi[c]
        # sections k-1 (in) and k (out): t + r phi / 2
        for sec, vec, dd, tt in ((k - 1, a, da, ta), (k, b, db, tb)):
            L[sec] = tt + 0.5 * r * ph
            gt = np.zeros(3)
            Ht = np.zeros((3, 3))
            # t' = d / t, t'' = -r^2 / t^3
            _radial(vec, dd / tt, -r * r / tt**3, gt, Ht, 1.0)
            for c in range(3 * nn):
                G[sec, c] += 0.5 * r * gphi[c]
                if want_hess:
                    for d in range(3 * nn):
                        H[sec, c, d] += 0.5 * r * Hdummy[c, d]
            z3 = np.zeros(3)
            Z33 = np.zeros((3, 3))
            gsec = np.zeros(3 * nn)
            Hsec = np.zeros((3 * nn, 3 * nn))
            if sec == k - 1:
                _scatter(k, gt, z3, Ht, Z33, Z33, gsec, Hsec)
            else:
                _scatter(k, z3, gt, Z33, Z33, Ht, gsec, Hsec)
            for c in range(3 * nn):
                G[sec, c] += gsec[c]
                if want_hess:
                    for d in range(3 * nn):
                        H[sec, c, d] += Hsec[c, d]
    return GEO_OK, -1
