"""numba kernels of the cable/pulley/latch element (Stohlman & Pellegrino, Eqs. 2-5 and 14).

Private module: the public face is :mod:`femast.elements.cable_latch`.

Reduction of the 2n equations
-----------------------------
Unknowns: n tensions T_i and n unstretched lengths L0_i.  Equations: n tension-only
laws (Eqs. 2-3), sum L0_i = L0 (Eq. 4), and n-1 jumps: T_{i+1} = T_i across each
frictionless pulley and T_{j+1} - T_j = dT(x) across the latch at interior node j
(Eq. 5), x = Lb - (L0_1 + ... + L0_j).

One cable has one EA.  Across frictionless pulleys the tension is uniform, so the
sections before the latch (group A: sections 1..j) carry T_A and those after it
(group B: j+1..n) carry T_B.  For a uniform tension the group behaves as one
section of length L_A = sum of its chord lengths and unstretched length
s = L0_1 + ... + L0_j:

    T_A(s) = EA max(0, L_A / s - 1),   T_B(s) = EA max(0, L_B / (L0 - s) - 1)

and the whole system reduces *exactly* to one scalar equation in s (the material
coordinate of the cable at the latch node) with x = Lb - s:

    T_B(s) - T_A(s) = dT(x)      (slip),      s = s_committed      (stick).

C(s) = T_B - T_A is non-decreasing in s, which makes the scalar problem easy to
bracket.  Given s, each section's L0_i follows from its own Eq. 2-3 (taut: L0_i =
L_i / (1 + T/EA); slack group: the slack is shared in proportion to L_i), so all
2n equations hold (checked by the tests through ``cable_equations``).

Return mapping of the latch
---------------------------
With the committed bead position x_c: if C(s_c) is inside the static-friction
band [dT_in(x_c), dT_out(x_c)] (lower bound -inf at the backstop) the bead sticks.
Otherwise it slides in the direction of the unbalanced force (sigma = +1 out if
C > dT_out, -1 in if C < dT_in) and stops at the *first* equilibrium it meets,
G(x) = sigma (C - dT_sigma(x)) = 0, or at the backstop.  The first root is found
by marching a grid over the contact zone (outside it G is monotone) and refined
by safeguarded Newton (rtsafe).  Where the cable is slack and the bead free, G
vanishes on an interval and the march returns its near end: a slack cable does
not move the bead.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .latch_law import latch_dT_scalar, latch_opening_scalar

STICK = 0
SLIP_OUT = 1
SLIP_IN = -1
BACKSTOP = 2

ERR_NONE = 0
ERR_ZERO_LENGTH = 1
ERR_BEAD_OFF_CABLE = 2
ERR_NOT_FINITE = 3

N_GRID = 256  # grid intervals over the contact zone for the first-root march
S_EPS = 1e-9  # s is kept in [S_EPS L0, (1 - S_EPS) L0]


@njit(cache=True)
def hysteresis_scalar(x, xb, Fh, ell):
    """Extra friction H(x) (N) of the latch hysteresis option and dH/dx (N/m).

    H = Fh w(x) with w = (exp(-(x + xb)/ell) - exp(-xb/ell)) / (1 - exp(-xb/ell)) for
    -xb <= x < 0 (1 with the bead on the backstop, 0 at the roller axis and beyond), so the
    static band widens to [dT_in - H, dT_out + H] near the latched state.  Fh = 0: H = 0."""
    if Fh <= 0.0 or x >= 0.0:
        return 0.0, 0.0
    u = x + xb
    if u < 0.0:
        u = 0.0
    e0 = math.exp(-xb / ell)
    den = 1.0 - e0
    eu = math.exp(-u / ell)
    return Fh * (eu - e0) / den, -Fh * eu / (ell * den)


@njit(cache=True)
def branch_scalar(x, sigma, p, Fh, ell):
    """Force jump of a bead moving in direction sigma (N) and its x-derivative (N/m): Eq. 14
    plus sigma H(x) of the hysteresis option (exactly Eq. 14 when Fh = 0)."""
    return branch_scalar_mu(x, sigma, p, p[3], Fh, ell)


@njit(cache=True)
def branch_scalar_mu(x, sigma, p, mu, Fh, ell):
    """:func:`branch_scalar` with the friction coefficient ``mu`` given (static or kinetic)."""
    D, dD = latch_dT_scalar(x, sigma, p[0], p[1], p[2], mu, p[4], p[5])
    if Fh > 0.0:
        H, dH = hysteresis_scalar(x, p[1], Fh, ell)
        D += sigma * H
        dD += sigma * dH
    return D, dD


@njit(cache=True)
def group_tensions(s, LA, LB, EA, L0):
    """Tensions of the two groups and their partial derivatives.

    Returns tA, dtA/ds, dtA/dLA, tB, dtB/ds, dtB/dLB (N, N/m)."""
    tA = 0.0
    dtA_ds = 0.0
    dtA_dLA = 0.0
    if LA > s and s > 0.0:
        tA = EA * (LA / s - 1.0)
        dtA_ds = -EA * LA / (s * s)
        dtA_dLA = EA / s
    sb = L0 - s
    tB = 0.0
    dtB_ds = 0.0
    dtB_dLB = 0.0
    if LB > sb and sb > 0.0:
        tB = EA * (LB / sb - 1.0)
        dtB_ds = EA * LB / (sb * sb)
        dtB_dLB = EA / sb
    return tA, dtA_ds, dtA_dLA, tB, dtB_ds, dtB_dLB


@njit(cache=True)
def _G(x, sigma, Lb, LA, LB, EA, L0, p, Fh, ell):
    """G = sigma (C - dT_sigma(x)) and dG/dx."""
    s = Lb - x
    tA, dtA_ds, _, tB, dtB_ds, _ = group_tensions(s, LA, LB, EA, L0)
    D, dD = branch_scalar(x, sigma, p, Fh, ell)
    C = tB - tA
    dC_dx = -(dtB_ds - dtA_ds)
    return sigma * (C - D), sigma * (dC_dx - dD), abs(tA) + abs(tB) + abs(D)


@njit(cache=True)
def _refine(xa, Ga, xb, Gb, sigma, Lb, LA, LB, EA, L0, p, Fh, ell):
    """First root of G in a bracket with G(xa) > 0 >= G(xb) (rtsafe-like)."""
    a = xa
    b = xb
    tolx = 4.0 * 2.220446049250313e-16 * (abs(Lb) + abs(xa) + L0)
    if Gb == 0.0:
        # may be the far end of a zero interval: keep bisecting towards a
        xcur = 0.5 * (a + b)
    elif abs(Gb) < abs(Ga):
        xcur = b
    else:
        xcur = a
    Gc, dGc, scale = _G(xcur, sigma, Lb, LA, LB, EA, L0, p, Fh, ell)
    dxold = abs(b - a)
    for _ in range(300):
        if Gc > 0.0:
            a = xcur
        else:
            b = xcur
        if Gc != 0.0 and abs(Gc) <= 1e-13 * scale:
            return xcur
        if abs(b - a) <= tolx:
            return b
        # Newton step if it stays inside and shrinks fast enough, else bisection
        use_bisect = True
        if dGc != 0.0 and Gc != 0.0:
            xn = xcur - Gc / dGc
            lo = min(a, b)
            hi = max(a, b)
            if lo < xn < hi and abs(xn - xcur) < 0.5 * dxold:
                use_bisect = False
        if use_bisect:
            xn = 0.5 * (a + b)
        dxold = abs(xn - xcur)
        xcur = xn
        Gc, dGc, scale = _G(xcur, sigma, Lb, LA, LB, EA, L0, p, Fh, ell)
    return xcur


@njit(cache=True)
def first_root(sigma, x_start, x_end, Lb, LA, LB, EA, L0, p, Fh, ell):
    """First x from x_start towards x_end (in direction sigma) with G(x) <= 0.

    Assumes G(x_start) > 0.  Returns (x, hit_end): hit_end is True when G > 0 all
    the way to x_end (then x = x_end)."""
    r = p[0]
    h = p[4]
    R = p[5]
    c2 = (r + R) * (r + R) - (h + r) * (h + r)
    xct = math.sqrt(c2) if c2 > 0.0 else 0.0
    hstep = 2.0 * xct / N_GRID
    xa = x_start
    Ga, _, _ = _G(xa, sigma, Lb, LA, LB, EA, L0, p, Fh, ell)
    if xct > 0.0:
        if sigma > 0:
            i = int(math.floor((xa + xct) / hstep)) + 1
            if i < 0:
                i = 0
            while i <= N_GRID:
                xg = -xct + i * hstep
                if xg >= x_end:
                    break
                if xg > xa:
                    Gg, _, _ = _G(xg, sigma, Lb, LA, LB, EA, L0, p, Fh, ell)
                    if Gg <= 0.0:
                        return _refine(xa, Ga, xg, Gg, sigma, Lb, LA, LB, EA, L0, p, Fh, ell), False
                    xa = xg
                    Ga = Gg
                i += 1
        else:
            i = int(math.ceil((xa + xct) / hstep)) - 1
            if i > N_GRID:
                i = N_GRID
            while i >= 0:
                xg = -xct + i * hstep
                if xg <= x_end:
                    break
                if xg < xa:
                    Gg, _, _ = _G(xg, sigma, Lb, LA, LB, EA, L0, p, Fh, ell)
                    if Gg <= 0.0:
                        return _refine(xa, Ga, xg, Gg, sigma, Lb, LA, LB, EA, L0, p, Fh, ell), False
                    xa = xg
                    Ga = Gg
                i -= 1
    Ge, _, _ = _G(x_end, sigma, Lb, LA, LB, EA, L0, p, Fh, ell)
    if Ge <= 0.0:
        return _refine(xa, Ga, x_end, Ge, sigma, Lb, LA, LB, EA, L0, p, Fh, ell), False
    return x_end, True


@njit(cache=True)
def solve_latch(LA, LB, EA, L0, Lb, has_latch, p, x_c, Fh=0.0, ell=1.0, mu_k=-1.0, status_c=0):
    """Solve the reduced cable equation for one element (Fh, ell: hysteresis option, N and m).

    mu_k : kinetic friction (< 0: the static p[3]); status_c : the committed status.  The static
    band uses p[3], except on the side of a bead that was sliding (it slides on at mu_k until it
    stops or reverses); a sliding bead follows Eq. 14 at mu_k.

    Returns x (m, bead position), s = Lb - x (m), status, tA, tB (N), ds/dLA, ds/dLB (-)."""
    if mu_k >= 0.0 and mu_k != p[3]:
        pk = p.copy()  # the law of a sliding bead
        pk[3] = mu_k
    else:
        pk = p
        mu_k = p[3]
    if not has_latch:
        tA, _, _, tB, _, _ = group_tensions(0.0, 0.0, LB, EA, L0)
        return x_c, 0.0, STICK, 0.0, tB, 0.0, 0.0
    r = p[0]
    xb = p[1]
    s_c = Lb - x_c
    tA, dtA_ds, dtA_dLA, tB, dtB_ds, dtB_dLB = group_tensions(s_c, LA, LB, EA, L0)
    C = tB - tA
    at_stop = x_c <= -xb * (1.0 - 1e-12)
    D_in, _ = branch_scalar_mu(x_c, -1.0, p, mu_k if status_c == SLIP_IN else p[3], Fh, ell)
    D_out, _ = branch_scalar_mu(x_c, 1.0, p, mu_k if status_c == SLIP_OUT else p[3], Fh, ell)
    lo = -np.inf if at_stop else D_in
    hi = D_out
    free = (not at_stop) and latch_opening_scalar(x_c, r, p[4], p[5]) <= 0.0
    sigma = 0
    if free and (tA > 0.0 or tB > 0.0):
        # zero-width band: a bead off the rollers under a taut cable always slides
        sigma = 1 if C >= 0.0 else -1
    elif C > hi:
        sigma = 1
    elif C < lo:
        sigma = -1
    if sigma == 0:
        status = BACKSTOP if at_stop else STICK
        return x_c, s_c, status, tA, tB, 0.0, 0.0
    if free and C == 0.0:
        x = x_c  # taut cable already balanced on a free bead
    elif sigma > 0:
        x_end = Lb - S_EPS * L0
        x, _ = first_root(1.0, x_c, x_end, Lb, LA, LB, EA, L0, pk, Fh, ell)
    else:
        x_end = Lb - (1.0 - S_EPS) * L0
        stop = -xb
        if stop > x_end:
            x_end = stop
        x, hit = first_root(-1.0, x_c, x_end, Lb, LA, LB, EA, L0, pk, Fh, ell)
        if hit and x_end == stop:
            s = Lb - x
            tA, _, _, tB, _, _ = group_tensions(s, LA, LB, EA, L0)
            return x, s, BACKSTOP, tA, tB, 0.0, 0.0
    s = Lb - x
    tA, dtA_ds, dtA_dLA, tB, dtB_ds, dtB_dLB = group_tensions(s, LA, LB, EA, L0)
    _, dD = branch_scalar(x, float(sigma), pk, Fh, ell)
    phi_s = dtB_ds - dtA_ds + dD
    scale = dtA_dLA + dtB_dLB + abs(dD) + dtB_ds - dtA_ds
    ds_dLA = 0.0
    ds_dLB = 0.0
    if phi_s > 1e-12 * scale:
        ds_dLA = dtA_dLA / phi_s
        ds_dLB = -dtB_dLB / phi_s
    status = SLIP_OUT if sigma > 0 else SLIP_IN
    return x, s, status, tA, tB, ds_dLA, ds_dLB


@njit(cache=True)
def cable_latch_kernel(X, EA, L0, Lb, jl, P, MuK, Hy, state, f, K, state_new, T, dT, energy, err):
    """All elements: nodal forces f (n_el, 6(n+1)), tangent K, trial state, tensions.

    X (n_el, n+1, 3) m; EA (N), L0 (m), Lb (m) per element; jl latch node (local
    index 1..n-1, 0 for none); P (n_el, 6) latch parameters (mu: static); MuK (n_el,) kinetic
    friction; Hy (n_el, 2) hysteresis
    option [Fh (N), ell (m)] (Fh = 0: off); state (n_el, n+2)
    committed [x_bead, status, L0_1..L0_n] (read only)."""
    n_el = X.shape[0]
    nn = X.shape[1]
    n = nn - 1
    e = np.empty((n, 3))
    L = np.empty(n)
    gA = np.empty(3 * nn)
    gB = np.empty(3 * nn)
    for el in range(n_el):
        err[el] = ERR_NONE
        for a in range(6 * nn):
            f[el, a] = 0.0
            for b in range(6 * nn):
                K[el, a, b] = 0.0
        ok = True
        for i in range(n):
            d0 = X[el, i + 1, 0] - X[el, i, 0]
            d1 = X[el, i + 1, 1] - X[el, i, 1]
            d2 = X[el, i + 1, 2] - X[el, i, 2]
            Li = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            if not math.isfinite(Li):
                err[el] = ERR_NOT_FINITE
                ok = False
                break
            if Li <= 0.0:
                err[el] = ERR_ZERO_LENGTH
                ok = False
                break
            L[i] = Li
            e[i, 0] = d0 / Li
            e[i, 1] = d1 / Li
            e[i, 2] = d2 / Li
        if not ok:
            for c in range(state.shape[1]):
                state_new[el, c] = state[el, c]
            continue
        j = jl[el]
        has_latch = j > 0
        LA = 0.0
        LB = 0.0
        for i in range(n):
            if i < j:
                LA += L[i]
            else:
                LB += L[i]
        x_c = state[el, 0]
        s_c = Lb[el] - x_c
        if has_latch and not (0.0 < s_c < L0[el]):
            err[el] = ERR_BEAD_OFF_CABLE
            for c in range(state.shape[1]):
                state_new[el, c] = state[el, c]
            continue
        p = P[el]
        x_new, s, status, tA, tB, ds_dLA, ds_dLB = solve_latch(
            LA, LB, EA[el], L0[el], Lb[el], has_latch, p, x_c, Hy[el, 0], Hy[el, 1], MuK[el], int(state[el, 1])
        )
        tA, dtA_ds, dtA_dLA, tB, dtB_ds, dtB_dLB = group_tensions(s, LA, LB, EA[el], L0[el])
        # total derivatives of the group tensions w.r.t. the group chord lengths
        MAA = dtA_dLA + dtA_ds * ds_dLA
        MAB = dtA_ds * ds_dLB
        MBA = dtB_ds * ds_dLA
        MBB = dtB_dLB + dtB_ds * ds_dLB
        # state, per-section tensions and unstretched lengths
        state_new[el, 0] = x_new
        state_new[el, 1] = status
        en = 0.0
        for i in range(n):
            if i < j:
                Ti = tA
                if tA > 0.0:
                    L0i = L[i] / (1.0 + tA / EA[el])
                else:
                    L0i = L[i] * s / LA
            else:
                Ti = tB
                sb = L0[el] - s
                if tB > 0.0:
                    L0i = L[i] / (1.0 + tB / EA[el])
                else:
                    L0i = L[i] * sb / LB
            state_new[el, 2 + i] = L0i
            T[el, i] = Ti
            if Ti > 0.0:
                en += 0.5 * EA[el] * (L[i] - L0i) ** 2 / L0i
        if has_latch:
            dlt = latch_opening_scalar(x_new, p[0], p[4], p[5])
            en += p[2] * dlt * dlt
        energy[el] = en
        dT[el] = tB - tA
        # g vectors: gradients of L_A and L_B w.r.t. nodal positions
        for a in range(3 * nn):
            gA[a] = 0.0
            gB[a] = 0.0
        for i in range(n):
            for c in range(3):
                if i < j:
                    gA[3 * i + c] -= e[i, c]
                    gA[3 * (i + 1) + c] += e[i, c]
                else:
                    gB[3 * i + c] -= e[i, c]
                    gB[3 * (i + 1) + c] += e[i, c]
        # internal forces f = T_A gA + T_B gB
        for a in range(nn):
            for c in range(3):
                f[el, 6 * a + c] = tA * gA[3 * a + c] + tB * gB[3 * a + c]
        # geometric stiffness T_i / L_i (I - e e^T)
        for i in range(n):
            Ti = T[el, i]
            if Ti <= 0.0:
                continue
            coef = Ti / L[i]
            for c in range(3):
                for d in range(3):
                    v = coef * ((1.0 if c == d else 0.0) - e[i, c] * e[i, d])
                    K[el, 6 * i + c, 6 * i + d] += v
                    K[el, 6 * (i + 1) + c, 6 * (i + 1) + d] += v
                    K[el, 6 * i + c, 6 * (i + 1) + d] -= v
                    K[el, 6 * (i + 1) + c, 6 * i + d] -= v
        # material stiffness [gA gB] M [gA gB]^T
        for a in range(nn):
            for c in range(3):
                ga = gA[3 * a + c]
                gb = gB[3 * a + c]
                ra = MAA * ga + MBA * gb
                rb = MAB * ga + MBB * gb
                if ra == 0.0 and rb == 0.0:
                    continue
                for b2 in range(nn):
                    for d in range(3):
                        K[el, 6 * a + c, 6 * b2 + d] += ra * gA[3 * b2 + d] + rb * gB[3 * b2 + d]
