"""Lee's frame and Williams' toggle: a high-accuracy planar elastica (shooting + pseudo-arclength
continuation) of extensible Euler-Bernoulli bars.

Part of :mod:`femast.verification.references` (written from theory, no femast code)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar

# =============================================================================
# 5b. Planar frames of extensible Euler-Bernoulli bars: shooting + continuation
# =============================================================================


@dataclass
class PlanarPath:
    """Equilibrium path of a planar frame.

    load : applied load P at each path point (positive in the nominal
        direction of the load, e.g. downward for Lee's frame).
    u, v : displacement of the monitored (loaded) point, u along +x and v
        along the load direction (positive = with the load).
    rotation : rotation of the section at the monitored point, rad,
        counter-clockwise positive.
    """

    load: np.ndarray
    u: np.ndarray
    v: np.ndarray
    rotation: np.ndarray
    info: dict = field(default_factory=dict)

    def distance(self, load, disp, load_scale: float, disp_scale: float, component: str = "v"):
        """Distance of points (disp, load), e.g. from an FE analysis, to this
        path, in the plane (disp/disp_scale, load/load_scale).

        The path may be multi-valued (snap-back), so points are compared with
        the nearest segment of the reference polyline, not interpolated at
        equal displacement.  ``component`` is 'v' or 'u'.  Returns an array of
        distances; e.g. ``max(distance) < 0.01`` with load_scale the limit
        load and disp_scale the displacement range is a 1 % path check.
        Accuracy is limited by the spacing of the path points (chord error).
        """
        d = getattr(self, component) / disp_scale
        p = self.load / load_scale
        A = np.stack((d[:-1], p[:-1]), axis=1)
        B = np.stack((d[1:], p[1:]), axis=1)
        AB = B - A
        L2 = np.maximum(np.einsum("ij,ij->i", AB, AB), 1e-300)
        pts = np.stack(
            (np.atleast_1d(np.asarray(disp, float)) / disp_scale, np.atleast_1d(np.asarray(load, float)) / load_scale),
            axis=1,
        )
        out = np.empty(len(pts))
        for n, X in enumerate(pts):
            t = np.clip(np.einsum("ij,ij->i", X - A, AB) / L2, 0.0, 1.0)
            out[n] = np.sqrt(np.min(np.sum((A + t[:, None] * AB - X) ** 2, axis=1)))
        return out


class _PlanarChain:
    """A chain of straight extensible Euler-Bernoulli bars, integrated along its
    arc length s in [0, Ltot] by the classical Runge-Kutta method.

    State (x, y, theta, M); Fa = sum of the external forces acting on [0, s]
    (start reaction + point loads passed).  With t = (cos theta, sin theta)::

        N = -Fa . t,  x' = (1 + N/EA) cos theta,  y' = (1 + N/EA) sin theta
        theta' = M/EI,  M' = x' Fa_y - y' Fa_x

    M(s) is the bending moment (counter-clockwise on the part [0, s]).
    Rigid joints add a jump to theta; point loads add to Fa.
    Start support 'pin' (M = 0, theta unknown) or 'clamp' (theta given,
    M unknown); end support 'pin' (x, y given, M = 0) or 'clamp' (x, y,
    theta given).  Unknowns q = (R_x, R_y, theta0 or M0).
    """

    def __init__(self, nodes, EI, EA, start, end, load_node, load_dir, h):
        self.nodes = [np.asarray(n, float) for n in nodes]
        self.EI, self.EA = float(EI), float(EA)
        self.start, self.end = start, end
        self.load_node = load_node
        self.load_dir = np.asarray(load_dir, float)
        seg = []
        for i in range(len(nodes) - 1):
            d = self.nodes[i + 1] - self.nodes[i]
            Ls = float(np.hypot(*d))
            seg.append((Ls, math.atan2(d[1], d[0]), max(2, int(math.ceil(Ls / h)))))
        self.seg = seg
        self.theta_start = seg[0][1]
        self.theta_end = seg[-1][1]

    def integrate(self, q, lam):
        """Return the end state (x, y, theta, M) and the state at the load node."""
        EI, EA = self.EI, self.EA
        Fx, Fy = float(q[0]), float(q[1])
        if self.start == "pin":
            th, M = self.theta_start + float(q[2]), 0.0
        else:
            th, M = self.theta_start, float(q[2])
        x, y = float(self.nodes[0][0]), float(self.nodes[0][1])
        at_load = None
        cos, sin = math.cos, math.sin
        for i, (Ls, ang, n) in enumerate(self.seg):
            if i > 0:
                th += ang - self.seg[i - 1][1]  # rigid joint keeps the angle between bars
            if i == self.load_node:
                at_load = (x, y, th, M)
                Fx += lam * self.load_dir[0]
                Fy += lam * self.load_dir[1]
            hs = Ls / n

            def f(th, M):
                c, s_ = cos(th), sin(th)
                e = 1.0 - (Fx * c + Fy * s_) / EA
                dx, dy = e * c, e * s_
                return dx, dy, M / EI, dx * Fy - dy * Fx

            for _ in range(n):
                k1 = f(th, M)
                k2 = f(th + 0.5 * hs * k1[2], M + 0.5 * hs * k1[3])
                k3 = f(th + 0.5 * hs * k2[2], M + 0.5 * hs * k2[3])
                k4 = f(th + hs * k3[2], M + hs * k3[3])
                x += hs / 6.0 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
                y += hs / 6.0 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
                th += hs / 6.0 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2])
                M += hs / 6.0 * (k1[3] + 2 * k2[3] + 2 * k3[3] + k4[3])
        if self.load_node == len(self.seg):
            at_load = (x, y, th, M)
        return (x, y, th, M), at_load

    def residual(self, q, lam, scale_F, scale_L):
        (x, y, th, M), _ = self.integrate(q, lam)
        xe, ye = self.nodes[-1]
        r3 = M / (scale_F * scale_L) if self.end == "pin" else th - self.theta_end
        return np.array([(x - xe) / scale_L, (y - ye) / scale_L, r3])

    def monitor(self, q, lam):
        _, (x, y, th, M) = self.integrate(q, lam)
        x0, y0 = self.nodes[self.load_node]
        i = min(self.load_node, len(self.seg) - 1)
        th0 = self.seg[i][1] if self.load_node < len(self.seg) else self.theta_end
        d = np.array([x - x0, y - y0])
        return d, th - th0


def _continuation(chain, P_scale, L_scale, ds, n_max, stop, q_scale):
    """Pseudo-arclength continuation of residual(q, lam) = 0 from the
    unloaded state.  Variables are scaled: z = (q / q_scale, lam / P_scale)."""

    def G(z):
        q = z[:3] * q_scale
        lam = z[3] * P_scale
        return chain.residual(q, lam, P_scale, L_scale)

    def jac(z, g0):
        Jm = np.empty((3, 4))
        h = 1e-7
        for j in range(4):
            zp = z.copy()
            zp[j] += h
            Jm[:, j] = (G(zp) - g0) / h
        return Jm

    z = np.zeros(4)
    g0 = G(z)
    Jm = jac(z, g0)
    # initial tangent: null vector of J, oriented with increasing load
    _, _, Vt = np.linalg.svd(Jm)
    t = Vt[-1]
    if t[3] < 0:
        t = -t
    pts = [z.copy()]
    step = ds
    for _ in range(n_max):
        ok = False
        while step > 1e-6 * ds:
            zp = z + step * t
            zc = zp.copy()
            for it in range(25):  # noqa: B007 (the count is read after the loop)
                g = G(zc)
                Jm = jac(zc, g)
                A = np.vstack((Jm, t))
                rhs = np.concatenate((g, [t @ (zc - zp)]))
                dz = np.linalg.solve(A, rhs)
                zc = zc - dz
                if np.linalg.norm(dz) < 1e-11:
                    ok = True
                    break
            if ok and np.linalg.norm(zc - z) < 3.0 * step:
                break
            ok = False
            step *= 0.5
        if not ok:
            break
        tn = zc - z
        tn /= np.linalg.norm(tn)
        z, t = zc, tn
        pts.append(z.copy())
        if it < 4:
            step = min(2.0 * step, 4.0 * ds)
        elif it > 8:
            step *= 0.5
        if stop(z[:3] * q_scale, z[3] * P_scale):
            break
    return pts


def _past_maximum(drop=0.98):
    """Stop criterion: the load has passed its first maximum and fallen by 2 %."""
    state = {"max": -np.inf}

    def stop(q, lam):
        state["max"] = max(state["max"], lam)
        return state["max"] > 0 and lam < drop * state["max"]

    return stop


def _path_from_points(chain, pts, q_scale, P_scale, load_dir):
    lam, u, v, rot = [], [], [], []
    for z in pts:
        q, lm = z[:3] * q_scale, z[3] * P_scale
        d, r = chain.monitor(q, lm)
        lam.append(lm)
        u.append(d[0])
        v.append(d @ load_dir)
        rot.append(r)
    return PlanarPath(np.array(lam), np.array(u), np.array(v), np.array(rot))


def _limit_load(chain, path, P_scale, L_scale, q_scale, load_dir):
    """Refine the first load maximum of ``path`` by maximising the load over the
    displacement v of the monitored point (displacement control: v is
    monotonic near a load limit point)."""
    dec = np.nonzero(np.diff(path.load) < 0)[0]
    if len(dec) == 0:
        raise RuntimeError("no load limit point on the computed path; extend it")
    i = int(dec[0])
    i = max(1, min(i, len(path.load) - 2))
    v_lo, v_hi = path.v[i - 1], path.v[i + 1]
    state = {"z": np.concatenate((path.info["q"][i] / q_scale, [path.load[i] / P_scale]))}

    def solve_v(vt):
        z = state["z"].copy()
        for _ in range(40):

            def H(zz):
                qq, ll = zz[:3] * q_scale, zz[3] * P_scale
                d, _ = chain.monitor(qq, ll)
                return np.concatenate((chain.residual(qq, ll, P_scale, L_scale), [(d @ load_dir - vt) / L_scale]))

            h0 = H(z)
            Jm = np.empty((4, 4))
            for j in range(4):
                zp = z.copy()
                zp[j] += 1e-7
                Jm[:, j] = (H(zp) - h0) / 1e-7
            dz = np.linalg.solve(Jm, h0)
            z = z - dz
            if np.linalg.norm(dz) < 1e-12:
                break
        state["z"] = z
        return z[3] * P_scale

    res = minimize_scalar(
        lambda vt: -solve_v(vt), bounds=(v_lo, v_hi), method="bounded", options={"xatol": 1e-9 * L_scale}
    )
    return -res.fun, res.x


#: Lee's frame (J.-S. Lee, 1968 experiments; the standard FE benchmark):
#: column and beam of length L = 120 with a rigid corner, both far ends
#: pinned, dead vertical load P on the beam at 24 from the corner;
#: E = 7.2e6, A = 6, I = 2 (so EI/L^2 = 1000).  Data as in Simo and Vu-Quoc
#: (1986) Example 7.4 and Schweizerhof and Wriggers (1986).
LEE_FRAME = dict(L=120.0, E=7.2e6, A=6.0, I=2.0, load_offset=24.0)

#: Published limit load of Lee's frame.  Confirmed: Simo and Vu-Quoc (1986),
#: CMAME 58, Example 7.4 (10 quadratic shear-deformable elements, nu = 0.3,
#: dead load): P_max = 18532 (= 18.53 EI/L^2); the follower-load case gives
#: 35447.  Published post-buckling path points (Schweizerhof and Wriggers
#: 1986; Battini 2002 thesis) could not be found with the search tool: use
#: :func:`lee_frame_path`, a converged elastica solution, for the path.
LEE_FRAME_PUBLISHED = {"Simo-Vu-Quoc 1986 limit load": 18532.0}


def _lee_chain(L, E, A, I, load_offset, h):
    nodes = [(0.0, 0.0), (0.0, L), (load_offset, L), (L, L)]
    return _PlanarChain(nodes, E * I, E * A, "pin", "pin", load_node=2, load_dir=(0.0, -1.0), h=h)


def lee_frame_path(
    L: float = 120.0,
    E: float = 7.2e6,
    A: float = 6.0,
    I: float = 2.0,
    load_offset: float = 24.0,
    v_max: float = 90.0,
    ds: float = 0.2,
    h: float = 2.0,
    n_max: int = 1000,
) -> PlanarPath:
    """Equilibrium path of Lee's frame, from the elastica (independent reference).

    Geometry and data of :data:`LEE_FRAME`: column from the pin (0, 0) up to
    the corner (0, L), beam from the corner to the pin (L, L), rigid corner,
    dead load P downward at (load_offset, L).  The bars are extensible
    Euler-Bernoulli (EA, EI, no shear deformation); the planar elastica of
    the whole frame is integrated from the base pin with the classical
    Runge-Kutta method (step ``h`` in arc length; error O(h^4)) and the three
    unknowns (base reaction, base rotation) are found by shooting so that the
    far end sits on its pin with zero moment.  The path is followed by
    pseudo-arclength continuation (Riks/Crisfield type, in scaled variables),
    which passes the load limit points and the snap-back in u.  Continuation
    stops when the load point's downward displacement v exceeds ``v_max``.

    Returns a :class:`PlanarPath` with load P (downward positive), u
    (horizontal, +x) and v (downward) of the load point.  Check: the first
    limit load is 18.5 EI/L^2 (Simo and Vu-Quoc 1986: 18532, see
    :data:`LEE_FRAME_PUBLISHED`).
    """
    chain = _lee_chain(L, E, A, I, load_offset, h)
    P_scale = E * I / L**2
    q_scale = np.array([P_scale, P_scale, 1.0])
    pts = _continuation(chain, P_scale, L, ds, n_max, lambda q, lam: chain.monitor(q, lam)[0][1] < -v_max, q_scale)
    path = _path_from_points(chain, pts, q_scale, P_scale, np.array([0.0, -1.0]))
    path.info = {"q": [z[:3] * q_scale for z in pts], "model": "Lee frame", "h": h}
    return path


def lee_frame_limit_load(h: float = 2.0, **kw):
    """First (maximum) limit load of Lee's frame and the downward displacement
    v of the load point there, from :func:`lee_frame_path` refined by Brent
    maximisation under displacement control.  Returns (P_max, v_at_P_max).
    Compare with :data:`LEE_FRAME_PUBLISHED` (Simo and Vu-Quoc 1986: 18532)."""
    p = dict(LEE_FRAME)
    p.update({k: v for k, v in kw.items() if k in p})
    chain = _lee_chain(p["L"], p["E"], p["A"], p["I"], p["load_offset"], h)
    P_scale = p["E"] * p["I"] / p["L"] ** 2
    q_scale = np.array([P_scale, P_scale, 1.0])
    pts = _continuation(chain, P_scale, p["L"], kw.get("ds", 0.2), 1000, _past_maximum(), q_scale)
    path = _path_from_points(chain, pts, q_scale, P_scale, np.array([0.0, -1.0]))
    path.info = {"q": [z[:3] * q_scale for z in pts]}
    return _limit_load(chain, path, P_scale, p["L"], q_scale, np.array([0.0, -1.0]))


#: Williams' toggle (F.W. Williams 1964, "An approach to the non-linear
#: behaviour of the members of a rigid jointed plane framework with finite
#: deflections", Q. J. Mech. Appl. Math. 17:451-469): two equal bars
#: clamped at (-12.943, 0) and (12.943, 0), rigidly joined at the apex
#: (0, 0.386) where a dead vertical load P acts; rectangular section
#: b = 0.753 in, d = 0.243 in (bending about the 0.243 in depth),
#: E = 10.3e6 psi, so EA = 1.885e6 lb and EI = 9.27e3 lb in^2.  These data
#: are the ones used in the later FE literature (section b x d confirmed from
#: public FE input files; E = 10.3e6 is the commonly quoted value, not
#: confirmed from the primary paper).  The published experimental and
#: analytical load-deflection points of Williams (1964) could not be found
#: with the search tool: use :func:`williams_toggle_path`.
WILLIAMS_TOGGLE = dict(half_span=12.943, rise=0.386, E=10.3e6, b=0.753, d=0.243)


def _toggle_chain(half_span, rise, E, b, d, h):
    A, I = b * d, b * d**3 / 12.0
    nodes = [(-half_span, 0.0), (0.0, rise), (half_span, 0.0)]
    return _PlanarChain(nodes, E * I, E * A, "clamp", "clamp", load_node=1, load_dir=(0.0, -1.0), h=h)


def _toggle_scales(half_span, rise, E, b, d):
    EI = E * b * d**3 / 12.0
    P_scale = EI * rise / half_span**3  # load scale of the shallow toggle
    return P_scale, np.array([P_scale * half_span / rise, P_scale, P_scale * half_span])


def williams_toggle_path(
    half_span: float = 12.943,
    rise: float = 0.386,
    E: float = 10.3e6,
    b: float = 0.753,
    d: float = 0.243,
    v_max: float = 0.6,
    ds: float = 0.2,
    h: float = 0.5,
    n_max: int = 1000,
) -> PlanarPath:
    """Equilibrium path of Williams' toggle from the elastica (independent reference).

    Data :data:`WILLIAMS_TOGGLE`; both supports clamped, rigid apex joint,
    dead load P downward at the apex; extensible Euler-Bernoulli bars solved
    exactly as in :func:`lee_frame_path` (shooting on the left-support
    reactions and moment, pseudo-arclength continuation).  The symmetric path
    has a load limit point (snap-through) shortly before the apex passes the
    line of the supports.  Returns a :class:`PlanarPath` (load, u, v of the
    apex; v downward).  Stops when v > ``v_max``.
    """
    chain = _toggle_chain(half_span, rise, E, b, d, h)
    P_scale, q_scale = _toggle_scales(half_span, rise, E, b, d)
    pts = _continuation(chain, P_scale, rise, ds, n_max, lambda q, lam: chain.monitor(q, lam)[0][1] < -v_max, q_scale)
    path = _path_from_points(chain, pts, q_scale, P_scale, np.array([0.0, -1.0]))
    path.info = {
        "q": [z[:3] * q_scale for z in pts],
        "model": "Williams toggle",
        "h": h,
        "P_scale": P_scale,
        "q_scale": q_scale,
    }
    return path


def williams_toggle_limit_load(h: float = 0.5, **kw):
    """First limit load of Williams' toggle and the apex deflection there:
    (P_max, v_at_P_max), refined as in :func:`lee_frame_limit_load`."""
    p = dict(WILLIAMS_TOGGLE)
    p.update({k: v for k, v in kw.items() if k in p})
    chain = _toggle_chain(p["half_span"], p["rise"], p["E"], p["b"], p["d"], h)
    P_scale, q_scale = _toggle_scales(p["half_span"], p["rise"], p["E"], p["b"], p["d"])
    pts = _continuation(chain, P_scale, p["rise"], kw.get("ds", 0.2), 1000, _past_maximum(), q_scale)
    path = _path_from_points(chain, pts, q_scale, P_scale, np.array([0.0, -1.0]))
    path.info = {"q": [z[:3] * q_scale for z in pts]}
    return _limit_load(chain, path, P_scale, p["rise"], q_scale, np.array([0.0, -1.0]))
