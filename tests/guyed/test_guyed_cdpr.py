"""CDPR statics of the Rocaspect paper (Eqs. 1-3, 7): wrench matrix, tension distribution, mast-top wrenches."""

import numpy as np
import pytest
from scipy.optimize import linprog, minimize
from scipy.spatial import ConvexHull, HalfspaceIntersection
from scipy.spatial.transform import Rotation

from femast.errors import ModelError
from femast.guyed.cdpr import (
    GRAVITY,
    CdprGeometry,
    cable_forces_on_masts,
    cable_vectors,
    gravity_wrench,
    mast_top_wrenches,
    rotation_matrix,
    tension_distribution,
    wrench_matrix,
)
from femast.guyed.rocaspect import FRAME, POSE_0, fig5a_trajectory, rocaspect_geometry

GEOM = rocaspect_geometry()
POSES = [POSE_0, [4.15, 3.4, 1.6, 0, 0, 0], [5.0, 4.0, 2.0, 0.05, -0.03, 0.1], [3.0, 4.5, 0.8, 0, 0.04, 0]]


def test_wrench_matrix_is_minus_cable_length_jacobian():
    # Independent reference: finite differences of the cable lengths under a platform twist
    # (translation dt, spin dphi: R <- expm(dphi) R).  Virtual work gives d|l|/dx = -W^T.
    pose = np.array([3.2, 2.9, 1.4, 0.1, -0.05, 0.2])
    R0 = rotation_matrix(pose[3:])

    def lengths(dx):
        R = Rotation.from_rotvec(dx[3:]).as_matrix() @ R0
        p = np.concatenate([pose[:3] + dx[:3], Rotation.from_matrix(R).as_euler("xyz")])
        return cable_vectors(GEOM, p)[2]

    h = 1e-6
    fd = np.column_stack([(lengths(h * e) - lengths(-h * e)) / (2 * h) for e in np.eye(6)])
    # central differences: truncation O(h^2 / length) ~ 1e-12, round-off ~ 1e-16 / h ~ 1e-10
    np.testing.assert_allclose(fd, -wrench_matrix(GEOM, pose).T, atol=1e-8)


@pytest.mark.parametrize("method", ["barycenter", "min_norm", "linprog"])
def test_tensions_balance_gravity_within_limits(method):
    weight = GEOM.mass * GRAVITY
    for pose in POSES:
        td = tension_distribution(GEOM, pose, method)
        # equilibrium is solved exactly up to round-off of a 6x8 SVD (N)
        assert td.residual < 1e-9 * weight
        assert np.all(td.tau >= GEOM.tau_min - 1e-9) and np.all(td.tau <= GEOM.tau_max + 1e-9)  # round-off
        # the gravity wrench itself is the platform weight, straight down
        np.testing.assert_allclose(gravity_wrench(GEOM, pose)[:3], [0, 0, -weight], rtol=1e-15)  # exact


def test_symmetric_pose_gives_symmetric_tensions():
    # The layout is mirror-symmetric about x = 4.15 and y = 3.4, so at the centre every mast
    # carries the same pair of tensions, and a mirrored pose permutes the tensions.
    for method in ("barycenter", "min_norm"):
        tau = tension_distribution(GEOM, [FRAME[0] / 2, FRAME[1] / 2, 1.6], method).tau.reshape(4, 2)
        np.testing.assert_allclose(tau, np.broadcast_to(tau[0], (4, 2)), rtol=1e-9)  # round-off of SVD/vertices
        t1 = tension_distribution(GEOM, [2.65, 2.5, 1.6], method).tau.reshape(4, 2)
        t2 = tension_distribution(GEOM, [FRAME[0] - 2.65, 2.5, 1.6], method).tau.reshape(4, 2)
        np.testing.assert_allclose(t2[[1, 0, 3, 2]], t1, rtol=1e-9)  # mirror x -> masts 1<->2, 3<->4


def test_barycenter_matches_independent_polygon_centroid():
    # Reference: qhull half-space intersection from a Chebyshev centre found by linprog, then
    # the area centroid of the hull; compared in tension space (N).
    pose = POSES[2]
    W, wg = wrench_matrix(GEOM, pose), gravity_wrench(GEOM, pose)
    tau_p = np.linalg.lstsq(W, -wg, rcond=None)[0]
    N = np.linalg.svd(W)[2][6:].T
    A = np.vstack([N, -N])
    b = np.concatenate([GEOM.tau_max - tau_p, tau_p - GEOM.tau_min])
    norm = np.linalg.norm(A, axis=1)
    cheb = linprog([0, 0, -1], A_ub=np.column_stack([A, norm]), b_ub=b, bounds=[(None, None)] * 2 + [(0, None)])
    hs = HalfspaceIntersection(np.column_stack([A, -b]), cheb.x[:2])
    hull = ConvexHull(hs.intersections)
    pts = hs.intersections[hull.vertices]
    c = pts.mean(axis=0)
    a, b2 = pts - c, np.roll(pts, -1, axis=0) - c
    tri_area = 0.5 * np.abs(a[:, 0] * b2[:, 1] - a[:, 1] * b2[:, 0])
    tri_cent = (pts + np.roll(pts, -1, axis=0) + c) / 3
    centroid = (tri_area[:, None] * tri_cent).sum(0) / tri_area.sum()
    # both are exact polygon computations; differences are round-off (N)
    np.testing.assert_allclose(tension_distribution(GEOM, pose).tau, tau_p + N @ centroid, atol=1e-7)


def test_min_norm_matches_generic_qp():
    pose = POSES[3]
    W, wg = wrench_matrix(GEOM, pose), gravity_wrench(GEOM, pose)
    ref = minimize(
        lambda t: t @ t,
        np.full(8, 200.0),
        jac=lambda t: 2 * t,
        method="SLSQP",
        constraints={"type": "eq", "fun": lambda t: W @ t + wg, "jac": lambda t: W},
        bounds=[(GEOM.tau_min, GEOM.tau_max)] * 8,
        options={"ftol": 1e-14, "maxiter": 500},
    )
    # SLSQP converges to ~1e-6 relative; our solution is an exact 2D projection
    np.testing.assert_allclose(tension_distribution(GEOM, pose, "min_norm").tau, ref.x, rtol=1e-5)


def test_linprog_gives_the_smallest_total_tension():
    for pose in POSES:
        lp = tension_distribution(GEOM, pose, "linprog")
        bary = tension_distribution(GEOM, pose, "barycenter")
        # the LP optimum is a polygon vertex: no vertex has a smaller total (N; HiGHS tolerance 1e-7)
        W, wg = wrench_matrix(GEOM, pose), gravity_wrench(GEOM, pose)
        tau_p = np.linalg.lstsq(W, -wg, rcond=None)[0]
        N = np.linalg.svd(W)[2][6:].T
        vert_sums = (tau_p[None] + bary.vertices @ N.T).sum(1)
        assert lp.tau.sum() == pytest.approx(vert_sums.min(), rel=1e-7)


def test_mast_top_wrenches_satisfy_global_equilibrium():
    # Independent check (statics of platform + cables): the cable forces on the masts minus the
    # returns to the winches must carry the platform weight, with the right moment about the origin.
    for pose in POSES[:3]:
        td = tension_distribution(GEOM, pose)
        w = mast_top_wrenches(GEOM, pose, td.tau)
        v = GEOM.winch_points - GEOM.exit_points
        tv = td.tau[:, None] * v / np.linalg.norm(v, axis=1)[:, None]
        mg = np.array([0.0, 0.0, -GEOM.mass * GRAVITY])
        f_total = w[:, :3].sum(0) - tv.sum(0)
        m_origin = (w[:, 3:] + np.cross(GEOM.mast_tops, w[:, :3])).sum(0) - np.cross(GEOM.exit_points, tv).sum(0)
        np.testing.assert_allclose(f_total, mg, atol=1e-9)  # round-off on ~500 N
        np.testing.assert_allclose(m_origin, np.cross(np.asarray(pose[:3], float), mg), atol=1e-8)  # ~2e3 N m


def test_mast_force_is_tension_times_u_plus_v():
    # Eq. 7 on one hand-made cable: exit at the origin, platform straight along +x, winch straight down.
    g = CdprGeometry(
        exit_points=np.zeros((1, 3)),
        anchor_points=np.zeros((1, 3)),
        winch_points=[[0, 0, -2.0]],
        mast_of_cable=[0],
        mast_bases=[[0, 0, -3.0]],
        mast_tops=[[0, 0, 0.5]],
        mass=1.0,
    )
    f = cable_forces_on_masts(g, [3.0, 0, 0], [100.0])
    np.testing.assert_allclose(f, [[100.0, 0, -100.0]], rtol=1e-15)  # exact arithmetic
    w = mast_top_wrenches(g, [3.0, 0, 0], [100.0])
    # moment about the top (0, 0, 0.5) of the force applied at the origin: (0,0,-0.5) x (100,0,-100)
    np.testing.assert_allclose(w[0, 3:], np.cross([0, 0, -0.5], [100.0, 0, -100.0]), rtol=1e-15)


def test_trajectory_is_feasible_and_continuous():
    traj = fig5a_trajectory(10)
    taus = np.array([tension_distribution(GEOM, p).tau for p in traj])
    assert np.all(traj[:, 2] <= 2.0 + 1e-12)  # the paper's height limit, m
    # steps of ~0.3 m: a continuous distribution changes by far less than the tension range
    assert np.abs(np.diff(taus, axis=0)).max() < 0.1 * (GEOM.tau_max - GEOM.tau_min)


def test_infeasible_pose_names_the_pose():
    for pose in ([4.15, 3.4, 3.9], [-1.0, 3.4, 1.0]):
        with pytest.raises(ModelError, match=r"no cable tension distribution.*x=.*workspace"):
            tension_distribution(GEOM, pose)
    tight = rocaspect_geometry(tau_min=5.0, tau_max=40.0)  # 8 x 40 N cannot lift 490 N
    for method in ("barycenter", "linprog"):
        with pytest.raises(ModelError, match="x=2.650 m, y=2.500 m, z=1.600 m"):
            tension_distribution(tight, POSE_0, method)


def test_bad_geometry_is_rejected():
    with pytest.raises(ModelError, match="mass"):
        rocaspect_geometry(mass=0.0)
    with pytest.raises(ModelError, match="tau_min"):
        rocaspect_geometry(tau_min=100.0, tau_max=50.0)
    g = rocaspect_geometry()
    with pytest.raises(ModelError, match="cable .* 11: its two end points coincide"):
        cable_vectors(g, g.exit_points[0] - g.anchor_points[0])
