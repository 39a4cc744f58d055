"""Latch identification from pull tests (Stohlman & Pellegrino, Section III.B-C, Eq. 15)."""

import copy

import numpy as np
import pytest

from femast.elements.latch_law import LATCHING, UNLATCHING, LatchParameters, latch_force
from femast.errors import ModelError
from femast.latch_identification import (
    fit_latch,
    fit_pull_tests,
    remove_cable_stretch,
    simulate_pull_test,
)

TRUE = LatchParameters(r=1.0e-3, x_backstop=1.8e-3, k=1.2e5, mu=0.10, h=1.5e-3, R=2.4e-3)
THETA = np.array([TRUE.r, TRUE.x_backstop, TRUE.k, TRUE.mu])
EA = 2.0e6  # N; stiff enough that the constant-length form of Eq. 15 adds < 0.3 um of bias
SIG_D, SIG_T = 5e-6, 0.3  # noise on d (m) and T (N)


@pytest.fixture(scope="module")
def clean_tests():
    return [simulate_pull_test(TRUE, d, EA=EA, n_steps=300) for d in (UNLATCHING, LATCHING)]


def noisy(tests, seed):
    rng = np.random.default_rng(seed)
    out = []
    for t in tests:
        t = copy.copy(t)
        t.d = t.d + rng.normal(0.0, SIG_D, t.d.size)
        t.T = t.T + rng.normal(0.0, SIG_T, t.T.size)
        out.append(t)
    return out


def test_eq15_by_hand():
    # d = 0.5013 m, T = 40 N, EA = 2e5 N, 0.5 m of loaded cable, d0 = 0.5 m: x = 1.3 mm - 0.1 mm.
    x = remove_cable_stretch(0.5013, 40.0, 2e5, 0.5, 0.5)
    assert x == pytest.approx(1.2e-3, abs=1e-15)  # hand arithmetic, round-off only
    assert remove_cable_stretch(0.5013, 40.0, 2e5, 0.5, 0.5, sign=-1) == pytest.approx(-1.2e-3, abs=1e-15)


def test_simulated_tests_follow_the_law(clean_tests):
    # Where the loaded cable is taut and the bead moves, the simulated test lies on Eq. 14,
    # and Eq. 15 recovers the bead position up to T (x - x_start) / EA.
    for t in clean_tests:
        taut = t.T > 1.0
        x = t.bead_position()
        assert np.max(np.abs(x[taut] - t.x_true[taut])) < 1e-6  # T dx / EA <= 110 N * 6 mm / 2e6 N
        moving = taut & (t.x_true > -TRUE.x_backstop)
        np.testing.assert_allclose(
            t.dT()[moving], latch_force(t.x_true[moving], t.direction, TRUE), atol=1e-7
        )  # element solve tolerance
    unl, lat = clean_tests
    assert unl.x_true[0] == -TRUE.x_backstop and lat.x_true[-1] == -TRUE.x_backstop
    peak = latch_force(np.linspace(-TRUE.x_backstop, 0.0, 20001), UNLATCHING, TRUE).max()
    assert unl.T.max() == pytest.approx(peak, rel=2e-3)  # the test's 300 grip steps straddle the peak


def test_recovers_known_parameters_from_noisy_data(clean_tests):
    res = fit_pull_tests(noisy(clean_tests, 1), h=TRUE.h, R=TRUE.R, sigma_T=SIG_T, sigma_x=SIG_D)
    assert res.success
    z = (res.x - THETA) / res.stderr
    assert np.all(np.abs(z) < 4.0)  # 4 standard errors: a false alarm once in ~4000 per parameter
    np.testing.assert_allclose(res.x, THETA, rtol=0.02)  # the data pin every parameter to < 2 %
    assert 0.6 < res.chi2_reduced < 1.6  # weights match the noise that was added (m ~ 400 points)
    assert res.params.k == res.x[2] and res.names == ("r", "x_backstop", "k", "mu")


def test_standard_errors_match_monte_carlo_spread(clean_tests):
    est, se = [], []
    for seed in range(24):
        res = fit_pull_tests(noisy(clean_tests, 100 + seed), h=TRUE.h, R=TRUE.R, sigma_T=SIG_T, sigma_x=SIG_D)
        est.append(res.x)
        se.append(res.stderr)
    ratio = np.std(est, axis=0) / np.mean(se, axis=0)
    # 24 samples: the sample std is within +-35 % of the truth at ~95 % confidence
    assert np.all((ratio > 0.6) & (ratio < 1.6)), ratio


def test_fit_starting_far_away(clean_tests):
    res = fit_pull_tests(
        noisy(clean_tests, 2), h=TRUE.h, R=TRUE.R, sigma_T=SIG_T, sigma_x=SIG_D, p0=[1.5e-3, 1.5e-3, 0.6e5, 0.02]
    )
    np.testing.assert_allclose(res.x, THETA, rtol=0.02)  # same basin: < 2 % as above


def test_bad_input():
    with pytest.raises(ModelError, match="never touch"):
        fit_latch(np.zeros(10), np.zeros(10), 1, h=3e-3, R=2e-3)
    with pytest.raises(ModelError, match="too few"):
        fit_latch(np.zeros(3), np.zeros(3), 1, h=1.5e-3, R=2.4e-3)
    with pytest.raises(ModelError, match="EA"):
        remove_cable_stretch(1.0, 1.0, 0.0, 0.5)
