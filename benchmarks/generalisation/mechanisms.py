"""Mechanisms of joints, contacts and cables, written from the textbook models (numpy only).

Every function is independent of femast's effect library (different functional forms on
purpose; see the package docstring).  Units follow the caller: a friction operator driven by a
rotation (rad) returns a moment (N m) when its force scale is in N m, driven by a position (m)
it returns a force (N).  Symbols: ``u`` the kinematic driver (rotation or position), ``F`` the
friction force or moment, ``s = sign(du)`` the direction of motion.

Friction (rate-independent hysteresis)
--------------------------------------
* Dahl (1968): ``dF/du = sigma |1 - s F/F_c|^alpha sign(1 - s F/F_c)``; for ``alpha = 1`` a
  monotone stroke from ``F0`` gives ``F = s F_c + (F0 - s F_c) exp(-sigma |du| / F_c)``.
* Bouc-Wen (Wen 1976): ``F = F_y z``, ``dz/du = (1 - |z|^n (beta sign(s z) + gamma)) / u_y``;
  with ``beta + gamma = 1`` ``|z| <= 1``; ``n = 1, beta = gamma = 1/2`` is the Dahl law with
  ``sigma = F_y / u_y``; ``n -> inf`` is the elastic-perfectly-plastic (Jenkins) element.
* Jenkins (elasto-slip): a spring ``k_s`` in series with a Coulomb slider of strength ``F_s``;
  ``F = clip(F + k_s du, -F_s, F_s)``.  A symmetric cycle of amplitude ``u_a > F_s / k_s``
  dissipates ``4 F_s (u_a - F_s / k_s)`` per cycle (the loop area).

Each operator can be driven by the kinematics (``*_driven``: ``F(u)``) or, in parallel with a
linear spring ``k``, by the load (``*_load_controlled``: solve ``m = k u + F(u)`` for ``u``
along a history ``m``), which is how a joint sees it under a prescribed wrench.
"""

from __future__ import annotations

import numpy as np


# --------------------------------------------------------------------------- smooth operators
def dahl_tangent(F_c: float, sigma: float, alpha: float = 1.0):
    """Tangent ``dF/du (F, s)`` of the Dahl model (force scale F_c, initial stiffness sigma)."""

    def g(F, s):
        a = 1.0 - s * F / F_c
        return sigma * np.copysign(abs(a) ** alpha, a)

    return g


def bouc_wen_tangent(F_y: float, u_y: float, n: float = 1.0, beta: float = 0.5, gamma: float = 0.5):
    """Tangent ``dF/du (F, s)`` of the Bouc-Wen model with ``F = F_y z`` (yield force F_y, yield
    displacement u_y, sharpness n; beta + gamma = 1 bounds |F| by F_y)."""

    def g(F, s):
        z = F / F_y
        sz = s * z
        return (F_y / u_y) * (1.0 - abs(z) ** n * ((beta if sz > 0 else -beta if sz < 0 else 0.0) + gamma))

    return g


def _rk4(state, h, f):
    k1 = f(state)
    k2 = f(state + 0.5 * h * k1)
    k3 = f(state + 0.5 * h * k2)
    k4 = f(state + h * k3)
    return state + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)


def smooth_driven(u, tangent, F0: float = 0.0, substeps: int = 40) -> np.ndarray:
    """Friction force along a kinematic history ``u`` (n,) for a smooth operator ``tangent``
    (``dahl_tangent`` or ``bouc_wen_tangent``), RK4 with ``substeps`` steps per sample."""
    u = np.asarray(u, float)
    F = np.empty_like(u)
    f = float(F0)
    F[0] = f
    for i in range(1, u.size):
        du = float(u[i] - u[i - 1])
        if du != 0.0:
            s = 1.0 if du > 0 else -1.0
            h = du / substeps
            for _ in range(substeps):
                f = _rk4(f, h, lambda y: float(tangent(y, s)))
        F[i] = f
    return F


def smooth_load_controlled(m, k: float, tangent, substeps: int = 40):
    """Solve ``m = k u + F(u)`` along a load history ``m`` (n,) for a smooth friction operator in
    parallel with a spring ``k``; returns ``(u, F)``.  Starts from ``u = F = 0`` at ``m[0] = 0``
    (or ``u = m[0] / k``).  Integrates ``dF/dm = g / (k + g)`` (RK4), ``u = (m - F) / k``."""
    m = np.asarray(m, float)
    F = np.empty_like(m)
    f = 0.0
    F[0] = f
    for i in range(1, m.size):
        dm = float(m[i] - m[i - 1])
        if dm != 0.0:
            s = 1.0 if dm > 0 else -1.0

            def rhs(y, s=s):
                g = float(tangent(y, s))
                return g / (k + g)

            h = dm / substeps
            for _ in range(substeps):
                f = _rk4(f, h, rhs)
        F[i] = f
    return (m - F) / k, F


# --------------------------------------------------------------------------- Jenkins element
def jenkins_driven(u, k_s: float, F_s: float, F0: float = 0.0) -> np.ndarray:
    """Elasto-slip element (spring k_s in series with a slider F_s) along a kinematic history."""
    u = np.asarray(u, float)
    F = np.empty_like(u)
    f = float(F0)
    F[0] = f
    for i in range(1, u.size):
        f = float(np.clip(f + k_s * (u[i] - u[i - 1]), -F_s, F_s))
        F[i] = f
    return F


def jenkins_load_controlled(m, k: float, k_s: float, F_s: float):
    """Solve ``m = k u + F_jenkins(u)`` exactly along a load history (stick: stiffness k + k_s,
    slip: k); returns ``(u, F)``."""
    m = np.asarray(m, float)
    u = np.empty_like(m)
    F = np.empty_like(m)
    uu, f = m[0] / k, 0.0
    u[0], F[0] = uu, f
    for i in range(1, m.size):
        dm = m[i] - m[i - 1]
        s = np.sign(dm)
        du = dm / (k + k_s)  # trial: stick
        if abs(f + k_s * du) > F_s:  # stick until the slider reaches s F_s, then slip
            du1 = (s * F_s - f) / k_s
            du = du1 + (dm - (k + k_s) * du1) / k
            f = s * F_s
        else:
            f = f + k_s * du
        uu += du
        u[i], F[i] = uu, f
    return u, F


# --------------------------------------------------------------------------- clearance laws
def clearance_tanh(m, c: float, m0: float) -> np.ndarray:
    """Smooth clearance: extra rotation ``c tanh(m / m0)`` (c the half play, m0 the closing scale)."""
    return c * np.tanh(np.asarray(m, float) / m0)


def clearance_piecewise(m, c: float, k0: float, k1: float) -> np.ndarray:
    """Piecewise-linear contact: a soft spring k0 across the play |phi| <= c, then contact
    stiffness k1: ``m = k0 phi`` inside, ``m = sign(phi) (k0 c + k1 (|phi| - c))`` outside; returns phi."""
    m = np.asarray(m, float)
    a = np.abs(m)
    phi = np.where(a <= k0 * c, a / k0, c + (a - k0 * c) / k1)
    return np.sign(m) * phi


def clearance_hertz(m, c: float, k0: float, K: float, p: float = 1.5, iters: int = 80) -> np.ndarray:
    """Power-law (Hertz, p = 3/2) contact after a play: ``m = k0 phi + K <|phi| - c>^p sign(phi)``;
    returns phi by bisection (the law is strictly increasing)."""
    m = np.asarray(m, float)
    a = np.abs(m)
    lo = np.zeros_like(a)
    hi = a / k0  # k0 phi alone reaches |m| there, so the root is below
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        val = k0 * mid + K * np.maximum(mid - c, 0.0) ** p
        lo = np.where(val < a, mid, lo)
        hi = np.where(val < a, hi, mid)
    return np.sign(m) * 0.5 * (lo + hi)


# --------------------------------------------------------------------------- stiffening laws
def duffing_rotation(m, k: float, k3: float) -> np.ndarray:
    """Real root of the hardening spring ``m = k u + k3 u^3`` (Cardano, k, k3 > 0)."""
    m = np.asarray(m, float)
    p = k / (3.0 * k3)
    q = m / (2.0 * k3)
    d = np.sqrt(q * q + p**3)
    return np.cbrt(q + d) + np.cbrt(q - d)


def asinh_rotation(m, k: float, m0: float) -> np.ndarray:
    """Spring whose tangent stiffness grows with the load, ``dm/du = k sqrt(1 + (m/m0)^2)``:
    ``u = (m0 / k) asinh(m / m0)``."""
    return (m0 / k) * np.arcsinh(np.asarray(m, float) / m0)


# --------------------------------------------------------------------------- zero-closing loops
def running_peak(y) -> np.ndarray:
    """Largest |y| since the last change of sign of y (the peak of the current excursion)."""
    y = np.asarray(y, float)
    P = np.empty_like(y)
    p, sgn = 0.0, 0.0
    for i, v in enumerate(y):
        sv = np.sign(v)
        if sv != 0 and sv != sgn:
            p, sgn = 0.0, sv
        p = max(p, abs(v))
        P[i] = p
    return P


def loop_quadratic(y, eps: float) -> np.ndarray:
    """Cable loop that closes at zero load: on the way back from the excursion peak P the
    response is ``y + eps y (1 - |y|/P)`` (loading follows y).  Loop area for 0 -> P -> 0 in the
    (response, y) plane: ``eps P^2 / 6``."""
    y = np.asarray(y, float)
    P = np.maximum(running_peak(y), 1e-300)
    return y + eps * y * (1.0 - np.abs(y) / P)


def loop_power(y, eps: float) -> np.ndarray:
    """Cable loop with a power-law return branch: ``P (|y|/P)^(1/(1 + eps)) sign(y)`` below the
    excursion peak P (loading follows y); closes at zero and at the peak."""
    y = np.asarray(y, float)
    P = np.maximum(running_peak(y), 1e-300)
    return np.sign(y) * P * (np.abs(y) / P) ** (1.0 / (1.0 + eps))


# --------------------------------------------------------------------------- fades and drifts
def fade(s, ell: float, form: str) -> np.ndarray:
    """Fade of a band with the distance ``s >= 0`` from where it is full (1 at s = 0):
    ``gauss`` exp(-(s/ell)^2), ``linear`` max(0, 1 - s/ell), ``lorentz`` 1/(1 + (s/ell)^2)."""
    s = np.maximum(np.asarray(s, float), 0.0) / ell
    if form == "gauss":
        return np.exp(-s * s)
    if form == "linear":
        return np.maximum(1.0 - s, 0.0)
    if form == "lorentz":
        return 1.0 / (1.0 + s * s)
    raise ValueError(f"unknown fade form {form!r}; use gauss, linear or lorentz")


def compliance_drift(tau, lam: float, form: str, tau0: float = 0.3, width: float = 0.03) -> np.ndarray:
    """Factor on a compliance along normalised time tau in [0, 1] (a pretension lost during the
    test): ``exp`` 1 + lam (1 - exp(-tau/tau0)) (creep relaxation), ``step`` 1 + lam / (1 +
    exp(-(tau - 0.5)/width)) (a shroud slips in its grip half-way)."""
    tau = np.asarray(tau, float)
    if form == "exp":
        return 1.0 + lam * (1.0 - np.exp(-tau / tau0))
    if form == "step":
        return 1.0 + lam / (1.0 + np.exp(-(tau - 0.5) / width))
    raise ValueError(f"unknown drift form {form!r}; use exp or step")


def cantilever_compliance(L: float, sections, shear_GA: float | None = None):
    """Tip compliances of a cantilever of length L (m) made of ``sections`` = [(length m, EI N m^2),
    ...] from the root: ``(c_f, c_m)`` with tip translation ``c_f f`` under a tip force (m/N) and
    ``c_m m`` under a tip moment (m/(N m)), by the unit-load method
    ``c_f = int (L - s)^2 / EI ds``, ``c_m = int (L - s) / EI ds``; ``shear_GA`` (N) adds the
    Timoshenko shear compliance ``L / GA`` to c_f."""
    c_f = c_m = 0.0
    s0 = 0.0
    for length, EI in sections:
        s1 = s0 + length
        c_f += ((L - s0) ** 3 - (L - s1) ** 3) / (3.0 * EI)
        c_m += ((L - s0) ** 2 - (L - s1) ** 2) / (2.0 * EI)
        s0 = s1
    if abs(s0 - L) > 1e-9 * L:
        raise ValueError(f"sections add up to {s0} m, not the length {L} m")
    if shear_GA:
        c_f += L / shear_GA
    return c_f, c_m


# --------------------------------------------------------------------------- guys, relays, creep
def slack_guys_rotation(m, k: float, k_g: float, theta_s: float, sides: int = 2) -> np.ndarray:
    """A joint of stiffness k braced by guys, each slack by the rotation ``theta_s``: one guy per side
    (``sides`` 2), or one guy only, on the side of positive rotation (``sides`` 1).  A guy pulls once
    the joint has turned past its slack: ``m = k u + k_g <|u| - theta_s>`` on a braced side, so
    ``u = m / k`` while ``|m| <= k theta_s``, else ``sign(m) (|m| + k_g theta_s) / (k + k_g)``."""
    m = np.asarray(m, float)
    a = np.abs(m)
    braced = np.where(a <= k * theta_s, m / k, np.sign(m) * (a + k_g * theta_s) / (k + k_g))
    return braced if sides == 2 else np.where(m > 0, braced, m / k)


def preisach_relays(alpha, beta, weights, u) -> np.ndarray:
    """Preisach operator: the weighted sum of relays along the input history ``u`` (n,).

    Relay j switches to +1 when ``u >= alpha_j`` and to -1 when ``u <= beta_j`` (``alpha_j >=
    beta_j``), and keeps its state in between; it starts at -1 if ``alpha_j + beta_j > 0``, else +1
    (the demagnetised state: zero output for a symmetric density).  Returns ``sum_j w_j r_j(t)``."""
    alpha, beta, w = (np.asarray(v, float) for v in (alpha, beta, weights))
    if np.any(alpha < beta):
        raise ValueError("a Preisach relay needs alpha >= beta")
    r = np.where(alpha + beta > 0, -1.0, 1.0)
    out = np.empty(len(u))
    for i, x in enumerate(np.asarray(u, float)):
        r = np.where(x >= alpha, 1.0, np.where(x <= beta, -1.0, r))
        out[i] = w @ r
    return out


def preisach_joint_rotation(m, k: float, c: float, M_max: float, n: int = 24) -> np.ndarray:
    """A joint whose micro-contacts slip by jumps: ``u = m / k + c P(m)`` with the Preisach operator
    P of relays on a grid of the triangle ``-M_max <= beta <= alpha <= M_max`` weighted by a
    Gaussian density of the half-width ``(alpha - beta) / 2`` (mean 0.35, sd 0.2 M_max) and of the
    bias ``(alpha + beta) / 2`` (sd 0.15 M_max); the weights sum to 1, so the slip spans +-c."""
    g = (np.arange(n) + 0.5) / n * 2.0 * M_max - M_max
    A, B = np.meshgrid(g, g, indexing="ij")
    keep = A >= B
    A, B = A[keep], B[keep]
    half, bias = 0.5 * (A - B), 0.5 * (A + B)
    w = np.exp(-0.5 * ((half - 0.35 * M_max) / (0.2 * M_max)) ** 2 - 0.5 * (bias / (0.15 * M_max)) ** 2)
    w /= w.sum()
    return np.asarray(m, float) / k + c * preisach_relays(A, B, w, m)


def log_creep_rotation(m, t, k: float, phi: float, t0: float) -> np.ndarray:
    """Linear viscoelastic joint with the logarithmic creep compliance ``J(s) = (1 + phi ln(1 + s/t0)) / k``
    (s the time since a load change, t0 in s), by Boltzmann superposition of the load steps between
    samples: ``u_i = sum_{j <= i} (m_j - m_{j-1}) J(t_i - t_j)`` (m_{-1} = 0).  Under a load held
    from t = 0 the rotation grows as ``ln(1 + t/t0)``; under cycles it lags the load."""
    m = np.asarray(m, float)
    t = np.asarray(t, float)
    dm = np.diff(m, prepend=0.0)
    s = t[:, None] - t[None, :]
    J = np.where(s >= 0, 1.0 + phi * np.log1p(np.maximum(s, 0.0) / t0), 0.0) / k
    return J @ dm
