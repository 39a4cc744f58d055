"""The noise model's reading never contradicts itself: a residual whose lag-1 autocorrelation is
high while its differences are white (a slow model error on white noise) says so, instead of
"no serial correlation (autocorrelation 0.66 <= 0.10)"."""

import re

import numpy as np

from femast.experiments.noise import ar1_threshold, channel_noise, lag1


def _numbers(text):
    return [float(x) for x in re.findall(r"\d+\.\d+", text)]


def test_a_correlated_residual_with_white_differences_is_named_as_such(monkeypatch):
    """The branch where the residual's lag-1 autocorrelation is above the white-noise threshold but
    the differences' bound is not (the mast-top data in mm gave 0.66 against 0.10): the differences'
    estimate is set below the threshold here, since on n rows the bound adds 3.8 / sqrt(n)."""
    from femast.experiments import noise

    rng = np.random.default_rng(3)
    n = 600
    r = 0.05 * rng.standard_normal(n) + 0.2 * np.sin(np.linspace(0.0, np.pi, n))  # slow drift + white
    assert lag1(r) > ar1_threshold(n)  # the residual itself is correlated
    monkeypatch.setattr(noise, "difference_phi", lambda u: -1.0)
    m = channel_noise("dx_m", r, n)
    assert m.phi == 0.0  # treated as white noise
    assert "is above" in m.reason and "slowly varying model error" in m.reason
    assert "<=" not in m.reason
    phi_hat, thr = _numbers(m.reason)[:2]
    assert phi_hat > thr  # what it says is true


def test_white_noise_reads_as_uncorrelated_with_a_true_inequality():
    rng = np.random.default_rng(4)
    m = channel_noise("dx_m", rng.standard_normal(600), 600)
    assert m.phi == 0.0 and "no serial correlation (lag-1 autocorrelation" in m.reason
    phi_hat, thr = _numbers(m.reason.split("<=")[0])[-1], _numbers(m.reason.split("<=")[1])[0]
    assert phi_hat <= thr
