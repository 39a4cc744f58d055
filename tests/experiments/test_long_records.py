"""Long records: above max_rows rows, compare and diagnose use every k-th row and say so; the
numbers of a thinned record are those of the same rows read alone; a long file reads whole."""

import warnings

import numpy as np
import pytest

from femast import examples
from femast.errors import DataFileError
from femast.experiments import compare, get_experiment, read_data
from femast.experiments.data import DataWarning
from femast.experiments.rows import thin


def test_thin_keeps_every_kth_row_and_their_file_lines():
    exp = get_experiment("mast-top")
    data = read_data(exp, examples.for_experiment("mast-top"))  # 500 rows
    with pytest.warns(DataWarning, match=r"500 rows; compare uses one row in 3 \(167 rows\)"):
        small = thin(data, 200)
    np.testing.assert_array_equal(small["dx_m"], data["dx_m"][::3])
    np.testing.assert_array_equal(small.lines, data.lines[::3])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert thin(data, 500) is data  # at the limit: untouched, no warning


def test_compare_of_a_thinned_record_is_compare_of_those_rows(tmp_path):
    exp = get_experiment("mast-top")
    data = read_data(exp, examples.for_experiment("mast-top"))
    with pytest.warns(DataWarning):
        thinned = compare(exp, data, max_rows=250)
    alone = compare(exp, data.subset(np.arange(0, data.n, 2)))
    assert thinned.n_samples == alone.n_samples == 250
    assert thinned.rms == pytest.approx(alone.rms, rel=1e-12)
    assert thinned.noise_rms == pytest.approx(alone.noise_rms, rel=1e-12)


def test_a_long_file_reads_whole_and_names_a_bad_cell(tmp_path):
    exp = get_experiment("mast-top")
    rng = np.random.default_rng(0)
    n = 50_000
    cols = {c.name: rng.standard_normal(n) * 1e-3 for c in exp.columns}
    names = list(cols)
    table = np.column_stack([cols[c] for c in names])
    p = tmp_path / "long.csv"
    np.savetxt(p, table, delimiter=",", header=",".join(names), comments="", fmt="%.17g")
    data = read_data(exp, p)
    for c in names:
        np.testing.assert_array_equal(data[c], cols[c])  # %.17g round-trips every double
    text = p.read_text().splitlines()
    text[30_001] = "1.5e-3,abc" + text[30_001][text[30_001].index(",", text[30_001].index(",") + 1) :]
    q = tmp_path / "bad.csv"
    q.write_text("\n".join(text) + "\n")
    with pytest.raises(DataFileError, match=rf"bad.csv line 30002, column '{names[1]}': 'abc' is not a number"):
        read_data(exp, q)


def _many_passes(n, cycles, seed=0):
    """A load cycled ``cycles`` times with a varying amplitude, a residual that repeats with the load
    (a model error) plus white noise of 1e-3: (coordinate, residual)."""
    t = np.linspace(0.0, 1.0, n)
    coord = np.sin(2 * np.pi * cycles * t) * (0.6 + 0.4 * np.abs(np.sin(7.0 * t)))
    return coord, 0.01 * np.sin(5.0 * coord) + np.random.default_rng(seed).normal(0.0, 1e-3, n)


def test_repeated_passes_of_a_long_record_compare_the_nearest_passes_and_keep_the_level():
    from femast.experiments.noise_estimators import CYCLE_MAX_PASS_PAIRS, _pass_pairs, cycle_scatter

    coord, r = _many_passes(10_000, 160)  # 320 passes: ~25 000 pairs of passes in the same direction
    nearest, m = cycle_scatter(coord, r, sigma=1e-3)
    every, m_all = cycle_scatter(coord, r, sigma=1e-3, max_pass_pairs=10**9)
    assert m < m_all / 5  # far fewer rows compared ...
    assert m > 20_000  # ... still tens of thousands: the level's scatter ~ 1 / sqrt(2 m) < 0.5 %
    assert nearest == pytest.approx(1.0, abs=0.03)  # the noise's own level: what repeats cancels
    assert nearest == pytest.approx(every, abs=0.02)
    directions = [1.0, -1.0] * 160
    pairs = _pass_pairs(directions, CYCLE_MAX_PASS_PAIRS)
    assert CYCLE_MAX_PASS_PAIRS <= len(pairs) < CYCLE_MAX_PASS_PAIRS + 320  # whole rounds of nearest passes
    assert all(directions[i] == directions[k] and i < k for i, k in pairs)
    assert {k - i for i, k in pairs} == {2, 4, 6, 8, 10, 12, 14}  # the next passes in the same direction


def test_repeated_passes_of_a_short_record_compare_every_pair():
    from femast.experiments.noise_estimators import cycle_scatter

    coord, r = _many_passes(3000, 20)  # 40 passes, 380 pairs: below the limit
    assert cycle_scatter(coord, r, sigma=1e-3) == cycle_scatter(coord, r, sigma=1e-3, max_pass_pairs=10**9)
