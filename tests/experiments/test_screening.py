"""Screening of diagnose's candidates on an expensive model: the linearised gain against closed forms,
the significance test it feeds by hand, and a diagnosis that screens reaching the verdict and
significance of one that refits every candidate in full, with fewer model runs.  The data come from
the two-axis test rig's generator (a gap crossed by a soft centring spring, ``clip``: no femast code)."""

import dataclasses
import math

import numpy as np
import pytest
import two_axis_rig as rig

from femast.experiments import diagnose, screening


def test_the_linearised_step_of_one_parameter_is_the_projection_clipped_at_its_bound():
    rng = np.random.default_rng(1)
    f0, j = rng.normal(size=50), rng.normal(size=50)
    w = np.full(50, 0.7)
    free = -(j @ f0) / (j @ j)  # the unbounded Gauss-Newton step, in closed form
    rss, du = screening.linearised_rss(f0, j[:, None], np.array([-10.0]), np.array([10.0]), w)
    assert du[0] == pytest.approx(free, rel=1e-9)
    assert rss == pytest.approx(0.7 * (f0 @ f0 - (j @ f0) ** 2 / (j @ j)), rel=1e-9)
    # a bound on the side of the step: the step stops on it
    lo, hi = (np.array([0.0]), np.array([10.0])) if free < 0 else (np.array([-10.0]), np.array([0.0]))
    rss, du = screening.linearised_rss(f0, j[:, None], lo, hi, w)
    assert du[0] == 0.0 and rss == pytest.approx(0.7 * f0 @ f0, rel=1e-12)


def test_a_linear_model_of_two_parameters_gains_what_least_squares_gains():
    rng = np.random.default_rng(2)
    J, f0 = rng.normal(size=(80, 2)), rng.normal(size=80)
    rss, _ = screening.linearised_rss(f0, J, np.full(2, -1e9), np.full(2, 1e9), np.ones(80))
    du = np.linalg.lstsq(J, -f0, rcond=None)[0]
    assert rss == pytest.approx(float(np.sum((f0 + J @ du) ** 2)), rel=1e-9)


def test_a_refit_goes_on_while_three_times_its_predicted_decrease_could_be_significant():
    # N = 100 residuals, baseline chi-square 100, one new parameter: significant (delta BIC < -10) below
    # 100 exp(-(10 + ln 100) / 100) = 86.41, i.e. a gain of 13.59; three times a predicted gain of 4.53 reaches it
    s = {"N": 100.0, "rss0": 100.0, "threshold": -10.0}
    need = 100.0 * (1.0 - math.exp(-(10.0 + math.log(100.0)) / 100.0))
    assert need == pytest.approx(13.59, abs=0.01)
    assert not screening.could_be_significant(100.0, 100.0 - 0.98 * need / 3.0, s, 1)
    assert screening.could_be_significant(100.0, 100.0 - 1.02 * need / 3.0, s, 1)
    # a second new parameter costs another ln N
    assert not screening.could_be_significant(100.0, 100.0 - 1.02 * need / 3.0, s, 2)
    # an iterate worse than the baseline (a poor start) is judged by the decrease predicted from it:
    # from 400, a step predicted to 290 could reach 400 - 3 x 110 = 70, significant; one to 320 (160) not
    assert screening.could_be_significant(400.0, 290.0, s, 1)
    assert not screening.could_be_significant(400.0, 320.0, s, 1)


def _expensive_rig():
    """The two-axis rig fitted as an FE rig is: finite differences, secant Jacobians, few runs."""
    fo = {"diff_step": 1e-3, "xtol": 1e-4, "ftol": 1e-4, "gtol": 1e-8, "max_nfev_per_param": 10, "expensive": True}
    return dataclasses.replace(rig.RIG, fit_options=fo)


def _runs(res) -> int:
    return sum(int(getattr(f, "fe_runs", 0)) for f in res.fits.values())


def test_a_screened_diagnosis_concludes_as_the_full_one_with_fewer_runs():
    exp, data = _expensive_rig(), rig.data(gap_x=2e-4, n=240)
    full = diagnose(exp, data, screen=False, heldout=False)
    fast = diagnose(exp, data, heldout=False)
    assert fast.verdict["kind"] == full.verdict["kind"] and fast.verdict["conclusion"] == full.verdict["conclusion"]
    sig = {e["effect"] for e in full.ranking if e["significant"]}
    assert sig and {e["effect"] for e in fast.ranking if e["significant"]} == sig
    screened = {e["effect"] for e in fast.ranking if e.get("screened")}
    assert screened and not (screened & sig)  # only candidates the full refits found not significant
    for e in fast.ranking:
        if e.get("screened"):
            assert "Screened out" in e["reading"] and not e["ic_gain"]
    assert _runs(fast) < _runs(full)
