"""Cyclic connection tests from the Bouc-Wen-Baber-Noori (BWBN) model (numpy only).

A smooth differential model of pinched, degrading hysteresis (Baber & Noori 1985; Foliente 1995
for timber joints), written here from its textbook equations.  It shares no functional form with
femast's connection effects (a gap with friction, a damage on the effective load): pinching is a
*slip-lock* function that lowers the hysteretic tangent near a level of ``z``, and degradation is
three energy-dependent coefficients.

Driven by the displacement ``u`` (m), the connection's force (N) is

    F = alpha k0 u + (1 - alpha) k0 z
    dz/du = h(z) / eta * (A - nu |z|^n (beta sign(z du) + gamma))
    de/du = z                                    (e: hysteretic energy per (1 - alpha) k0, m^2)
    A = 1 - dA e,  nu = 1 + dnu e,  eta = 1 + deta e          (strength and stiffness degradation)
    h(z) = 1 - zeta1 exp(-(z sign(du) - q z_u)^2 / zeta2^2)     (pinching, the slip-lock)
    zeta1 = zeta_s (1 - exp(-p e)),  zeta2 = (psi + dpsi e)(lam + zeta1),  z_u = (A / (nu (beta + gamma)))^(1/n)

``z`` has the unit of ``u``; ``beta + gamma`` is 1 / (yield displacement) for ``n = 1``.
Closed forms (``tests/experiments/test_connection_generator.py``): with no pinching or
degradation and ``n = 1``, a monotone stroke from rest gives ``z = (1 - exp(-c u)) / c`` and
``e = (u - z) / c`` (``c = beta + gamma``); the pinched tangent at ``z = q z_u`` is ``1 - zeta_s``
times the unpinched one once ``p e >> 1``; the tangent through ``z = 0`` is ``A / eta``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class BWBN:
    """Parameters of the BWBN connection (defaults: no pinching, no degradation, n = 1)."""

    k0: float = 2.0e6  # N/m, initial stiffness
    alpha: float = 0.05  # post-yield stiffness share
    beta: float = 250.0  # 1/m
    gamma: float = 150.0  # 1/m
    n: float = 1.0
    dA: float = 0.0  # 1/m^2
    dnu: float = 0.0  # 1/m^2
    deta: float = 0.0  # 1/m^2
    zeta_s: float = 0.0  # pinching severity in [0, 1)
    p: float = 0.0  # 1/m^2, rate at which pinching develops with the energy
    q: float = 0.1  # level of z (share of z_u) where the slip-lock acts
    psi: float = 0.2e-3  # m, width of the pinched zone
    dpsi: float = 0.0  # 1/m
    lam: float = 0.5  # coupling of width and severity


def _rates(z, e, s, c: BWBN):
    """dz/du and de/du at (z, e) for the direction s = sign(du)."""
    A = 1.0 - c.dA * e
    nu = 1.0 + c.dnu * e
    eta = 1.0 + c.deta * e
    az = abs(z)
    core = A - nu * az**c.n * (c.beta * np.sign(z * s) + c.gamma)
    h = 1.0
    if c.zeta_s > 0.0:
        zeta1 = c.zeta_s * -np.expm1(-c.p * e)
        zeta2 = (c.psi + c.dpsi * e) * (c.lam + zeta1)
        z_u = (max(A, 1e-12) / (nu * (c.beta + c.gamma))) ** (1.0 / c.n)
        h = 1.0 - zeta1 * np.exp(-(((z * s - c.q * z_u) / zeta2) ** 2))
    return h / eta * core, z


def bwbn_driven(u, c: BWBN, substeps: int = 20, state: bool = False):
    """Force (N) of the BWBN connection along the displacement path ``u`` (m), from rest (z = e = 0).

    Each row-to-row step is integrated with ``substeps`` classical Runge-Kutta steps in ``u``.  With
    ``state=True`` also returns ``z`` and ``e`` at the rows."""
    u = np.asarray(u, dtype=float)
    z = e = 0.0
    Z = np.zeros_like(u)
    E = np.zeros_like(u)
    for i in range(1, u.size):
        du = u[i] - u[i - 1]
        if du == 0.0:
            Z[i], E[i] = z, e
            continue
        s = 1.0 if du > 0 else -1.0
        h = du / substeps
        for _ in range(substeps):
            k1z, k1e = _rates(z, e, s, c)
            k2z, k2e = _rates(z + 0.5 * h * k1z, e + 0.5 * h * k1e, s, c)
            k3z, k3e = _rates(z + 0.5 * h * k2z, e + 0.5 * h * k2e, s, c)
            k4z, k4e = _rates(z + h * k3z, e + h * k3e, s, c)
            z += h / 6.0 * (k1z + 2 * k2z + 2 * k3z + k4z)
            e += h / 6.0 * (k1e + 2 * k2e + 2 * k3e + k4e)
        Z[i], E[i] = z, e
    F = c.alpha * c.k0 * u + (1.0 - c.alpha) * c.k0 * Z
    return (F, Z, E) if state else F


def cyclic_protocol(amplitudes, trailing: int = 2, trailing_share: float = 0.75, step: float = 1e-4):
    """A cyclic protocol of connection tests (in the unit of ``amplitudes``: m, or N for a force
    protocol): for each amplitude a primary cycle, then ``trailing`` cycles at ``trailing_share`` of
    it (the CUREE protocol's shape); rows about ``step`` apart along the path.  Returns the path and
    the index of the cycle of each row."""
    peaks, cyc = [], []
    k = 0
    for a in amplitudes:
        for amp in [a] + [trailing_share * a] * trailing:
            peaks += [amp, -amp, 0.0]
            cyc += [k, k, k]
            k += 1
    path = [np.zeros(1)]
    cycle = [np.zeros(1, dtype=int)]
    last = 0.0
    for p, g in zip(peaks, cyc):
        m = max(2, int(np.ceil(abs(p - last) / step)))
        path.append(np.linspace(last, p, m + 1)[1:])
        cycle.append(np.full(m, g))
        last = p
    return np.concatenate(path), np.concatenate(cycle)
