"""The resolution of recorded readings as a floor of the noise model.

Data are made here, by a connection test recorded to 0.01 mm and 0.01 kN: a linear connection
(``u = F / k``) driven by a force protocol in 40 N steps, a little noise on both channels, then
each reading rounded to its count.  The reference is the error the recorder actually made (the
recorded values against the exact ones), known here because the data are generated.
"""

import warnings

import numpy as np
import pytest

import femast.examples
from femast.experiments import compare, from_arrays, get_experiment, read_data
from femast.experiments.data import DataWarning
from femast.experiments.noise import ChannelNoise
from femast.experiments.resolution import resolution, rounding_sigma

Q_U, Q_F = 10e-6, 10.0  # 0.01 mm and 0.01 kN (m, N)
K = 2.0e6  # N/m


def _protocol(step=40.0, amps=(2e3, 4e3, 6e3)):
    path = [0.0]
    for a in amps:
        for peak in (a, -a, 0.0):
            m = int(round(abs(peak - path[-1]) / step))
            path += list(np.linspace(path[-1], peak, m + 1)[1:])
    return np.array(path)


def _recorded(seed, noise_share=0.3):
    """(F_N, u_m recorded, u_m exact): a slow protocol (the displacement moves 2 counts per row)."""
    rng = np.random.default_rng(seed)
    F = _protocol()
    u = F / K
    u_rec = Q_U * np.round((u + rng.normal(0.0, noise_share * Q_U, u.size)) / Q_U)
    F_rec = Q_F * np.round((F + rng.normal(0.0, noise_share * Q_F, F.size)) / Q_F)
    return F_rec, u_rec, F, u


def test_resolution_is_the_step_of_the_grid():
    rng = np.random.default_rng(0)
    x = rng.normal(0.0, 3e-3, 500)
    assert resolution(x) == 0.0  # continuous readings lie on no grid
    rec = Q_U * np.round(x / Q_U)  # recorded to 0.01 mm, in m: binary round-off on every value
    assert resolution(rec) == pytest.approx(Q_U, rel=1e-9)
    assert resolution(0.37 + 0.05 * np.round(x / 0.05e-3)) == pytest.approx(0.05, rel=1e-9)  # offset grid
    assert resolution(np.r_[0.0, 1.0, 2.0]) == 0.0  # too few readings to claim a grid
    assert resolution(0.6 * (1.0 - np.abs(np.linspace(-1.0, 1.0, 11)))) == 0.0  # a designed path of 5 steps
    assert rounding_sigma(Q_U) == pytest.approx(Q_U / np.sqrt(12.0))


def test_rounding_sigma_is_the_rms_of_a_uniform_rounding():
    rng = np.random.default_rng(1)
    x = rng.uniform(-1.0, 1.0, 200_000)
    err = 0.01 * np.round(x / 0.01) - x
    assert np.sqrt(np.mean(err**2)) == pytest.approx(rounding_sigma(0.01), rel=0.01)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_quantised_null_is_judged_against_the_recorders_error(seed):
    F_rec, u_rec, F, u = _recorded(seed)
    exp = get_experiment("joint-test")
    res = compare(exp, from_arrays(exp, F_N=F_rec, u_m=u_rec), fit=True, history=False)
    m = res.noise_model["u_m"]
    # what the recorder did to the displacement a linear model of the recorded force sees
    actual = np.sqrt(np.mean((u_rec - F_rec / K) ** 2))
    assert m.source == "resolution"
    assert 0.8 < m.sigma_rms / actual < 1.25
    # the residual's own estimate collapses (most differences are exactly zero): the floor is why
    assert m.levels["residual"] < 0.01 * m.levels["resolution"]
    assert m.disagree
    assert res.ratio < 1.3  # a perfect model is at the noise


def test_floor_leaves_a_noisier_channel_and_a_given_level_alone():
    F_rec, u_rec, F, u = _recorded(4, noise_share=3.0)  # noise of 3 counts: the rounding is a small part
    exp = get_experiment("joint-test")
    data = from_arrays(exp, F_N=F_rec, u_m=u_rec)
    m = compare(exp, data, fit=True, history=False).noise_model["u_m"]
    assert m.source != "resolution" and m.levels["resolution"] < 0.5 * m.sigma_rms  # the estimate stands
    without_floor = ChannelNoise(
        "u_m", "white", m.sigma, levels={k: v for k, v in m.levels.items() if k != "resolution"}
    )
    assert m.disagree == without_floor.disagree  # a floor below the estimates is no disagreement
    given = compare(exp, data, fit=True, history=False, sigma={"u_m": 1e-7}).noise_model["u_m"]
    assert given.source == "given" and given.sigma_rms == pytest.approx(1e-7)


def test_disagree_counts_a_floor_only_above_an_estimate():
    def noise(levels):
        return ChannelNoise("u_m", "white", np.ones(3), levels=levels)

    assert not noise({"residual": 1.0, "resolution": 0.1}).disagree
    assert noise({"residual": 0.1, "resolution": 1.0}).disagree
    assert noise({"residual": 1.0, "repeated passes": 2.0, "resolution": 0.1}).disagree


def test_spc1_reads_without_a_duplicate_warning_and_a_doubled_record_still_warns(tmp_path):
    exp = get_experiment("joint-test")
    with warnings.catch_warnings():
        warnings.simplefilter("error", DataWarning)
        data = read_data(exp, femast.examples.for_experiment("joint-test"))  # 20, 10, 20, 20 N at rest
    assert data.n == 33028
    F_rec, u_rec, _, _ = _recorded(5)
    rows = "\n".join(f"{f:.0f},{x:.5f}" for f, x in zip(F_rec[:200], u_rec[:200]) for _ in range(2))
    path = tmp_path / "doubled.csv"
    path.write_text("F_N,u_m\n" + rows + "\n")
    with pytest.warns(DataWarning, match=r"repeat the row before them exactly"):
        read_data(exp, path)
