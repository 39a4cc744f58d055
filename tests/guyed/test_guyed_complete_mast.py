"""Dyneema law (Eq. 25) and the complete mast: passive / active shroud stiffness (Eqs. 16-26) of the Rocaspect paper."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from femast.elements.shroud_law import (
    ROCASPECT_X_S,
    DyneemaLaw,
    axial_rigidity_secant,
    axial_rigidity_tangent,
    shroud_stiffness,
    strain_from_tension,
    tension_from_strain,
)
from femast.errors import ModelError
from femast.guyed.cantilever import cantilever_compliance, cantilever_stiffness, mast_section
from femast.guyed.complete_mast import (
    ShroudSet,
    active_stiffness,
    displacement_complete,
    mast_stiffness,
    passive_stiffness,
    passive_stiffness_blocks,
    shroud_geometry,
    shroud_wrench_matrix,
)
from femast.guyed.rocaspect import E_NO_SHROUD, L_BEAM, mast_tops, rocaspect_shrouds

LAW = DyneemaLaw()
TOP = np.array([0.1, 0.2, 4.0])
RNG = np.random.default_rng(3)
UPPER = TOP + np.array([[0.05, 0.0, -0.25], [-0.03, 0.04, -0.3], [0.0, 0.0, 0.0]])
LOWER = np.array([[0.9, -0.3, 0.0], [-0.4, 0.8, 0.0], [-0.5, -0.6, 0.1]])
TAU0 = np.array([900.0, 1200.0, 400.0])


# ----------------------------------------------------------------------------- Eq. 25 law
def test_dyneema_law_units_and_seed_values():
    # k0 is an axial rigidity (N): EA at zero load; at 1200 N: k0 + k1 1200 + k2 1200^2 by hand.
    assert axial_rigidity_secant(LAW, 0.0) == ROCASPECT_X_S[0]
    assert axial_rigidity_tangent(LAW, 0.0) == pytest.approx(ROCASPECT_X_S[0], rel=1e-15)  # same formula at 0
    assert axial_rigidity_secant(LAW, 1200.0) == pytest.approx(
        935353.664 + 144.32 * 1200 - 0.000465 * 1200**2, rel=1e-15
    )  # round-off
    # Eq. 25: a 4 m shroud at 1200 N, secant form: (k0 + k1 tau + k2 tau^2) / l in N/m
    assert shroud_stiffness(LAW, 1200.0, 4.0, kind="secant") == pytest.approx(1107868.064 / 4.0, rel=1e-12)
    # the tangent is 18 % stiffer at 1200 N (progressive rope)
    assert axial_rigidity_tangent(LAW, 1200.0) / axial_rigidity_secant(LAW, 1200.0) == pytest.approx(1.1836, abs=1e-4)


def test_tangent_rigidity_is_derivative_of_tension_strain_law():
    for tau in (0.0, 400.0, 1200.0, 3000.0):
        eps = strain_from_tension(LAW, tau)
        h = 1e-9
        fd = (tension_from_strain(LAW, eps + h) - tension_from_strain(LAW, max(eps - h, 0.0))) / (
            eps + h - max(eps - h, 0)
        )
        # central difference on a smooth law: truncation ~h^2 and round-off ~1e-16 tau / h
        assert axial_rigidity_tangent(LAW, tau) == pytest.approx(fd, rel=1e-6)


def test_tension_strain_inverse_and_linear_limit():
    tau = np.linspace(0, 5000, 11)
    np.testing.assert_allclose(tension_from_strain(LAW, strain_from_tension(LAW, tau)), tau, rtol=1e-12, atol=1e-9)
    lin = DyneemaLaw(1e6, 50.0, 0.0)  # k2 = 0: tau = k0 eps / (1 - k1 eps) in closed form
    eps = np.array([0.0, 1e-4, 1e-3, 5e-3])
    np.testing.assert_allclose(tension_from_strain(lin, eps), 1e6 * eps / (1 - 50 * eps), rtol=1e-13)  # round-off
    assert tension_from_strain(LAW, -1e-3) == 0.0  # slack rope


def test_law_rejects_bad_input():
    with pytest.raises(ModelError, match="k0.*positive.*N"):
        DyneemaLaw(0.0, 1.0, 0.0)
    with pytest.raises(ModelError, match="outside the range"):
        axial_rigidity_secant(LAW, -5.0)
    with pytest.raises(ModelError, match="shroud length.*positive"):
        shroud_stiffness(LAW, 100.0, 0.0)
    with pytest.raises(ModelError, match="tangent"):
        shroud_stiffness(LAW, 100.0, 1.0, kind="chord")


# ----------------------------------------------------------------------------- Eqs. 21-26
def _shroud_wrench_after_motion(dx, law_fn, lengths0):
    """-(W_s tau) of the shrouds after moving the top by translation dx[:3] and spin dx[3:] (reference)."""
    R = Rotation.from_rotvec(dx[3:]).as_matrix()
    c = TOP + dx[:3]
    up = c + (UPPER - TOP) @ R.T
    s = LOWER - up
    l = np.linalg.norm(s, axis=1)
    f = law_fn(l, lengths0)[:, None] * s / l[:, None]
    return -np.concatenate([f.sum(0), np.cross(up - c, f).sum(0)])


def _fd_stiffness(law_fn, lengths0, h=1e-6):
    return np.column_stack(
        [
            (
                _shroud_wrench_after_motion(h * e, law_fn, lengths0)
                - _shroud_wrench_after_motion(-h * e, law_fn, lengths0)
            )
            / (2 * h)
            for e in np.eye(6)
        ]
    )


def test_active_plus_passive_equals_finite_difference_of_shroud_wrench():
    k = np.array([2.5e5, 3.0e5, 1.5e5])  # N/m, linear springs
    shrouds = ShroudSet(UPPER, LOWER, TAU0, law=None, stiffness=k)
    _, l0, _ = shroud_geometry(TOP, shrouds)
    K_fd = _fd_stiffness(lambda l, l0_: TAU0 + k * (l - l0_), l0)
    K = active_stiffness(TOP, shrouds) + passive_stiffness(TOP, shrouds)
    # central differences with h = 1e-6 m: relative error ~1e-9 on entries up to 1e5
    np.testing.assert_allclose(K, K_fd, atol=1e-6 * np.abs(K_fd).max())
    # the printed Eq. 26 misses the moment-arm term: it is off by much more than the FD error
    K_seed = active_stiffness(TOP, shrouds, form="printed") + passive_stiffness(TOP, shrouds)
    assert np.abs(K_seed - K_fd)[3:, 3:].max() > 100.0  # N m/rad; ~tau |e|


def test_tangent_law_gives_the_consistent_passive_stiffness():
    # Shrouds following the Dyneema law exactly: the unstretched length is fixed by the pretension.
    shrouds = ShroudSet(UPPER, LOWER, TAU0)
    _, l, _ = shroud_geometry(TOP, shrouds)
    l_free = l / (1.0 + strain_from_tension(LAW, TAU0))
    K_fd = _fd_stiffness(lambda lc, lf: tension_from_strain(LAW, lc / lf - 1.0), l_free)
    K_t = active_stiffness(TOP, shrouds) + passive_stiffness(TOP, shrouds, kind="tangent")
    # FD error ~1e-9 relative; 1e-6 leaves margin for the law's curvature
    np.testing.assert_allclose(K_t, K_fd, atol=1e-6 * np.abs(K_fd).max())
    K_s = active_stiffness(TOP, shrouds) + passive_stiffness(TOP, shrouds, kind="secant")
    assert np.abs(K_s - K_fd).max() > 0.05 * np.abs(K_fd).max()  # the printed secant is ~10-18 % off


def test_passive_block_form_equals_wrench_product():
    shrouds = ShroudSet(UPPER, LOWER, TAU0)
    Kp = passive_stiffness(TOP, shrouds)
    np.testing.assert_allclose(passive_stiffness_blocks(TOP, shrouds), Kp, rtol=1e-12, atol=1e-9 * np.abs(Kp).max())
    np.testing.assert_allclose(Kp, Kp.T, atol=1e-9 * np.abs(Kp).max())  # W K W^T is symmetric
    assert np.linalg.matrix_rank(Kp, tol=1e-9 * np.abs(Kp).max()) == 3  # three springs


def test_active_stiffness_asymmetry_is_the_net_shroud_moment():
    # Identity: a b^T - b a^T = [b x a]x, so K_a - K_a^T = [m]x in the rotation block, where
    # m = W_s[3:] tau is the shrouds' net moment about C_i3, and zero elsewhere.
    shrouds = ShroudSet(UPPER, LOWER, TAU0)
    K = active_stiffness(TOP, shrouds)
    m = (shroud_wrench_matrix(TOP, shrouds) @ TAU0)[3:]
    expected = np.zeros((6, 6))
    expected[3:, 3:] = [[0, -m[2], m[1]], [m[2], 0, -m[0]], [-m[1], m[0], 0]]
    np.testing.assert_allclose(K - K.T, expected, atol=1e-9 * np.abs(K).max())  # round-off
    assert np.abs(m).max() > 10.0  # N m: the check is not vacuous


def test_single_taut_string_active_stiffness():
    # A string tied at the reference point (e = 0): lateral stiffness tau / l, nothing else.
    shrouds = ShroudSet([TOP], [TOP + [0.0, 0.0, -4.0]], [1000.0], law=None, stiffness=[1.0])
    K = active_stiffness(TOP, shrouds)
    expected = np.zeros((6, 6))
    expected[0, 0] = expected[1, 1] = 1000.0 / 4.0
    np.testing.assert_allclose(K, expected, atol=1e-12)  # exact closed form up to round-off


def test_active_stiffness_blocks_scale_with_the_right_dimensions():
    # Scale the whole mast by s at fixed tension: N/m blocks ~ 1/s, N/rad blocks ~ 1, N m/rad ~ s.
    s = 3.0
    sh1 = ShroudSet(UPPER, LOWER, TAU0, law=None, stiffness=[1, 1, 1])
    sh3 = ShroudSet(s * UPPER, s * LOWER, TAU0, law=None, stiffness=[1, 1, 1])
    for form, ok in (("corrected", True), ("printed", False)):
        K1, K3 = active_stiffness(TOP, sh1, form), active_stiffness(s * TOP, sh3, form)
        expect = np.block([[K1[:3, :3] / s, K1[:3, 3:]], [K1[3:, :3], K1[3:, 3:] * s]])
        assert np.allclose(K3, expect, rtol=1e-10, atol=1e-9) == ok  # exact scaling, round-off only


def test_no_shrouds_reduces_to_the_beam_model():
    K_beam = cantilever_stiffness(L_BEAM, mast_section(E_NO_SHROUD))
    ms = mast_stiffness(K_beam, mast_tops()[0], None)
    dw = RNG.normal(size=(5, 6)) * 100
    C = cantilever_compliance(L_BEAM, mast_section(E_NO_SHROUD))
    # pinv of an invertible 6x6 of condition ~1e5: relative round-off ~1e-10
    np.testing.assert_allclose(displacement_complete(ms, dw), dw @ C.T, rtol=1e-8, atol=1e-12)


def test_shrouds_stiffen_the_mast_more_with_more_pretension():
    K_beam = cantilever_stiffness(L_BEAM, mast_section(E_NO_SHROUD))
    top = mast_tops()[0]
    lateral = [np.diag(mast_stiffness(K_beam, top, rocaspect_shrouds(0, t)).compliance)[:2] for t in (400, 1200)]
    bare = np.diag(cantilever_compliance(L_BEAM, mast_section(E_NO_SHROUD)))[:2]
    assert np.all(lateral[1] < lateral[0]) and np.all(lateral[0] < 0.5 * bare)
    # the wrench matrix of Eq. 21 has unit force columns
    np.testing.assert_allclose(
        np.linalg.norm(shroud_wrench_matrix(top, rocaspect_shrouds(0, 400))[:3], axis=0), 1.0, rtol=1e-15
    )


def test_bad_shroud_input_is_rejected():
    with pytest.raises(ModelError, match="shroud 2: its two end points coincide"):
        ShroudSet(UPPER, np.vstack([LOWER[0], UPPER[1], LOWER[2]]), TAU0)
    with pytest.raises(ModelError, match="shroud stiffness.*N/m"):
        ShroudSet(UPPER, LOWER, TAU0, law=None, stiffness=[1e5, 0.0, 1e5])
    with pytest.raises(ModelError, match="cannot push"):
        ShroudSet(UPPER, LOWER, [100.0, -1.0, 100.0])
    with pytest.raises(ModelError, match="6, 6"):
        mast_stiffness(np.eye(3), TOP, None)
