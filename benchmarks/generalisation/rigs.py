"""The two rigs of the benchmark, written from the papers (numpy only).

Mast top (the Rocaspect paper, Sec. III-A, Eqs. 4-7)
-----------------------------------------
A rigid mast of height L = 3.651 m on three elastic joints at its base O.  A wrench change
``(f, m_C)`` on the top C (forces N, moments N m about C, base frame) loads the joints with the
moment about O, ``M = m_C + r_OC x f`` (N m); a joint rotation ``theta`` (rad, about the base
axes) moves the top by ``theta x r_OC`` (m).  Bending joint stiffnesses 2.7e5 and 2.3e5 N m/rad
(the Rocaspect paper, Table III, 1200 N of shroud pretension); the torsion joint is rigid.  A mechanism
changes how a joint rotation follows its moment (``theta_j = g_j(M_j history)``), or adds a top
translation (beam, drift).

Latch pull test (Stohlman & Pellegrino, Sec. III, Eqs. 6-15)
-----------------------------------------------
Roller latch law (Eqs. 6-14), ``x`` the bead position (m, positive outside, backstop at
``-x_b``), ``delta = sqrt((r + R)^2 - x^2) - h - r`` the roller opening (contact while > 0),
``y = h + delta + r``::

    dT_in(x)  = -2 k delta (x + mu y) / (y - mu x)     latching   (dx < 0)
    dT_out(x) = -2 k delta (x - mu y) / (y + mu x)     unlatching (dx > 0)

with the paper's fit r = 1.1 mm, x_b = 2.0 mm, k = 100 N/mm, mu = 0.07, h = 1.5 mm, R = 2.4 mm.
The rig pulls with one cable at a time (Sec. III.B), so a latching pass cannot hold dT > 0 and an
unlatching pass cannot hold dT < 0 (the paper's text has the two the other way round; with the
signs of Eqs. 5 and 14 this is the physical reading).  A cycle: a hold on the backstop (pushed
in to -F_push, released, pulled to the breakaway force), unlatching out to x_max, latching back
to the backstop.
"""

from __future__ import annotations

import numpy as np

L_MAST = 3.651  # m, the Rocaspect paper, Sec. IV-B-2
K_JOINTS = (2.7e5, 2.3e5)  # N m/rad, the Rocaspect paper, Table III (1200 N)
LATCH = {"r": 1.1e-3, "xb": 2.0e-3, "k": 1e5, "mu": 0.07, "h": 1.5e-3, "R": 2.4e-3}  # Stohlman & Pellegrino, Sec. III.C


# =========================================================================== mast top
def joint_moments(wrench, L: float = L_MAST) -> np.ndarray:
    """Moments about the base O (n, 3) N m of wrench changes (n, 6) on a vertical mast's top."""
    w = np.asarray(wrench, float)
    r = np.array([0.0, 0.0, L])
    return w[:, 3:] + np.cross(r, w[:, :3])


def top_translation(theta, L: float = L_MAST) -> np.ndarray:
    """Translation (n, 3) m of the top for base rotations theta (n, 3) rad: ``theta x r_OC``."""
    return np.cross(np.asarray(theta, float), np.array([0.0, 0.0, L]))


def _ramps(peaks, n: int) -> np.ndarray:
    """Piecewise-linear history through ``peaks`` (k, d), starting and ending at 0, n samples
    spaced in proportion to the distance travelled."""
    pts = np.vstack([np.zeros((1, peaks.shape[1])), peaks, np.zeros((1, peaks.shape[1]))])
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    q = np.linspace(0.0, s[-1], n)
    return np.column_stack([np.interp(q, s, pts[:, j]) for j in range(pts.shape[1])])


def mast_path(kind: str, n: int, rng, amplitude_N: float = 10.0, dt_s: float = 0.5):
    """Wrench history (n, 6) and time (n,) s of a mast-top test.

    kind: ``cycles30`` horizontal force cycles at 30 deg to x through zero, amplitudes changing
    from cycle to cycle; ``biaxial`` excursions 0 -> peak -> 0 in changing directions; ``moments``
    force cycles plus independent top-moment cycles (so force and moment are not proportional);
    ``onesided`` pulls along 30 deg that never reverse the load; ``variable_rate`` the cycles30
    path with slow and fast cycles (time steps 2 s and 0.25 s); ``holds`` the cycles30 peaks with
    the load held as long as each ramp lasts at every peak and at zero (a creep test)."""
    ncyc = max(4, n // 60)
    amps = amplitude_N * rng.uniform(0.55, 1.0, ncyc)
    a30 = np.radians(30.0)
    if kind in ("cycles30", "variable_rate", "moments"):
        sgn = np.where(np.arange(ncyc) % 2 == 0, 1.0, -1.0)
        peaks = np.column_stack([sgn * amps * np.cos(a30), sgn * amps * np.sin(a30)])
        f = _ramps(peaks, n)
    elif kind == "biaxial":
        ang = rng.uniform(0, 2 * np.pi, ncyc)
        peaks = np.zeros((2 * ncyc - 1, 2))
        peaks[0::2] = np.column_stack([amps * np.cos(ang), amps * np.sin(ang)])
        f = _ramps(peaks, n)
    elif kind == "holds":  # cycles30 with the load held at every peak and at zero (a creep test)
        sgn = np.where(np.arange(ncyc) % 2 == 0, 1.0, -1.0)
        peaks = np.column_stack([sgn * amps * np.cos(a30), sgn * amps * np.sin(a30)])
        stops = [np.zeros(2)]
        for pk in peaks:
            stops += [pk, np.zeros(2)]
        seg = n // (2 * len(stops) - 1)  # a ramp and a hold per stop
        f = [np.zeros((seg, 2))]
        for a, b in zip(stops[:-1], stops[1:]):
            q = np.linspace(0.0, 1.0, seg + 1)[1:, None]
            f += [a + (b - a) * q, np.repeat(b[None], seg, axis=0)]
        f = np.vstack(f)
        f = np.vstack([f, np.zeros((n - len(f), 2))]) if len(f) < n else f[:n]
    elif kind == "onesided":
        peaks = np.zeros((2 * ncyc - 1, 2))
        peaks[0::2] = np.column_stack([amps * np.cos(a30), amps * np.sin(a30)])
        f = _ramps(peaks, n)
    else:
        raise ValueError(f"unknown mast path {kind!r}")
    w = np.zeros((n, 6))
    w[:, :2] = f
    w[:, 2] = -0.2 * np.hypot(f[:, 0], f[:, 1])  # the cables also pull the top down a little
    if kind == "moments":
        tau = np.linspace(0.0, 1.0, n)
        w[:, 3] = 0.5 * amplitude_N * np.sin(2 * np.pi * 5.3 * tau + 0.4)
        w[:, 4] = 0.5 * amplitude_N * np.sin(2 * np.pi * 3.1 * tau + 1.3)
    if kind == "variable_rate":
        block = (np.arange(n) * ncyc // n) % 2
        t = np.concatenate([[0.0], np.cumsum(np.where(block[1:] == 0, 2.0, 0.25))])
    else:
        t = dt_s * np.arange(n)
    return w, t


def viscous_joint(m, t, k: float, c: float) -> np.ndarray:
    """Kelvin-Voigt joint ``m = k u + c du/dt`` along a piecewise-linear moment history: exact
    update per step (a rate-dependent mechanism femast's library does not have)."""
    m = np.asarray(m, float)
    u = np.empty_like(m)
    u[0] = m[0] / k
    T = c / k
    for i in range(1, m.size):
        h = t[i] - t[i - 1]
        a = (m[i] - m[i - 1]) / h  # dm/dt on the step
        # u' = (m0 + a s - k u) / c  ->  particular u_p = (m0 + a s)/k - a T / k
        up0 = (m[i - 1] - a * T) / k
        u[i] = (m[i] - a * T) / k + (u[i - 1] - up0) * np.exp(-h / T)
    return u


# =========================================================================== latch pull
def roller_opening(x, p=LATCH) -> np.ndarray:
    """delta(x) (m) of Eq. 10 (negative: no contact)."""
    x = np.asarray(x, float)
    rr = (p["r"] + p["R"]) ** 2 - x * x
    return np.where(rr > 0, np.sqrt(np.maximum(rr, 0.0)), 0.0) - p["h"] - p["r"]


def latch_law(x, direction: int, p=LATCH) -> np.ndarray:
    """dT (N) of Eq. 14 at positions x (m): direction -1 latching (dT_in), +1 unlatching (dT_out);
    0 out of contact."""
    x = np.asarray(x, float)
    d = roller_opening(x, p)
    y = p["h"] + d + p["r"]
    mu, k = p["mu"], p["k"]
    if direction < 0:
        f = -2 * k * d * (x + mu * y) / (y - mu * x)
    else:
        f = -2 * k * d * (x - mu * y) / (y + mu * x)
    return np.where(d > 0, f, 0.0)


def latch_path(n: int, rng, x_max_m=(4.0e-3, 3.0e-3), push_N: float = 40.0, p=LATCH):
    """Bead path of a pull test: per cycle a hold on the backstop, unlatching to x_max, latching back.

    Returns ``segments``: a list of ``(kind, x (k,) m)`` with kind ``hold`` (bead on the backstop;
    the force program is set later), ``out`` or ``in``; about n samples in all, spread in
    proportion to a hold weight of 2 mm per hold and the distance moved."""
    xb = p["xb"]
    spans = []
    for xm in x_max_m:
        xm = xm * rng.uniform(0.95, 1.05)
        spans += [("hold", 2.0e-3, None), ("out", xm + xb, (-xb, xm)), ("in", xm + xb, (xm, -xb))]
    total = sum(s[1] for s in spans)
    segs = []
    for kind, length, ends in spans:
        k = max(8, int(round(n * length / total)))
        if kind == "hold":
            segs.append((kind, np.full(k, -xb)))
        elif kind == "out":  # starts on the backstop: the hold's pull ends at the breakaway dT_out(-x_b)
            segs.append((kind, np.linspace(ends[0], ends[1], k)))
        else:
            segs.append((kind, np.linspace(ends[0], ends[1], k + 1)[1:]))
    return segs


def hold_force(k: int, push_N: float, breakaway_N: float) -> np.ndarray:
    """Force program (N) of a hold on the backstop: 0 -> -push -> 0 -> breakaway (k samples)."""
    k1 = k // 2
    down = -push_N * np.sin(np.linspace(0.0, np.pi, k1, endpoint=False))
    up = np.linspace(0.0, breakaway_N, k - k1)
    return np.concatenate([down, up])
