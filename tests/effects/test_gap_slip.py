"""Slip through a gap with friction (the pinching law) against its closed forms."""

import numpy as np
import pytest

from femast.effects.gap_slip import gap_slip


def _cycles(F_m, n_cycles, n_per_quarter=20000, start=0.0):
    """0 -> +F_m -> -F_m -> +F_m ... (n_cycles full cycles), then back to 0; fine steps."""
    q = np.linspace(0.0, 1.0, n_per_quarter + 1)[1:]
    path = [np.array([start])]
    path.append(start + (F_m - start) * q)
    for _ in range(n_cycles):
        path += [F_m - 2 * F_m * np.concatenate([q, 1 + q]) / 2, -F_m + 2 * F_m * np.concatenate([q, 1 + q]) / 2]
    return np.concatenate(path)


def _work(F, s):
    return float(np.sum(0.5 * (F[1:] + F[:-1]) * np.diff(s)))


def test_monotonic_load_crushes_by_the_excess_over_the_onset():
    F = np.linspace(0.0, 30e3, 3001)
    s = gap_slip(F, F_y=12e3, k_e=2e6, F_f=2e3, k_g=1e5)
    np.testing.assert_allclose(s, np.maximum(F - 12e3, 0.0) / 2e6, rtol=0, atol=1e-15)


@pytest.mark.parametrize("k_g", [0.0, 2e5, 1e6])
def test_loop_on_repeated_cycles_dissipates_four_friction_times_the_half_gap(k_g):
    F_y, k_e, F_f, F_m = 10e3, 1e6, 1.5e3, 25e3
    F = _cycles(F_m, n_cycles=3)
    s, e = gap_slip(F, F_y, k_e, F_f, k_g, edges=True)
    half_gap = (F_m - F_y) / k_e
    np.testing.assert_allclose(e[-1], [half_gap, half_gap], rtol=1e-12)
    # one full cycle after the first excursion to each side: from the second +F_m peak to the third
    peaks = np.flatnonzero(F == F_m)
    i0, i1 = peaks[1], peaks[2]
    assert k_g * half_gap >= F_f or k_g == 0.0
    # the sharp slip happens within one load step dF of +-F_f: the trapezoidal work is exact to 2 dF / F_f
    dF = F_m / 20000
    np.testing.assert_allclose(_work(F[i0 : i1 + 1], s[i0 : i1 + 1]), 4 * F_f * half_gap, rtol=2 * dF / F_f)


def test_unloaded_connector_rests_where_friction_balances_its_bending():
    # after an excursion to +F_m, at zero load the shank has sprung back to F_f / k_g (inside the gap)
    F_y, k_e, F_f, k_g, F_m = 10e3, 1e6, 1e3, 2e5, 25e3
    F = np.concatenate([np.linspace(0, F_m, 5001), np.linspace(F_m, 0, 5001)[1:]])
    s = gap_slip(F, F_y, k_e, F_f, k_g)
    assert (F_m - F_y) / k_e > F_f / k_g
    np.testing.assert_allclose(s[-1], F_f / k_g, rtol=1e-12)
    # sharp gap (k_g = 0): it stays at the edge until the load reverses past -F_f
    s0 = gap_slip(np.concatenate([F, [-0.9 * F_f, -1.1 * F_f]]), F_y, k_e, F_f, 0.0)
    np.testing.assert_allclose(s0[-3:], [(F_m - F_y) / k_e, (F_m - F_y) / k_e, 0.0], atol=1e-15)


def test_edges_keep_the_largest_excursion_of_each_side():
    F = np.array([0.0, 20e3, -5e3, 15e3, -30e3, 0.0, 22e3])
    _, e = gap_slip(F, F_y=10e3, k_e=1e6, F_f=1e3, edges=True)
    np.testing.assert_allclose(e[:, 0], [0, 0.01, 0.01, 0.01, 0.01, 0.01, 0.012])
    np.testing.assert_allclose(e[:, 1], [0, 0, 0, 0, 0.02, 0.02, 0.02])


def test_columns_are_independent_and_take_their_own_parameters():
    rng = np.random.default_rng(1)
    F = np.cumsum(rng.normal(0, 2e3, (400, 2)), axis=0)
    both = gap_slip(F, F_y=[8e3, 12e3], k_e=[1e6, 3e6], F_f=[1e3, 2e3], k_g=[0.0, 1e5])
    np.testing.assert_array_equal(both[:, 0], gap_slip(F[:, 0], 8e3, 1e6, 1e3, 0.0))
    np.testing.assert_array_equal(both[:, 1], gap_slip(F[:, 1], 12e3, 3e6, 2e3, 1e5))


def test_friction_above_the_onset_acts_as_the_onset():
    F = _cycles(20e3, 2, 500)
    np.testing.assert_array_equal(gap_slip(F, 10e3, 1e6, 15e3, 3e6), gap_slip(F, 10e3, 1e6, 10e3, 1e6))


def test_bad_parameters_are_refused():
    with pytest.raises(ValueError, match="F_y and k_e must be > 0"):
        gap_slip(np.zeros(3), 0.0, 1e6, 1e3)
    with pytest.raises(ValueError, match="3 values for 2 load columns"):
        gap_slip(np.zeros((3, 2)), [1.0, 2.0, 3.0], 1e6, 1e3)
