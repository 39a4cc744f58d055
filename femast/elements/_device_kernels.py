"""numba kernel of the cable over an ordered list of devices (Stohlman & Pellegrino, Sec. II.B.2).

Private module: the public face is :mod:`femast.elements.cable_devices`.

Unknowns and equations
----------------------
A cable of n sections, nodes 0..n, devices at the interior nodes 1..n-1.  The unknowns are the
material coordinates S_1..S_{n-1} of the cable at the devices (S_0 = 0, S_n = L0, Eq. 4), so the
unstretched lengths are l0_i = S_{i+1} - S_i and the tensions (Eqs. 2-3)

    e_i = L_i / l0_i - 1,        T_i = EA max(0, e_i).

One equation per device (the paper's jumps Delta T_i = T_{i+1} - T_i as functions of the cable
distribution): ``EA (e_out - e_in) = 0`` for a frictionless pulley, ``S - S_committed = 0`` for a
device that sticks (or a clamp), ``S - S_max = 0`` at a stop, and ``r_sigma(T_in, T_out, S, phi) = 0``
(:mod:`._device_laws`) for a device sliding in direction sigma.  With the 2n unknowns (T_i, l0_i)
eliminated by Eqs. 2-4 this is the paper's 2n system.

Stick/slip: an active-set return mapping from the committed state.  All friction devices start
sticking; the device whose static band is most violated starts sliding in the direction of its
unbalanced force; a sliding device that would move against its direction sticks again; repeat
until nothing changes.  Each set is solved by Newton on S with a step limited so that no
unstretched length loses more than 90 % and a sliding latch crosses its contact zone one grid
cell at a time (first equilibrium in its direction).

Consistent tangent: with the device residuals R(S; L, phi) = 0, dS/dx = -A^-1 (R_L dL/dx +
R_phi dphi/dx), A = dR/dS, and ``K = sum_i T_i d2L_i/dx2 + sum_i dL_i/dx (dT_i/dx)^T``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._cable_geometry import GEO_OK, cable_geometry
from ._cable_kernels import latch_opening_scalar
from ._device_algebra import cable_forces_and_tangent
from ._device_algebra import section_tensions as _sections
from ._device_algebra import solve_small as _solve_small
from ._device_laws import CLAMP, FREE, LATCH, builtin_law, max_step, s_max_of

_law = builtin_law
"""The device law the kernels call (a module global, so that the kernels cache; a family with a user
law runs a copy of this module with ``_law`` replaced, see :mod:`._device_user_kernels`)."""

STICK = 0
SLIP_OUT = 1  # sigma = +1: the out side pulls (dS < 0)
SLIP_IN = -1  # sigma = -1: the in side pulls (dS > 0)
STOP = 2  # held at S_max (latch backstop)
SLIDE_FREE = 3  # frictionless pulley

ERR_NONE = 0
ERR_NO_CONVERGENCE = 10  # the device equations did not converge
ERR_SHORT = 11  # a section's unstretched length would be <= 0 (the cable is far too short)
ERR_ACTIVE_SET = 12  # the stick/slip set cycled

MAX_NEWTON = 800
MAX_SET = 60


@njit(cache=True)
def _assemble(S, L, phi, EA, L0, kinds, P, modes, targets, R, A, RL, Rphi, T, dT_dl0, de_dl0, e):
    """Device residuals R (n-1,), dR/dS A, dR/dL RL (n-1, n) and dR/dphi Rphi (n-1,)."""
    n = L.shape[0]
    m = n - 1
    _sections(S, L, EA, T, dT_dl0, de_dl0, e)
    for d in range(m):
        R[d] = 0.0
        Rphi[d] = 0.0
        for j in range(m):
            A[d, j] = 0.0
        for j in range(n):
            RL[d, j] = 0.0
    for d in range(m):
        i_in = d
        i_out = d + 1
        mode = modes[d]
        if mode == SLIDE_FREE:
            # EA (e_out - e_in); l0_in = S[d+1] - S[d], l0_out = S[d+2] - S[d+1]
            R[d] = EA * (e[i_out] - e[i_in])
            if d >= 1:
                A[d, d - 1] += EA * de_dl0[i_in]
            A[d, d] += -EA * de_dl0[i_out] - EA * de_dl0[i_in]
            if d + 1 < m:
                A[d, d + 1] += EA * de_dl0[i_out]
            RL[d, i_out] = EA / (S[i_out + 1] - S[i_out])
            RL[d, i_in] = -EA / (S[i_in + 1] - S[i_in])
        elif mode == STICK or mode == STOP:
            c = EA / L0
            R[d] = c * (S[d + 1] - targets[d])
            A[d, d] = c
        else:
            sigma = float(mode)
            r, rTi, rTo, rs, rphi = _law(kinds[d], sigma, T[i_in], T[i_out], S[d + 1], phi[d], P[d], False)
            R[d] = r
            if d >= 1:
                A[d, d - 1] += -rTi * dT_dl0[i_in]
            A[d, d] += rTi * dT_dl0[i_in] - rTo * dT_dl0[i_out] + rs
            if d + 1 < m:
                A[d, d + 1] += rTo * dT_dl0[i_out]
            if T[i_in] > 0.0:
                RL[d, i_in] = rTi * EA / (S[i_in + 1] - S[i_in])
            if T[i_out] > 0.0:
                RL[d, i_out] = rTo * EA / (S[i_out + 1] - S[i_out])
            Rphi[d] = rphi


@njit(cache=True)
def _newton(S, L, phi, EA, L0, kinds, P, modes, targets, smax, bufs):
    """Solve the device equations for the current modes, S updated in place.

    Returns 0 (converged), the index + 1 of a sliding device whose row is singular (negative:
    -(d + 1)), ERR_SHORT or ERR_NO_CONVERGENCE (as 1000 + code)."""
    R, A, RL, Rphi, T, dT_dl0, de_dl0, e, dS = bufs
    n = L.shape[0]
    m = n - 1
    back = np.empty(m)
    front = np.empty(m)
    has_front = np.zeros(m, dtype=np.bool_)
    start = np.empty(m)
    S_prev = np.empty(m)
    step_prev = np.zeros(m)
    halvings = 0
    for d in range(m):
        back[d] = S[d + 1]
        front[d] = S[d + 1]
        start[d] = S[d + 1]
    for it in range(MAX_NEWTON):
        _assemble(S, L, phi, EA, L0, kinds, P, modes, targets, R, A, RL, Rphi, T, dT_dl0, de_dl0, e)
        # a device sliding towards its stop that has reached it and is still pushed stays there
        stopped = False
        for d in range(m):
            if modes[d] == SLIP_IN and S[d + 1] >= smax[d] and -R[d] > 0.0:
                modes[d] = STOP
                targets[d] = smax[d]
                stopped = True
        if stopped:
            _assemble(S, L, phi, EA, L0, kinds, P, modes, targets, R, A, RL, Rphi, T, dT_dl0, de_dl0, e)
        rhs = -R
        if not _solve_small(A, rhs, dS):
            if it > 0 and halvings < 80:
                # the last step took a sliding device's both sides slack (a flat residual): go back
                # halfway, so that the device stops where its cable just becomes slack
                halvings += 1
                for d in range(m):
                    step_prev[d] *= 0.5
                    S[d + 1] = S_prev[d] + step_prev[d]
                continue
            # find a sliding device with an (almost) empty row: both sides slack
            for d in range(m):
                if modes[d] == SLIP_OUT or modes[d] == SLIP_IN:
                    rowmax = 0.0
                    for j in range(m):
                        rowmax = max(rowmax, abs(A[d, j]))
                    if rowmax <= 1e-12 * EA / L0:
                        return -(d + 1)
            return 1000 + ERR_NO_CONVERGENCE
        raw = 0.0
        for d in range(m):
            raw = max(raw, abs(dS[d]))
        if raw <= 1e-13 * L0:
            for d in range(m):
                S[d + 1] += dS[d]
            _assemble(S, L, phi, EA, L0, kinds, P, modes, targets, R, A, RL, Rphi, T, dT_dl0, de_dl0, e)
            return 0
        # sliding latches: the first equilibrium in the direction of motion (Stohlman & Pellegrino, Sec. II.B.2).
        # Per device a bracket [back, front] along the motion: back = the furthest point where the
        # device is still pushed, front = the nearest where it is pushed back; Newton steps are kept
        # inside it and below one grid cell, else a cell forward (front unknown) or bisection.
        fixed = False
        for d in range(m):
            mode = modes[d]
            if mode == SLIP_OUT or mode == SLIP_IN:
                h = max_step(kinds[d], S[d + 1], P[d])
                if h == math.inf:
                    continue
                dirS = -float(mode)
                # the latest evaluation wins: the other devices' motion can make older ends stale
                if mode * R[d] > 0.0:
                    back[d] = S[d + 1]
                    if has_front[d] and (front[d] - S[d + 1]) * dirS <= 1e-6 * h:
                        has_front[d] = False  # (a front this close was left by the others' motion)
                elif (S[d + 1] - start[d]) * dirS > 0.0:
                    front[d] = S[d + 1]  # (at its start a device not pushed is left to Newton)
                    has_front[d] = True
                    if (S[d + 1] - back[d]) * dirS <= 1e-6 * h:
                        back[d] = start[d]
                xn = S[d + 1] + dS[d]
                ok = abs(dS[d]) <= h and (xn - back[d]) * dirS > 0.0
                if has_front[d]:
                    ok = ok and (front[d] - xn) * dirS > 0.0
                if not ok:
                    if has_front[d] and abs(front[d] - back[d]) <= 2.0 * h:
                        xn = 0.5 * (back[d] + front[d])
                    else:
                        xn = back[d] + dirS * h
                        if has_front[d] and (xn - front[d]) * dirS >= 0.0:
                            xn = 0.5 * (back[d] + front[d])
                    # a constrained Newton step: this device moves by xn - S, the others follow
                    for j in range(m):
                        A[d, j] = 0.0
                    A[d, d] = 1.0
                    rhs[d] = xn - S[d + 1]
                    fixed = True
        if fixed and not _solve_small(A, rhs, dS):
            return 1000 + ERR_NO_CONVERGENCE
        # no unstretched length may lose more than 90 % in one step
        alpha = 1.0
        for i in range(n):
            l0 = S[i + 1] - S[i]
            dl = (dS[i] if i < m else 0.0) - (dS[i - 1] if i >= 1 else 0.0)
            if dl < -0.9 * l0:
                alpha = min(alpha, 0.9 * l0 / (-dl))
        for d in range(m):
            S_prev[d] = S[d + 1]
            step_prev[d] = alpha * dS[d]
            S[d + 1] += alpha * dS[d]
            if modes[d] == SLIP_IN and S[d + 1] > smax[d]:
                S[d + 1] = smax[d]  # the next iteration decides whether it stays at the stop
        for i in range(n):
            if not S[i + 1] - S[i] > 0.0:
                return 1000 + ERR_SHORT
    return 1000 + ERR_NO_CONVERGENCE


@njit(cache=True)
def _relax(S, L, phi, EA, L0, kinds, P, modes, targets, smax, bufs):
    """Pseudo-transient continuation of the device equations (the fallback of :func:`_newton` when
    several devices slide at once): each sliding device moves with the flow ``dS/dtau = -c r(S)``
    (its unbalanced force pushes it along its direction), integrated by implicit Euler steps

        r_d(S) + (D_d / beta) (S_d - S_d^k) = 0   (sliding d),   the other rows as in _newton,

    D_d = EA / l0_in + EA / l0_out, with beta growing x4 after a step and shrinking /4 after a failed
    one or a step that takes a sliding latch more than one grid cell (:func:`max_step`).  Implicit
    Euler does not pass a stable root of the flow, so the march stops at the first equilibrium the
    coupled devices meet, as the grid march of the single-latch element.  Same return codes."""
    R, A, RL, Rphi, T, dT_dl0, de_dl0, e, dS = bufs
    n = L.shape[0]
    m = n - 1
    Sk = np.empty(m)
    Dd = np.zeros(m)
    rhs = np.empty(m)
    beta = 0.25
    for _outer in range(400):
        for d in range(m):
            Sk[d] = S[d + 1]
        _assemble(S, L, phi, EA, L0, kinds, P, modes, targets, R, A, RL, Rphi, T, dT_dl0, de_dl0, e)
        sliding = False
        for d in range(m):
            if modes[d] == SLIP_OUT or modes[d] == SLIP_IN:
                sliding = True
                Dd[d] = EA / (S[d + 1] - S[d]) + EA / (S[d + 2] - S[d + 1])
        if not sliding:
            return 1000 + ERR_NO_CONVERGENCE
        ok = False
        for _inner in range(40):
            _assemble(S, L, phi, EA, L0, kinds, P, modes, targets, R, A, RL, Rphi, T, dT_dl0, de_dl0, e)
            for d in range(m):
                rhs[d] = -R[d]
                if modes[d] == SLIP_OUT or modes[d] == SLIP_IN:
                    rhs[d] -= Dd[d] / beta * (S[d + 1] - Sk[d])
                    A[d, d] += Dd[d] / beta
            if not _solve_small(A, rhs, dS):
                break
            alpha = 1.0
            for i in range(n):
                l0 = S[i + 1] - S[i]
                dl = (dS[i] if i < m else 0.0) - (dS[i - 1] if i >= 1 else 0.0)
                if dl < -0.9 * l0:
                    alpha = min(alpha, 0.9 * l0 / (-dl))
            raw = 0.0
            for d in range(m):
                S[d + 1] += alpha * dS[d]
                raw = max(raw, abs(dS[d]))
            if raw <= 1e-13 * L0:
                ok = True
                break
        # a step that crosses more than one cell of a sliding latch, or leaves a stop, is too long
        if ok:
            for d in range(m):
                if modes[d] == SLIP_OUT or modes[d] == SLIP_IN:
                    if abs(S[d + 1] - Sk[d]) > max_step(kinds[d], Sk[d], P[d]):
                        ok = False
                    if modes[d] == SLIP_IN and S[d + 1] > smax[d] * (1.0 + 1e-14):
                        ok = False
        if not ok:
            for d in range(m):
                S[d + 1] = Sk[d]
            beta *= 0.25
            if beta < 1e-14:
                return 1000 + ERR_NO_CONVERGENCE
            continue
        # an accepted step: a device at its stop and still pushed stays there
        _assemble(S, L, phi, EA, L0, kinds, P, modes, targets, R, A, RL, Rphi, T, dT_dl0, de_dl0, e)
        for d in range(m):
            if modes[d] == SLIP_IN and S[d + 1] >= smax[d] * (1.0 - 1e-14) and -R[d] > 0.0:
                modes[d] = STOP
                targets[d] = smax[d]
                S[d + 1] = smax[d]
        # converged when a plain Newton step is round-off
        moved = 0.0
        for d in range(m):
            moved = max(moved, abs(S[d + 1] - Sk[d]))
        if beta >= 1e8 and moved <= 1e-12 * L0:
            _assemble(S, L, phi, EA, L0, kinds, P, modes, targets, R, A, RL, Rphi, T, dT_dl0, de_dl0, e)
            for d in range(m):
                rhs[d] = -R[d]
            if _solve_small(A, rhs, dS):
                raw = 0.0
                for d in range(m):
                    raw = max(raw, abs(dS[d]))
                if raw <= 1e-12 * L0:
                    for d in range(m):
                        S[d + 1] += dS[d]
                    _assemble(S, L, phi, EA, L0, kinds, P, modes, targets, R, A, RL, Rphi, T, dT_dl0, de_dl0, e)
                    return 0
            else:
                return 0  # a flat residual (a slack device): the flow has stopped
        beta = min(beta * 4.0, 1e12)
    return 1000 + ERR_NO_CONVERGENCE


@njit(cache=True)
def solve_devices(L, phi, EA, L0, kinds, P, S_c, modes_c, S, modes, bufs):
    """Active-set return mapping of one cable (module note).  S (n+1,) and modes (n-1,) are
    outputs (S[0] = 0, S[n] = L0).  Returns an error code (ERR_*)."""
    n = L.shape[0]
    m = n - 1
    R, A, RL, Rphi, T, dT_dl0, de_dl0, e, dS = bufs
    targets = np.empty(m)
    smax = np.empty(m)
    S[0] = 0.0
    S[n] = L0
    for d in range(m):
        S[d + 1] = S_c[d]
        targets[d] = S_c[d]
        smax[d] = s_max_of(kinds[d], P[d])
        if kinds[d] == FREE:
            modes[d] = SLIDE_FREE
        elif kinds[d] != CLAMP and S_c[d] >= smax[d] - 1e-12 * L0:
            modes[d] = STOP
        else:
            modes[d] = STICK
    tol_s = 1e-12 * L0
    S_start = np.empty(n + 1)
    modes_start = np.empty(m, dtype=np.int64)
    for _it in range(MAX_SET):
        for d in range(m):  # sliding devices start from the last solution
            if modes[d] == STICK:
                S[d + 1] = S_c[d]
                targets[d] = S_c[d]
            elif modes[d] == STOP:
                S[d + 1] = targets[d]
        S_start[:] = S
        modes_start[:] = modes[:m]
        code = _newton(S, L, phi, EA, L0, kinds, P, modes, targets, smax, bufs)
        if code == 1000 + ERR_NO_CONVERGENCE:  # several devices sliding at once: the continuation
            S[:] = S_start
            modes[:m] = modes_start
            code = _relax(S, L, phi, EA, L0, kinds, P, modes, targets, smax, bufs)
        if code < 0:
            modes[-code - 1] = STICK  # both sides slack: nothing drives the device
            continue
        if code > 0:
            return code - 1000
        Tmax = 0.0
        for i in range(n):
            Tmax = max(Tmax, T[i])
        tol_f = 1e-11 * Tmax
        # sliding devices moving against their direction stick again
        changed = False
        for d in range(m):
            if modes[d] == SLIP_OUT and S[d + 1] > S_c[d] + tol_s:
                modes[d] = STICK
                changed = True
            elif modes[d] == SLIP_IN and S[d + 1] < S_c[d] - tol_s:
                modes[d] = STICK
                changed = True
        if changed:
            continue
        # the most violated static band starts sliding
        worst = 0.0
        wd = -1
        wmode = STICK
        for d in range(m):
            if modes[d] != STICK and modes[d] != STOP:
                continue
            if kinds[d] == CLAMP or kinds[d] == FREE:
                continue
            # static friction for a device at rest; one that slid in the last increment goes on at
            # the kinetic law in its direction (it sticks again on arrest or reversal)
            rp = _law(kinds[d], 1.0, T[d], T[d + 1], S[d + 1], phi[d], P[d], modes_c[d] != SLIP_OUT)[0]
            if rp > tol_f and rp > worst:
                worst = rp
                wd = d
                wmode = SLIP_OUT
            if modes[d] == STOP:
                continue  # the stop holds any pull from the in side
            rm = _law(kinds[d], -1.0, T[d], T[d + 1], S[d + 1], phi[d], P[d], modes_c[d] != SLIP_IN)[0]
            if rm < -tol_f and -rm > worst:
                worst = -rm
                wd = d
                wmode = SLIP_IN
        if wd < 0:
            return ERR_NONE
        modes[wd] = wmode
    return ERR_ACTIVE_SET


@njit(cache=True)
def device_kernel(X, radius, EA, L0, kinds, P, state, f, K, state_new, T_out, phi_out, energy, err, where):
    """All elements of a family: nodal forces f (n_el, 6 nn), tangent K, trial state, tensions.

    X (n_el, nn, 3) m; radius (nn,) m; EA (N), L0 (m) per element; kinds (n-1,); P (n_el, n-1,
    N_PARAM); state (n_el, 2 (n-1)) committed [S_1..S_{n-1}, mode_1..mode_{n-1}] (read only).
    err / where: error code and the node, section or device it concerns."""
    n_el = X.shape[0]
    nn = X.shape[1]
    n = nn - 1
    m = n - 1
    L = np.empty(n)
    G = np.empty((n, 3 * nn))
    H = np.empty((n, 3 * nn, 3 * nn))
    phi = np.empty(max(m, 1))
    dphi = np.empty((max(m, 1), 3 * nn))
    S = np.empty(n + 1)
    modes = np.empty(max(m, 1), dtype=np.int64)
    modes_c = np.empty(max(m, 1), dtype=np.int64)
    bufs = (
        np.empty(m),
        np.empty((m, m)),
        np.empty((m, n)),
        np.empty(m),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(m),
    )
    R, A, RL, Rphi, T, dT_dl0, de_dl0, e, dS = bufs
    dTdx = np.empty((n, 3 * nn))
    for el in range(n_el):
        err[el] = ERR_NONE
        where[el] = -1
        for a in range(6 * nn):
            f[el, a] = 0.0
            for b in range(6 * nn):
                K[el, a, b] = 0.0
        for c in range(state.shape[1]):
            state_new[el, c] = state[el, c]
        code, w = cable_geometry(X[el], radius, True, L, G, H, phi, dphi)
        if code != GEO_OK:
            err[el] = code
            where[el] = w
            continue
        for d in range(m):
            modes_c[d] = int(state[el, m + d])
        code = solve_devices(L, phi, EA[el], L0[el], kinds, P[el], state[el, :m], modes_c, S, modes, bufs)
        if code != ERR_NONE:
            err[el] = code
            continue
        # final residual derivatives at the converged set (also refreshes T, dT_dl0)
        targets = np.empty(m)
        for d in range(m):
            targets[d] = S[d + 1]
        _assemble(S, L, phi[:m], EA[el], L0[el], kinds, P[el], modes, targets, R, A, RL, Rphi, T, dT_dl0, de_dl0, e)
        for d in range(m):
            state_new[el, d] = S[d + 1]
            state_new[el, m + d] = modes[d]
            phi_out[el, d] = phi[d]
        en = 0.0
        for i in range(n):
            T_out[el, i] = T[i]
            if T[i] > 0.0:
                l0 = S[i + 1] - S[i]
                en += 0.5 * EA[el] * (L[i] - l0) ** 2 / l0
        for d in range(m):
            if kinds[d] == LATCH:
                p = P[el, d]
                dlt = latch_opening_scalar(p[6] - S[d + 1], p[0], p[4], p[5])
                en += p[2] * dlt * dlt
        energy[el] = en
        cable_forces_and_tangent(S, G, H, dphi, A, RL, Rphi, T, dT_dl0, EA[el], f[el], K[el], dTdx)
