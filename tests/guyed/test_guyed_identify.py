"""Identification (the Rocaspect paper, Eqs. 27-30): recovery of known parameters from synthetic noisy data."""

import numpy as np
import pytest

from femast.elements.shroud_law import ROCASPECT_X_S, DyneemaLaw, strain_from_tension
from femast.errors import ModelError
from femast.guyed.cantilever import cantilever_compliance, mast_section
from femast.guyed.cdpr import trajectory_loads
from femast.guyed.identify import fit_3r, fit_beam_E, fit_shroud_law, rocaspect_eq29_matrix, shroud_design_matrix
from femast.guyed.mast_3r import displacement_3r
from femast.guyed.rocaspect import (
    E_1200N,
    L_BEAM,
    TABLE_III,
    fig5a_trajectory,
    mast_bases,
    mast_tops,
    rocaspect_geometry,
)

R_OC = mast_tops()[0] - mast_bases()[0]
_, _WR = trajectory_loads(rocaspect_geometry(), fig5a_trajectory(12))
DW = _WR[:, 0] - _WR[0, 0]  # mast-1 wrench changes along the Fig. 5a-like trajectory, N and N m
K_TRUE = np.array([*TABLE_III["1 and 8"][2:], np.inf])  # N m/rad; torsion rigid
N_SIGMA = 3.5  # a fixed-seed estimate lies within 3.5 standard errors (two-sided p ~ 5e-4)


def _tensile_test(rng, sigma, n=60):
    """Loading 50-400 kg and 0-300 kg as in the Rocaspect paper, Fig. 4a; elongations of a 0.5 m sample (m)."""
    tau = np.concatenate([np.linspace(50, 400, n) * 9.81, np.linspace(0, 300, n) * 9.81])
    dl = 0.5 * strain_from_tension(DyneemaLaw(), tau)
    return dl + rng.normal(0.0, sigma, dl.size), tau


def test_shroud_law_exact_data_recovers_seed_coefficients():
    dl, tau = _tensile_test(np.random.default_rng(0), 0.0)
    r = fit_shroud_law(dl, tau)
    # noise-free data: only the conditioning of the 3-column fit (~1e8) limits the accuracy
    np.testing.assert_allclose(r.x, ROCASPECT_X_S, rtol=1e-6)
    assert r.success and r.names == ("k0", "k1", "k2") and r.units == ("N", "-", "1/N")


def test_shroud_law_noisy_data_recovers_seed_coefficients_within_stderr():
    r = fit_shroud_law(*_tensile_test(np.random.default_rng(1), 0.5e-6))  # dial indicator noise 0.5 um
    assert np.all(np.abs(r.x - ROCASPECT_X_S) < N_SIGMA * r.stderr)
    assert r.stderr[0] / ROCASPECT_X_S[0] < 0.01  # k0 (EA at zero load) is well determined
    assert r.stderr[2] / abs(ROCASPECT_X_S[2]) < 0.5  # the small curvature term is resolved, but only just


def test_shroud_law_stderr_is_calibrated():
    # Monte Carlo: the scatter of repeated fits matches the Jacobian standard errors.
    rng = np.random.default_rng(2)
    fits = [fit_shroud_law(*_tensile_test(rng, 1e-6, n=30)) for _ in range(150)]
    x = np.array([f.x for f in fits])
    se = np.array([f.stderr for f in fits]).mean(0)
    # with 150 samples the empirical std has a ~6 % sampling error; 25 % covers it and small bias
    np.testing.assert_allclose(x.std(0, ddof=1), se, rtol=0.25)


def test_3r_stiffnesses_recovered_from_trajectory_data():
    rng = np.random.default_rng(4)
    dc = displacement_3r(K_TRUE, R_OC, DW) + rng.normal(0, 2e-4, DW.shape)  # laser tracker + mast noise 0.2 mm
    r = fit_3r(DW, dc, R_OC, rows=(0, 1, 2), free=(True, True, False))
    assert r.success
    assert np.all(np.abs(r.x - K_TRUE[:2]) < N_SIGMA * r.stderr)
    assert np.all(r.stderr / K_TRUE[:2] < 0.05)  # 0.2 mm noise on ~1 cm motions: a few % at most
    # left free, the torsion joint cannot be seen in top translations: reported, not invented
    r3 = fit_3r(DW, dc, R_OC, rows=(0, 1, 2))
    assert np.isinf(r3.stderr[2]) and "k_theta3" in r3.message
    # noise-free, all six components: exact recovery including torsion
    k = np.array([2.7e5, 2.3e5, 5.0e4])
    r6 = fit_3r(DW, displacement_3r(k, R_OC, DW), R_OC)
    np.testing.assert_allclose(r6.x, k, rtol=1e-7)  # least_squares stops at xtol/gtol ~1e-10..1e-8


def test_eq29_linear_system_gives_the_compliances():
    # Eq. 28: A_theta [1/k1, 1/k2, 1/k3] = dc; the paper's unknowns are compliances.
    k = np.array([2.7e5, 2.3e5, 5.0e4])
    A = rocaspect_eq29_matrix(DW, R_OC)
    comp = np.linalg.lstsq(A, displacement_3r(k, R_OC, DW).ravel(), rcond=None)[0]
    np.testing.assert_allclose(comp, 1 / k, rtol=1e-9)  # exact linear data, conditioning ~1e4


def test_beam_E_recovered_with_G_from_poisson():
    rng = np.random.default_rng(5)
    C = cantilever_compliance(L_BEAM, mast_section(E_1200N))
    dc = DW @ C.T + rng.normal(0, 2e-4, DW.shape)
    r = fit_beam_E(DW, dc, rows=(0, 1, 2))
    assert abs(r.x[0] - E_1200N) < N_SIGMA * r.stderr[0]
    assert r.stderr[0] / E_1200N < 0.05  # same noise as above
    # with the rotations measured, E and G are both identifiable; G = E / 2.6 is recovered
    dc6 = DW @ C.T + rng.normal(0, 1e-6, DW.shape)  # 1 urad / 1 um noise
    r2 = fit_beam_E(DW, dc6, fit_G=True)
    assert np.all(np.abs(r2.x - [E_1200N, E_1200N / 2.6]) < N_SIGMA * r2.stderr)


def test_identification_rejects_bad_data():
    with pytest.raises(ModelError, match="pair up"):
        shroud_design_matrix([1e-3, 2e-3], [100.0])
    with pytest.raises(ModelError, match="one measured displacement per wrench"):
        fit_3r(DW, DW[:-1], R_OC)
    with pytest.raises(ModelError, match="cannot determine"):
        fit_shroud_law([1e-4, 2e-4], [100.0, 200.0])
    with pytest.raises(ModelError, match="beam length"):
        fit_beam_E(DW, DW, L=-1.0)
    with pytest.raises(ModelError, match="fixed 3R joint stiffness"):
        fit_3r(DW, DW, R_OC, free=(True, True, False), k_fixed=(1, 1, 0))
