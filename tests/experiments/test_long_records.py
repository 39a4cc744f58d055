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
