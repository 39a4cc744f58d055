"""Consistent tangents and rigid-body invariance."""

import math

import numpy as np
import pytest

import femast as fm
from femast.analysis import Analysis
from femast.elements.base import IncrementContext
from femast.elements.beam_corot import BeamFamily, element_frame
from femast.elements.truss import TrussFamily
from femast.rotations import expm_so3, logm_so3, ts_inv, ts_inv_T_times_derivative
from femast.testing import fd_tangent


def _random_beams(rng, n=6):
    # disconnected elements so that each element's FD columns are independent
    X = rng.normal(size=(2 * n, 3))
    nodes = np.arange(2 * n).reshape(n, 2)
    E0 = np.array([element_frame(X[a], X[b], rng.normal(size=3)) for a, b in nodes])
    l0 = np.linalg.norm(X[nodes[:, 1]] - X[nodes[:, 0]], axis=1)
    fam = BeamFamily(
        nodes,
        E0,
        l0,
        EA=rng.uniform(1e2, 1e3, n),
        GJ=rng.uniform(1, 5, n),
        EIy=rng.uniform(1, 5, n),
        EIz=rng.uniform(1, 5, n),
    )
    # large rigid motion plus moderate deformation
    x = np.empty_like(X)
    R = np.empty((2 * n, 3, 3))
    for _e, (a, b) in enumerate(nodes):
        Q = expm_so3(rng.normal(size=3) * 2.5)
        c = rng.normal(size=3)
        x[a] = Q @ X[a] + c + 0.05 * rng.normal(size=3)
        x[b] = Q @ X[b] + c + 0.05 * rng.normal(size=3)
        R[a] = expm_so3(0.3 * rng.normal(size=3)) @ Q
        R[b] = expm_so3(0.3 * rng.normal(size=3)) @ Q
    return fam, x, R


def test_rotation_maps_against_finite_differences():
    rng = np.random.default_rng(0)
    for _ in range(5):
        th = rng.normal(size=3)
        d = rng.normal(size=3)
        h = 1e-6
        dR = (expm_so3(th + h * d) - expm_so3(th - h * d)) / (2 * h)
        W = dR @ expm_so3(th).T
        spin = np.array([W[2, 1], W[0, 2], W[1, 0]])
        # Ts^-1 maps the spin back to dtheta; FD error O(h^2) ~ 1e-11
        np.testing.assert_allclose(ts_inv(th) @ spin, d, atol=1e-8)
        np.testing.assert_allclose(
            logm_so3(expm_so3(th)), th if np.linalg.norm(th) < math.pi else logm_so3(expm_so3(th)), atol=1e-13
        )
        m = rng.normal(size=3)
        K = ts_inv_T_times_derivative(th, m)
        Kfd = np.column_stack([(ts_inv(th + h * e).T @ m - ts_inv(th - h * e).T @ m) / (2 * h) for e in np.eye(3)])
        np.testing.assert_allclose(K, Kfd, atol=1e-8)  # central FD with h = 1e-6: error ~1e-10


def test_beam_tangent_matches_finite_differences_at_large_rotations():
    # 8e: exact tangent vs central FD (h = 1e-6; truncation ~h^2 |f'''| ~ 1e-10 relative)
    rng = np.random.default_rng(42)
    fam, x, R = _random_beams(rng)
    K = fam.evaluate(x, R, None).k
    Kfd = fd_tangent(fam, x, R)
    for e in range(fam.n_elements):
        assert np.abs(K[e] - Kfd[e]).max() <= 1e-6 * np.abs(K[e]).max()


def test_truss_tangent_matches_finite_differences():
    rng = np.random.default_rng(3)
    X = rng.normal(size=(8, 3))
    nodes = np.arange(8).reshape(4, 2)
    L = np.linalg.norm(X[nodes[:, 1]] - X[nodes[:, 0]], axis=1)
    fam = TrussFamily(nodes, L * 0.9, [1e3] * 4, [True, False, True, False])
    x = X + 0.1 * rng.normal(size=X.shape)
    R = np.tile(np.eye(3), (8, 1, 1))
    K = fam.evaluate(x, R, None).k
    Kfd = fd_tangent(fam, x, R)
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()  # FD truncation ~1e-10 relative


def test_assembled_tangent_matches_finite_difference_of_residual():
    # The assembled K_ff of a 3D frame (beams + cable) at a deformed state vs FD of internal forces.
    m = fm.Model("frame")
    pts = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0.2), (0.5, 0.5, 1.0)]
    n = m.nodes(pts)
    sec = fm.circular_tube(0.05, 0.04, E=70e9)
    for a, b in [(0, 4), (1, 4), (2, 4), (3, 4), (0, 1), (1, 2)]:
        m.beam(n[a], n[b], sec, up=(0, 0, 1) if b != 4 else (1, 0, 0), n=2)
    m.truss(n[2], n[3], EA=1e5, pretension=100.0, tension_only=True)
    m.fix(n[0])
    m.step("s")
    an = Analysis(m, out=None or __import__("tempfile").mkdtemp(), progress=False)
    rng = np.random.default_rng(7)
    du = 0.05 * rng.normal(size=an.dofmap.n_free)
    an.system.update(du)
    K = an.tangent().toarray()
    ctx = IncrementContext()

    def internal(shift):
        x0, R0, s0 = an.x.copy(), an.R.copy(), an.spin.copy()
        an.system.update(shift)
        F = an.assembler.forces([r.f for r in an.system.evaluate(ctx)])[: an.dofmap.n_free]
        an.x, an.R, an.spin = x0, R0, s0
        return F

    h = 1e-6
    Kfd = np.column_stack([(internal(h * e) - internal(-h * e)) / (2 * h) for e in np.eye(an.dofmap.n_free)])
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()  # FD truncation/roundoff ~1e-9 relative


def test_rigid_rotation_produces_no_internal_forces():
    # 8f: element level, any large rigid motion (angle > 2 pi in accumulated terms is a multiple of
    # the same matrix): forces vanish to roundoff relative to the element stiffness.
    rng = np.random.default_rng(5)
    fam, _, _ = _random_beams(rng)
    X = np.empty((2 * fam.n_elements, 3))
    X[fam.nodes[:, 0]] = 0.0
    X[fam.nodes[:, 1]] = fam.E0[:, :, 0] * fam.l0[:, None]
    Q = expm_so3(np.array([0.4, -2.2, 2.9]))
    x = X @ Q.T + np.array([3.0, -1.0, 2.0])
    R = np.tile(Q, (len(X), 1, 1))
    f = fam.evaluate(x, R, None).f
    assert np.abs(f).max() < 1e-10 * fam.EA.max()


def test_prescribed_large_rotation_of_free_frame_is_rigid():
    # Analysis level: a node of an unsupported frame is turned by 7 rad (> 2 pi) about z; the frame
    # follows rigidly: positions = Q X, reactions zero (to 1e-8 of EA * strain scale).
    m = fm.Model("spin")
    n = m.nodes([(0, 0, 0), (1, 0, 0), (1, 0.5, 0.3), (0, 0.4, -0.2)])
    sec = fm.circular_tube(0.02, 0.015, E=200e9)
    for a, b in [(0, 1), (1, 2), (2, 3), (3, 0)]:
        m.beam(n[a], n[b], sec, up=(0, 0, 1), n=2)
    step = m.step("turn", initial_increment=0.05, max_increment=0.1)
    step.prescribe(n[0], ux=0, uy=0, uz=0, rx=0, ry=0, rz=7.0)
    res = fm.solve(m, __import__("tempfile").mkdtemp(), progress=False)
    Q = expm_so3(np.array([0, 0, 7.0]))
    X = m.coordinates
    np.testing.assert_allclose(X + res.frame(-1)["U"], X @ Q.T, atol=1e-10)  # exact rigid motion
    assert np.abs(res.frame(-1)["RF"]).max() < 1e-6  # N, N m: no reaction to a rigid rotation
    assert res.node_history(n[0], "rz")[-1] == pytest.approx(7.0, abs=1e-12)


def test_small_rotation_logarithm_agrees_with_atan2_form():
    """The beam kernel's logarithm (series of atan below 0.02 rad) against the atan2 form
    of logm_so3: within a few ulps across the switch (two roundings of one quaternion; both are within
    6e-16 of mpmath's logarithm of the same matrices), the same bits above it."""
    from numba import njit

    from femast.rotations import logm_so3_small_into

    @njit
    def small(R):
        out = np.empty(3)
        logm_so3_small_into(R, out)
        return out

    rng = np.random.default_rng(7)
    for t in np.concatenate([np.geomspace(1e-14, 0.02, 200), rng.uniform(0.0199, 0.0201, 50), [0.5, 2.0, 3.1]]):
        d = rng.normal(size=3)
        v = t * d / np.linalg.norm(d)
        R = expm_so3(v)
        ref = logm_so3(R)
        got = small(R)
        if t > 0.0201:
            assert np.array_equal(got, ref)  # the atan2 form itself
        else:
            assert np.abs(got - ref).max() <= 1e-15 * np.abs(ref).max()  # a few ulps: round-off of one quaternion
            assert np.abs(got - v).max() <= 2e-15 * t  # and of the exact vector
    assert np.array_equal(small(np.eye(3)), np.zeros(3))
