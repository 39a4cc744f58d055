"""latch-pull experiment (Stohlman & Pellegrino's latch law, Eqs. 12-14): compare and diagnose on data with hidden effects."""

import numpy as np
import pytest

from femast.elements.latch_law import LATCHING, UNLATCHING, LatchParameters, latch_force
from femast.experiments import AT_NOISE, compare, diagnose, from_arrays, get_experiment, predict, run_model
from femast.rigs.synthetic import latch_pull_data

EXP = get_experiment("latch-pull")
N_SIGMA = 4.0  # identified parameters within 4 Jacobian standard errors (two-sided p ~ 6e-5 per parameter)
REFIT_TOL = 1.2  # the refit error is within 1.2x the noise
SEED_FIT = {"r": 1.1e-3, "x_backstop": 2.0e-3, "k": 1e5, "mu": 0.07}
OTHER = {"r": 1.3e-3, "x_backstop": 1.8e-3, "k": 8e4, "mu": 0.1}  # a stiffer-friction, shorter latch

CASES = [
    # (effect, truth, baseline params, noise N, noise mm, passes, seed, relative tolerance and its reason)
    (
        "latch_hysteresis",
        {"F_h": 8.0, "ell": 4e-4},
        SEED_FIT,
        0.5,
        0.01,
        2,
        1,
        0.15,
    ),  # F_h and ell trade off (correlation ~0.8): 8 N over 0.4 mm is resolved to ~10 %
    (
        "latch_hysteresis",
        {"F_h": 6.0, "ell": 3e-4},
        OTHER,
        0.3,
        0.005,
        1,
        2,
        0.15,
    ),  # one pass with lower noise: as above
    (
        "friction_hysteresis",
        {"F_f": 1.5},
        OTHER,
        0.5,
        0.01,
        2,
        3,
        0.10,
    ),  # a constant offset over the whole path: well determined
    ("stretch_error", {"c_s": 5e-6}, SEED_FIT, 0.8, 0.01, 2, 4, 0.05),  # a 0.3 mm shear at 60 N against 0.01 mm noise
]


@pytest.mark.parametrize(
    "effect,truth,base,noise_N,noise_mm,passes,seed,rel", CASES, ids=[f"{c[0]}-s{c[6]}" for c in CASES]
)
def test_hidden_effect_is_localised_ranked_first_and_identified(
    effect, truth, base, noise_N, noise_mm, passes, seed, rel
):
    data, _ = latch_pull_data(
        base, {effect: truth}, passes=passes, noise_N=noise_N, noise_mm=noise_mm, seed=seed, x_far_mm=(4.0, 3.3)
    )
    c = compare(EXP, data, fit=True)
    assert c.ratio > 1.3 > c.at_noise  # the hidden effect is above the noise
    w = c.worst[0]
    rows = slice(w["start_row"], w["end_row"] + 1)
    oracle = predict(EXP, data, base, {effect: truth})["dT_N"]
    misfit = np.abs(oracle - c.predicted["dT_N"])
    # the worst segment is where the truth departs most: 1.5x its path average (3x and more seen)
    assert misfit[rows].mean() >= 1.5 * misfit.mean()
    if effect == "latch_hysteresis":  # ... and that is near the latched state, within a few ell of the backstop
        x_worst = 1e-3 * np.median(data["x_mm"][rows])
        assert x_worst < -base["x_backstop"] + 4 * truth["ell"]
    d = diagnose(EXP, data, workers=1)
    top = d.ranking[0]
    assert top["effect"] == effect and top["significant"]
    assert d.verdict["missing_effect"] == effect and d.verdict["explained"] is True
    for name, value in truth.items():
        est, se = top["params"][name]["value"], top["params"][name]["stderr"]
        assert abs(est - value) <= N_SIGMA * se, (name, est, se, value)
        assert abs(est - value) <= rel * abs(value), (name, est, value)
    # the noise the exact truth model leaves on these data (dT noise plus x noise through the slope)
    noise = run_model(EXP, data, {**EXP.defaults(), **base}, {effect: truth}).rms
    assert top["rms"] <= REFIT_TOL * noise
    assert top["ratio"] <= AT_NOISE


@pytest.mark.parametrize("base,seed", [(SEED_FIT, 11), (OTHER, 12)])
def test_null_case_nothing_is_missing(base, seed):
    data, _ = latch_pull_data(base, seed=seed)
    d = diagnose(EXP, data, workers=1)
    assert d.verdict["missing_effect"] is None and d.verdict["explained"] is True
    assert not any(e["significant"] for e in d.ranking)
    fit = d.baseline_fit
    for name, value in base.items():  # the baseline fit recovers the latch (Stohlman & Pellegrino, Sec. III.C)
        i = fit.names.index(name)
        assert abs(fit.x[i] - value) <= N_SIGMA * fit.stderr[i], (name, fit.x[i], fit.stderr[i], value)


def test_out_of_library_load_cell_drift_is_not_explained():
    data, _ = latch_pull_data(SEED_FIT, drift_N=3.0, seed=21)  # a 3 N slow drift of the force sensor
    d = diagnose(EXP, data, workers=1)
    assert d.verdict["missing_effect"] is None and d.verdict["explained"] is False
    assert d.baseline["ratio"] > 2.0  # a 3 N drift against 0.5 N noise: far above the floor


def test_model_follows_the_latch_law_on_its_branches():
    # unlatching out from the backstop then latching back in, noise-free: the prediction is Eq. 14
    p = LatchParameters.adam_fit()
    x = np.concatenate([np.linspace(-1.9e-3, 3e-3, 60), np.linspace(3e-3, -1.9e-3, 60)])
    sig = np.where(np.arange(x.size) < 60, UNLATCHING, LATCHING)
    dT = latch_force(x, sig, p)
    dT = np.where(sig > 0, np.maximum(dT, 0.0), np.minimum(dT, 0.0))  # one-sided pull test
    data = from_arrays(EXP, x_mm=1e3 * x, dT_N=dT)
    pred = predict(EXP, data, SEED_FIT)["dT_N"]
    np.testing.assert_allclose(pred, dT, atol=1e-9)  # every sample lies on its branch: zero residual


def test_backstop_holds_any_inward_pull():
    x = np.full(20, -2.0e-3)
    dT = -np.linspace(0.0, 80.0, 20)  # the latching cable pulls the seated bead against the backstop
    data = from_arrays(EXP, x_mm=1e3 * x, dT_N=dT)
    pred = predict(EXP, data, SEED_FIT)["dT_N"]
    np.testing.assert_allclose(pred, dT, atol=1e-9)


def test_compare_reports_latch_zones_and_directions():
    data, _ = latch_pull_data(SEED_FIT, {"latch_hysteresis": {"F_h": 8.0, "ell": 4e-4}}, seed=31)
    c = compare(EXP, data, fit=True)
    kinds = {k["kind"] for k in c.by_kind}
    assert {
        "zone (a) at backstop",
        "zone (b) behind roller axis",
        "latching (dx < 0)",
        "unlatching (dx > 0)",
        "loading",
        "peak",
    } <= kinds
