"""Statics of the 8-cable suspended CDPR carried by four masts (the Rocaspect paper, Eqs. 1-3 and 7).

Conventions (SI units: m, N, kg, rad)
-------------------------------------
* Base frame F_b: origin at the foot of mast 1, x along the 8.3 m side (towards mast 2),
  y along the 6.8 m side (towards mast 4), z up.
* A platform pose is ``[x, y, z, roll, pitch, yaw]``: the position of the platform frame
  origin (its geometric centre) in m and fixed-axis x-y-z angles in rad,
  ``R = Rz(yaw) Ry(pitch) Rx(roll)``.
* Cable vector (Eq. 1): ``l_j = R b_j + t - a_j`` points from the exit point A_j to the
  platform anchor B_j; ``u_j = l_j / |l_j|``.

Sign correction to Eqs. 2-3
---------------------------
With Eq. 1's ``u_j`` (from A_j towards the platform) a cable *pulls the platform along
-u_j*, so the cables' wrench on the platform is ``-W_printed tau`` with ``W_printed`` the matrix
printed as Eq. 3.  Eq. 2 (``W tau + w_g = 0``) therefore only holds with ``w_g`` the
*gravity* wrench if the columns of W are built from ``-u_j``.  This module does that:
:func:`wrench_matrix` returns ``W = [-u_j ; (R b_j) x (-u_j)]`` (moments about the platform
origin) and :func:`gravity_wrench` returns the physical gravity wrench, so Eq. 2 holds as
printed.  ``W_printed = -W`` is also ``d|l|/dx`` (the cable-length Jacobian with respect to the
platform twist), which the tests check by finite differences.

Pulleys are treated as points (the paper takes their kinematics into account in the
controller but does not give them).  The cable leaves the pulley at A_j towards the
platform and returns to its winch at F_j; the force on the mast at A_j is therefore
``tau_j (u_j + v_j)`` with ``v_j`` the unit vector from A_j to F_j (Eq. 7).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linprog
from scipy.spatial.transform import Rotation

from ..errors import ModelError
from ._common import check_positive, check_vectors, fmt_pose, unit_vectors

GRAVITY = 9.81
"""Standard gravity used for the platform weight, m/s^2."""


@dataclass(frozen=True)
class CdprGeometry:
    """Geometry and limits of a CDPR whose cable exit points sit on masts.

    Attributes
    ----------
    exit_points : (m, 3) cable exit points A_j in F_b, m (Eq. 1 ``a``).
    anchor_points : (m, 3) platform anchor points B_j in F_mp, m (Eq. 1 ``b``).
    winch_points : (m, 3) points F_j in F_b towards which each cable returns from its pulley, m (Eq. 7).
    mast_of_cable : (m,) index i of the mast carrying cable j (0-based).
    mast_bases : (n, 3) mast base points O_i in F_b, m.
    mast_tops : (n, 3) mast top points C_i3 in F_b, m (the reference point of the mast wrench, Eq. 7).
    mass : platform mass, kg.
    cog : (3,) platform centre of mass in F_mp, m.
    tau_min, tau_max : admissible cable tensions, N.
    labels : cable names, e.g. ``"11"`` for mast 1, cable 1.
    """

    exit_points: np.ndarray
    anchor_points: np.ndarray
    winch_points: np.ndarray
    mast_of_cable: np.ndarray
    mast_bases: np.ndarray
    mast_tops: np.ndarray
    mass: float
    cog: np.ndarray = field(default_factory=lambda: np.zeros(3))
    tau_min: float = 20.0
    tau_max: float = 1500.0
    labels: tuple = ()

    def __post_init__(self):
        a = check_vectors("exit_points", self.exit_points)
        m = a.shape[0]
        for name in ("anchor_points", "winch_points"):
            arr = check_vectors(name, getattr(self, name))
            if arr.shape != (m, 3):
                raise ModelError(f"{name} has shape {arr.shape}; need one point per cable, ({m}, 3), in m")
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "exit_points", a)
        bases = check_vectors("mast_bases", self.mast_bases)
        tops = check_vectors("mast_tops", self.mast_tops)
        if bases.shape != tops.shape:
            raise ModelError("mast_bases and mast_tops need the same shape (n, 3), in m")
        unit_vectors("mast (base O_i to top C_i3)", tops - bases, labels=[str(i + 1) for i in range(len(tops))])
        object.__setattr__(self, "mast_bases", bases)
        object.__setattr__(self, "mast_tops", tops)
        idx = np.asarray(self.mast_of_cable, dtype=int)
        if idx.shape != (m,) or idx.min() < 0 or idx.max() >= len(tops):
            raise ModelError(f"mast_of_cable must give, for each of the {m} cables, a mast index in 0..{len(tops) - 1}")
        object.__setattr__(self, "mast_of_cable", idx)
        check_positive("platform mass", self.mass, "kg")
        object.__setattr__(self, "cog", check_vectors("cog", self.cog).reshape(3))
        if not (0.0 <= self.tau_min < self.tau_max):
            raise ModelError(f"tension limits need 0 <= tau_min ({self.tau_min}) < tau_max ({self.tau_max}), in N")
        if not self.labels:
            counter = {}
            labels = []
            for i in idx:
                counter[i] = counter.get(i, 0) + 1
                labels.append(f"{i + 1}{counter[i]}")
            object.__setattr__(self, "labels", tuple(labels))
        unit_vectors("cable return (exit point A to winch point F)", self.winch_points - a, labels=self.labels)

    @property
    def n_cables(self) -> int:
        return self.exit_points.shape[0]

    @property
    def n_masts(self) -> int:
        return self.mast_tops.shape[0]


# --------------------------------------------------------------------------- geometry
def rotation_matrix(angles) -> np.ndarray:
    """Rotation matrix ``R = Rz(yaw) Ry(pitch) Rx(roll)`` from fixed-axis angles in rad."""
    return Rotation.from_euler("xyz", np.asarray(angles, dtype=float)).as_matrix()


def _pose(pose):
    p = np.asarray(pose, dtype=float).ravel()
    if p.size == 3:
        p = np.concatenate([p, np.zeros(3)])
    if p.size != 6 or not np.all(np.isfinite(p)):
        raise ModelError(f"platform pose {pose!r} must be [x, y, z] (m) or [x, y, z, roll, pitch, yaw] (m, rad)")
    return p, rotation_matrix(p[3:])


def cable_vectors(geom: CdprGeometry, pose):
    """Cable vectors of Eq. 1, ``l_j = R b_j + t - a_j`` (m), from exit point A_j to anchor B_j.

    Returns ``(l, u, length, Rb)``: vectors (m, 3) in m, unit vectors (m, 3), lengths (m,) in m,
    and the anchor points rotated into F_b, ``R b_j`` (m, 3) in m.
    """
    p, R = _pose(pose)
    Rb = geom.anchor_points @ R.T
    l = Rb + p[:3] - geom.exit_points
    u, length = unit_vectors("cable (exit point A to platform anchor B)", l, labels=geom.labels)
    return l, u, length, Rb


def wrench_matrix(geom: CdprGeometry, pose) -> np.ndarray:
    """Wrench matrix W (6, m) of Eq. 3, sign-corrected so that Eq. 2 ``W tau + w_g = 0`` holds.

    Column j is the wrench (N, N m about the platform origin, per N of tension) cable j applies
    to the platform: ``[-u_j ; (R b_j) x (-u_j)]``.  The paper's printed Eq. 3 is ``-W``
    (see the module note).
    """
    _, u, _, Rb = cable_vectors(geom, pose)
    return np.vstack([-u.T, np.cross(Rb, -u).T])


def gravity_wrench(geom: CdprGeometry, pose) -> np.ndarray:
    """Gravity wrench w_g (6,) on the platform, N and N m about the platform origin (Eq. 2)."""
    _, R = _pose(pose)
    f = np.array([0.0, 0.0, -geom.mass * GRAVITY])
    return np.concatenate([f, np.cross(R @ geom.cog, f)])


# --------------------------------------------------------------------------- tensions
@dataclass(frozen=True)
class TensionDistribution:
    """A tension distribution at one pose.

    tau : (m,) cable tensions, N.
    W : (6, m) wrench matrix (:func:`wrench_matrix`).
    w_g : (6,) gravity wrench, N and N m.
    method : name of the method used.
    vertices : (k, 2) vertices of the feasible polygon in null-space coordinates, N
        (empty for ``method='linprog'`` or when not computed).
    """

    tau: np.ndarray
    W: np.ndarray
    w_g: np.ndarray
    method: str
    vertices: np.ndarray

    @property
    def residual(self) -> float:
        """Equilibrium residual |W tau + w_g|, N (and N m)."""
        return float(np.linalg.norm(self.W @ self.tau + self.w_g))


def _feasible_polygon(W, w_g, tau_min, tau_max):
    """Vertices of the 2D set of feasible tensions ``tau = tau_p + N lam``, for redundancy 2.

    Returns ``(tau_p, N, vertices)`` with vertices (k, 2) ordered counter-clockwise
    (k = 0 when no tension distribution exists).
    """
    U, s, Vt = np.linalg.svd(W)
    if s[-1] < 1e-9 * s[0]:
        return None
    tau_p = -Vt[:6].T @ ((U.T @ w_g) / s)  # minimum-norm particular solution
    N = Vt[6:].T  # orthonormal basis of the null space of W
    # Half-planes A lam <= b: tau <= tau_max and -tau <= -tau_min.
    A = np.vstack([N, -N])
    b = np.concatenate([tau_max - tau_p, tau_p - tau_min])
    i, j = np.array(list(itertools.combinations(range(len(b)), 2))).T
    det = A[i, 0] * A[j, 1] - A[i, 1] * A[j, 0]
    ok = np.abs(det) > 1e-12
    i, j, det = i[ok], j[ok], det[ok]
    lam = np.column_stack([(b[i] * A[j, 1] - b[j] * A[i, 1]) / det, (A[i, 0] * b[j] - A[j, 0] * b[i]) / det])
    tol = 1e-9 * max(tau_max, 1.0)
    inside = np.all(lam @ A.T <= b + tol, axis=1)
    V = lam[inside]
    if V.shape[0] == 0:
        return tau_p, N, V
    c = V.mean(axis=0)
    V = V[np.argsort(np.arctan2(V[:, 1] - c[1], V[:, 0] - c[0]))]
    # Several limit lines can meet at one vertex: drop repeats (values are kept, not rounded).
    keep = np.linalg.norm(V - np.roll(V, 1, axis=0), axis=1) > tol
    if not keep.any():
        keep[0] = True
    return tau_p, N, V[keep]


def _polygon_centroid(V):
    if len(V) < 3:
        return V.mean(axis=0)
    x, y = V[:, 0], V[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = 0.5 * cross.sum()
    if abs(area) < 1e-12 * max(1.0, np.abs(V).max() ** 2):
        return V.mean(axis=0)
    return np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6.0 * area)


def _closest_point(V, q):
    """Point of the convex polygon V (ordered) closest to q."""
    if len(V) == 1:
        return V[0]
    P0, P1 = V, np.roll(V, -1, axis=0)
    if len(V) >= 3:
        edge = P1 - P0
        if np.all(edge[:, 0] * (q[1] - P0[:, 1]) - edge[:, 1] * (q[0] - P0[:, 0]) >= 0.0):
            return q  # inside (counter-clockwise polygon)
    d = P1 - P0
    t = np.clip(np.einsum("ij,ij->i", q - P0, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
    P = P0 + t[:, None] * d
    return P[np.argmin(np.linalg.norm(P - q, axis=1))]


def tension_distribution(geom: CdprGeometry, pose, method: str = "barycenter", tau_ref=None) -> TensionDistribution:
    """Cable tensions (N) satisfying ``W tau + w_g = 0`` (Eq. 2) with ``tau_min <= tau <= tau_max``.

    Methods
    -------
    ``"barycenter"`` (default)
        The 8 cables give a redundancy of 2: all solutions are ``tau = tau_p + N lam`` with
        ``N`` a basis of the null space of W.  The feasible set of ``lam`` is a convex polygon
        (the intersection of the 16 half-planes from the tension limits); its vertices are found
        by intersecting every pair of limit lines and keeping the feasible points.  The
        distribution is the polygon's centroid (Mikelsons et al., ICRA 2008; Lamaury and
        Gouttefarde, ICRA 2013).  It is continuous along a trajectory and stays away from both
        limits.
    ``"min_norm"``
        The feasible tensions closest, in the 2-norm, to ``tau_ref`` (default: all zero, i.e.
        the minimum 2-norm distribution), computed exactly as the polygon point closest to
        the projection of ``tau_ref``.  Also continuous along trajectories.
    ``"linprog"``
        Minimum total tension, ``min sum(tau)`` by :func:`scipy.optimize.linprog`; any
        redundancy, but the solution jumps between polygon vertices along a trajectory.

    Raises :class:`~femast.errors.ModelError` naming the pose when no distribution exists
    (the pose is outside the wrench-feasible workspace) or W is rank deficient.
    """
    p, _ = _pose(pose)
    W = wrench_matrix(geom, p)
    w_g = gravity_wrench(geom, p)
    lim = f"[{geom.tau_min:g}, {geom.tau_max:g}] N"
    if method == "linprog":
        res = linprog(np.ones(geom.n_cables), A_eq=W, b_eq=-w_g, bounds=(geom.tau_min, geom.tau_max), method="highs")
        if res.status != 0:
            raise ModelError(
                f"no cable tension distribution within {lim} balances the platform weight at pose "
                f"({fmt_pose(p)}): linprog says '{res.message}'. Move the pose inside the wrench-feasible "
                "workspace (lower, nearer the centre) or widen the tension limits."
            )
        return TensionDistribution(res.x, W, w_g, method, np.zeros((0, 2)))
    if method not in ("barycenter", "min_norm"):
        raise ModelError(f"unknown tension distribution method {method!r}; use 'barycenter', 'min_norm' or 'linprog'")
    if geom.n_cables - 6 != 2:
        raise ModelError(f"method {method!r} needs exactly 8 cables (redundancy 2); use method='linprog'")
    poly = _feasible_polygon(W, w_g, geom.tau_min, geom.tau_max)
    if poly is None:
        raise ModelError(
            f"the wrench matrix is rank deficient at pose ({fmt_pose(p)}): the cables cannot "
            "hold the platform in all directions there; choose another pose"
        )
    tau_p, N, V = poly
    if V.shape[0] == 0:
        raise ModelError(
            f"no cable tension distribution within {lim} balances the platform weight at pose "
            f"({fmt_pose(p)}). Move the pose inside the wrench-feasible workspace (lower, nearer the "
            "centre of the frame) or widen the tension limits."
        )
    if method == "barycenter":
        lam = _polygon_centroid(V)
    else:
        ref = np.zeros(geom.n_cables) if tau_ref is None else np.broadcast_to(np.asarray(tau_ref, float), tau_p.shape)
        lam = _closest_point(V, N.T @ (ref - tau_p))
    tau = np.clip(tau_p + N @ lam, geom.tau_min, geom.tau_max)  # clip removes round-off only
    return TensionDistribution(tau, W, w_g, method, V)


def is_feasible(geom: CdprGeometry, pose) -> bool:
    """True when some tension distribution within the limits balances the platform at ``pose``."""
    p, _ = _pose(pose)
    poly = _feasible_polygon(wrench_matrix(geom, p), gravity_wrench(geom, p), geom.tau_min, geom.tau_max)
    return poly is not None and poly[2].shape[0] > 0


# --------------------------------------------------------------------------- mast loads
def cable_forces_on_masts(geom: CdprGeometry, pose, tau) -> np.ndarray:
    """Force each cable applies to its mast at the exit point A_j, ``tau_j (u_j + v_j)`` (m, 3), N (Eq. 7)."""
    _, u, _, _ = cable_vectors(geom, pose)
    v, _ = unit_vectors(
        "cable return (exit point A to winch point F)", geom.winch_points - geom.exit_points, labels=geom.labels
    )
    return np.asarray(tau, dtype=float)[:, None] * (u + v)


def mast_top_wrenches(geom: CdprGeometry, pose, tau) -> np.ndarray:
    """Resultant cable wrench on each mast top (n, 6) of Eq. 7: ``[sum f_j ; sum (a_j - c_i3) x f_j]``.

    Forces in N, moments in N m about the mast top C_i3, base-frame axes.
    """
    f = cable_forces_on_masts(geom, pose, tau)
    m = np.cross(geom.exit_points - geom.mast_tops[geom.mast_of_cable], f)
    out = np.zeros((geom.n_masts, 6))
    np.add.at(out, geom.mast_of_cable, np.hstack([f, m]))
    return out


def trajectory_loads(geom: CdprGeometry, poses, method: str = "barycenter"):
    """Tensions (k, m) in N and mast-top wrenches (k, n, 6) in N, N m along a list of poses (k, 3|6)."""
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    tau = np.array([tension_distribution(geom, p, method=method).tau for p in poses])
    wr = np.array([mast_top_wrenches(geom, p, t) for p, t in zip(poses, tau)])
    return tau, wr
