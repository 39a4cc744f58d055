"""Noise model of diagnose: estimators against noise of known variance and AR(1)
coefficient, the heteroscedastic law, given uncertainties and the errors on bad input."""

import math

import numpy as np
import pytest

from femast.errors import DataFileError, ModelError
from femast.experiments import Measured
from femast.experiments.fitting import bic
from femast.experiments.noise import (
    ChannelNoise,
    ar1_threshold,
    channel_noise,
    difference_phi,
    effective_n,
    given_sigma,
    heteroscedastic_fit,
    information_criterion,
    lag1,
)


def _ar1(phi, n, sigma, rng):
    e = np.empty(n)
    w = rng.normal(0.0, sigma * math.sqrt(1 - phi**2), n)
    e[0] = rng.normal(0.0, sigma)
    for i in range(1, n):
        e[i] = phi * e[i - 1] + w[i]
    return e


@pytest.mark.parametrize("phi", [0.3, 0.6, 0.85])
def test_ar1_coefficient_level_and_effective_size_are_recovered(phi):
    rng = np.random.default_rng(int(100 * phi))
    n, sigma, draws = 500, 2e-5, 20
    est = [channel_noise("d", _ar1(phi, n, sigma, rng), n) for _ in range(draws)]
    ph = np.array([m.phi for m in est])
    lev = np.array([m.sigma_rms for m in est])
    assert all(m.kind == "ar1" for m in est)
    # lag-1 estimator: standard error sqrt((1 - phi^2) / n) per draw; mean of 20 within 4 of them
    # (plus its O(1/n) bias towards 0)
    assert abs(ph.mean() - phi) < 4 * math.sqrt((1 - phi**2) / n / draws) + 2.0 / n
    # the level from the second differences: scatter 5-9 % per draw (measured), mean of 20 within 4 %
    assert abs(lev.mean() / sigma - 1) < 0.04
    np.testing.assert_allclose(est[0].n_eff, n * (1 - est[0].phi) / (1 + est[0].phi), rtol=1e-12)


def test_white_noise_is_called_white_and_the_thresholds_are_the_99th_percentiles():
    rng = np.random.default_rng(3)
    n = 400
    kinds = [channel_noise("d", rng.normal(0, 1.0, n), n, {"g": np.linspace(0, 1, n)}).kind for _ in range(100)]
    # each test is at its 99th percentile; two tests (correlation, level): expect 2 of 100, allow 6
    assert sum(k != "white" for k in kinds) <= 6
    z = rng.standard_normal((4000, n))
    r1 = np.array([lag1(x) for x in z[:1000]])
    assert abs(np.mean(r1 > ar1_threshold(n)) - 0.01) < 0.01  # binomial sd of the rate: 0.003
    # difference estimator: unbiased on AR(1), standard error ~1.9 / sqrt(n) (documented)
    dp = np.array([difference_phi(x) for x in z[:500]])
    assert abs(dp.mean()) < 4 * 1.9 / math.sqrt(n) / math.sqrt(500)
    assert 1.2 / math.sqrt(n) < dp.std() < 1.9 / math.sqrt(n)


def test_heteroscedastic_law_is_recovered():
    # Stohlman & Pellegrino, Eq. 15: residual e_T (1 + s C) - s e_d, variance sigma_T^2 (1 + s C)^2 + s^2 sigma_d^2
    rng = np.random.default_rng(7)
    n = 600
    s = np.sin(np.linspace(0, 9, n)) * 3e5  # signed slope of the law, N/m
    C, sT, sd = 2.5e-6, 0.4, 2e-6
    true = np.sqrt(sT**2 * (1 + s * C) ** 2 + (s * sd) ** 2)  # 0.4 N ... 0.85 / 0.65 N by the sign of s
    fits = [heteroscedastic_fit(rng.normal(0, 1, n) * true, s) for _ in range(20)]
    A, B, D = np.mean([f["coef"] for f in fits], axis=0)
    # 20 draws of 600 rows: the mean law within 5 % of the true one at every slope
    np.testing.assert_allclose(np.sqrt(A + B * s + D * s * s), true, rtol=0.05)
    np.testing.assert_allclose([A, B], [sT**2, 2 * C * sT**2], rtol=0.25)
    m = channel_noise("dT_N", rng.normal(0, 1, n) * true, n, {"slope": s})
    assert m.kind == "heteroscedastic" and m.covariate == "slope"


def test_information_criterion_is_the_bic_for_white_noise_and_uses_n_eff():
    rng = np.random.default_rng(1)
    z = rng.normal(0, 1, 3 * 200)
    white = {c: ChannelNoise(c, "white", np.ones(200), 0.0, 200.0) for c in "abc"}
    assert information_criterion(z, 200, white, 4) == pytest.approx(bic(float(z @ z), 600, 4), rel=1e-14)
    corr = {c: ChannelNoise(c, "ar1", np.ones(200), 0.5, effective_n(200, 0.5)) for c in "abc"}
    N = 3 * 200 / 3.0  # (1 - 0.5) / (1 + 0.5) = 1/3
    assert information_criterion(z, 200, corr, 4) == pytest.approx(
        N * math.log(float(z @ z) / 3.0 / N) + 4 * math.log(N), rel=1e-12
    )


def test_given_sigma_column_is_used_and_checked():
    d = Measured(
        "latch-pull", {"x_mm": np.zeros(12), "dT_N": np.zeros(12), "sigma_dT_N": np.full(12, 0.3)}, path="pull.csv"
    )
    np.testing.assert_array_equal(given_sigma(d, "dT_N"), 0.3)
    m = channel_noise("dT_N", np.zeros(12), 12, given=given_sigma(d, "dT_N"))
    assert m.kind == "given" and "sigma_dT_N" in m.reason
    d.columns["sigma_dT_N"][4] = 0.0
    with pytest.raises(DataFileError, match=r"pull.csv line 6: column 'sigma_dT_N' = 0.0: .*finite and > 0"):
        given_sigma(d, "dT_N")
    d.columns["sigma_dT_N"][4] = -1.0
    with pytest.raises(DataFileError, match="sigma_dT_N"):
        given_sigma(d, "dT_N")


def test_too_few_rows_for_the_noise_model_is_named():
    with pytest.raises(ModelError, match=r"channel dT_N: 5 rows are too few for the noise model .*sigma_dT_N"):
        channel_noise("dT_N", np.zeros(5), 5)


def test_pinned_rows_are_left_out_of_the_level():
    # a latch-pull residual is exactly zero where the measured force lies in an admissible band (the
    # static band of a bead at rest, Eq. 9) and one constant along a hold on the backstop: 20 % of the
    # rows pinned must not pull the level down (with them: ~0.7 of the true level)
    rng = np.random.default_rng(11)
    n, sigma = 500, 0.5
    r = rng.normal(0, sigma, n)
    r[100:150] = 0.0
    r[300:350] = 0.012  # a hold: (x + x_backstop) x 5e4 N/m, the same on every row
    lev = []
    for _ in range(20):
        rr = r.copy()
        rr[~np.isin(np.arange(n), np.r_[100:150, 300:350])] = rng.normal(0, sigma, n - 100)
        m = channel_noise("dT_N", rr, n)
        assert "100 pinned rows" in m.reason
        lev.append(m.sigma_rms)
    # 400 noisy rows: the robust level scatters ~5 % per draw; the mean of 20 within 4 %
    assert abs(np.mean(lev) / sigma - 1) < 0.04


def test_variance_law_never_goes_below_its_floor():
    # noise growing with the load's size from 0.4 to 2 of a level: unconstrained, a negative A once put
    # the rows near zero load at a tenth of their noise.  A, D >= 0 and the floor (0.04 of the mean variance).
    rng = np.random.default_rng(5)
    n = 300
    g = np.abs(np.sin(np.linspace(0, 12, n)))
    true = 0.4 + 1.6 * g
    for _ in range(20):
        h = heteroscedastic_fit(rng.normal(0, 1, n) * true, g)
        A, B, D = h["coef"]
        assert A >= 0 and D >= 0
        v = A + B * g + D * g * g
        assert np.all(h["sigma"] ** 2 >= 0.04 * np.mean(v) * (1 - 1e-12))  # the floor, to round-off
        assert np.all(h["sigma"] > 0.25 * true)  # not a tenth of the true noise again (these 20 draws: >= 0.51)


def _passes(n_per, k):
    """A path driven up and down k times over [0, 1] (n_per rows per pass, offset grids)."""
    out = []
    for i in range(k):
        g = np.linspace(0, 1, n_per) + (0.37 * i % 1.0) / n_per  # another grid on each pass
        out.append(g if i % 2 == 0 else g[::-1])
    return np.concatenate(out)


def test_repeated_passes_give_the_level_and_cancel_what_repeats():
    from femast.experiments.noise import cycle_scatter, with_cycles

    rng = np.random.default_rng(2)
    coord = _passes(120, 6)
    n = coord.size
    # repeats with the coordinate: model error, not noise (12 rows a period: linear interpolation leaves
    # (pi/12)^2/2 x 3 = 0.1 at most, 1 % of the level in variance; 6 rows a period would leave +8 %)
    ripple = 3.0 * np.sin(2 * np.pi * coord / 0.1)
    lev = []
    for _ in range(20):
        r = ripple + rng.normal(0, 0.5, n)
        level, m = cycle_scatter(coord, r)
        lev.append(level)
    assert m > 200
    # m ~ 300 compared rows: relative scatter 1 / sqrt(2 m) ~ 4 % per draw, the mean of 20 within 3 %
    assert abs(np.mean(lev) / 0.5 - 1) < 0.03
    # AR(1) noise: rows of different passes are independent, the level is the marginal one
    lev = [cycle_scatter(coord, _ar1(0.6, n, 0.5, rng))[0] for _ in range(20)]
    # (interpolating within a correlated pass adds variance: the estimate is high by ~9 % (measured),
    # on the safe side: the check only ever lowers a noise model's level)
    assert 0.97 < np.mean(lev) / 0.5 < 1.15
    # a noise model that took the ripple for noise (level 2.2) is brought back to the passes' level
    r = ripple + rng.normal(0, 0.5, n)
    m = with_cycles(ChannelNoise("dT_N", "ar1", np.full(n, 2.2), 0.5, effective_n(n, 0.5)), coord, r)
    assert m.kind == "white+cycles" and m.phi == 0.0 and abs(m.sigma_rms / 0.5 - 1) < 0.15  # 3 se of one draw
    # one that is right is left alone
    ok = ChannelNoise("dT_N", "white", np.full(n, 0.5), 0.0, float(n))
    assert with_cycles(ok, coord, rng.normal(0, 0.5, n)).sigma_rms == 0.5
