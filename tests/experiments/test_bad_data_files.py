"""A battery of malformed measured-data files.  Each must give a DataFileError
whose message names the item (file, line, column or separator); never a raw exception, a NaN
result or a silent acceptance."""

import math
import warnings

import numpy as np
import pytest

from femast.cli import main
from femast.errors import DataFileError
from femast.experiments import from_arrays, get_experiment, read_data
from femast.experiments.data import DataWarning

N = 20


def _latch_rows(n=N):
    # a plausible latch pull: bead position (mm) and tension difference (N) with a smooth shape
    x = np.linspace(-2.0, 2.0, n)
    return [(f"{a:.6g}", f"{0.3 * a + 0.05 * math.sin(3 * a):.6g}") for a in x]


def _latch_csv(rows=None, header="x_mm,dT_N", sep=","):
    rows = _latch_rows() if rows is None else rows
    return "\n".join([header] + [sep.join(r) for r in rows]) + "\n"


def _mast_csv(mutate=None, header="fx_N,fy_N,fz_N,mx_Nm,my_Nm,mz_Nm,dx_m,dy_m,dz_m,t_s"):
    rows = []
    for i in range(N):
        f = 10.0 * math.sin(0.3 * i)
        rows.append(
            [
                f"{f:.6g}",
                "0",
                "-1",
                "0",
                "0",
                "0",
                f"{1e-5 * f + 1e-7 * i:.6g}",
                f"{2e-6 * f - 3e-8 * i:.6g}",
                f"{1e-7 * i:.6g}",
                f"{0.1 * i:.6g}",
            ]
        )
    if mutate:
        mutate(rows)
    return "\n".join([header] + [",".join(r) for r in rows]) + "\n"


def _set(row, col, value):
    def m(rows):
        rows[row][col] = value

    return m


def _latch_with(row, col, value):
    rows = [list(r) for r in _latch_rows()]
    rows[row][col] = value
    return _latch_csv(rows)


# (id, experiment, file content (str or bytes or None for no file), regex the message must contain)
CASES = [
    ("missing-file", "latch-pull", None, r"no such data file"),
    ("empty-file", "latch-pull", "", r"no header row"),
    ("comments-only", "latch-pull", "# a comment\n# another\n", r"no header row"),
    ("semicolons", "latch-pull", _latch_csv(sep=";", header="x_mm;dT_N"), r"line 1: .*semicolons.*comma-separated"),
    ("tabs", "latch-pull", _latch_csv(sep="\t", header="x_mm\tdT_N"), r"line 1: .*tabs.*comma-separated"),
    ("spaces", "latch-pull", _latch_csv(sep=" ", header="x_mm dT_N"), r"line 1: .*spaces.*comma-separated"),
    ("bars", "latch-pull", _latch_csv(sep="|", header="x_mm|dT_N"), r"line 1: .*bars.*comma-separated"),
    ("decimal-commas", "latch-pull", "x_mm;dT_N\n1,5;2,25\n", r"semicolons.*comma-separated"),
    ("unknown-column", "latch-pull", _latch_csv(header="x_mm,dT_N,temp_C"), r"column 'temp_C' is not a latch-pull"),
    ("missing-column", "latch-pull", "x_mm\n" + "\n".join(str(i) for i in range(N)), r"missing column\(s\) dT_N"),
    ("duplicate-column", "latch-pull", _latch_csv(header="x_mm,dT_N,dT_N"), r"column 'dT_N' appears twice"),
    ("unnamed-column", "latch-pull", _latch_csv(header="x_mm,,dT_N"), r"column 2 of the header has no name"),
    ("wrong-case", "latch-pull", _latch_csv(header="X_MM,dT_N"), r"column 'X_MM'.*did you mean 'x_mm'"),
    ("no-unit", "latch-pull", _latch_csv(header="x,dT_N"), r"column 'x'.*did you mean 'x_mm'"),
    ("short-row", "latch-pull", _latch_csv() + "1.0\n", rf"line {N + 2}: 1 cells but the header"),
    ("long-row", "latch-pull", _latch_csv() + "1.0,2.0,3.0\n", rf"line {N + 2}: 3 cells but the header"),
    ("thousands-separator", "latch-pull", _latch_csv() + "1,000,2\n", rf"line {N + 2}: 3 cells"),
    ("text-cell", "latch-pull", _latch_with(4, 1, "abc"), r"line 6, column 'dT_N': 'abc' is not a number"),
    ("unit-in-cell", "latch-pull", _latch_with(3, 0, "5 mm"), r"line 5, column 'x_mm': '5 mm' is not a number"),
    ("empty-cell", "latch-pull", _latch_with(2, 1, ""), r"line 4, column 'dT_N': an empty cell"),
    ("hex-cell", "latch-pull", _latch_with(2, 0, "0x10"), r"line 4, column 'x_mm': '0x10' is not a number"),
    ("nan-cell", "latch-pull", _latch_with(5, 1, "nan"), r"line 7, column 'dT_N': nan is not a finite number"),
    ("NaN-cell", "latch-pull", _latch_with(5, 1, "NaN"), r"line 7, column 'dT_N': NaN is not a finite"),
    ("inf-cell", "latch-pull", _latch_with(6, 0, "inf"), r"line 8, column 'x_mm': inf is not a finite"),
    ("minus-inf-cell", "latch-pull", _latch_with(6, 1, "-inf"), r"line 8, column 'dT_N': -inf is not a finite"),
    ("overflowing-cell", "latch-pull", _latch_with(6, 1, "1e400"), r"line 8, column 'dT_N': 1e400 is not a finite"),
    ("1e308-cell", "latch-pull", _latch_with(7, 1, "1e308"), r"line 9, column 'dT_N': 1e\+308 N is beyond 1e\+15"),
    ("1e20-input", "latch-pull", _latch_with(7, 0, "-1e20"), r"line 9, column 'x_mm': -1e\+20 mm is beyond"),
    ("1e16-cell", "latch-pull", _latch_with(0, 1, "1e16"), r"line 2, column 'dT_N': 1e\+16 N is beyond"),
    (
        "all-zero-channel",
        "latch-pull",
        _latch_csv([(r[0], "0") for r in _latch_rows()]),
        r"column 'dT_N' is zero on every row",
    ),
    (
        "constant-channel",
        "latch-pull",
        _latch_csv([(r[0], "5.5") for r in _latch_rows()]),
        r"column 'dT_N' has the same value 5.5 N on every row",
    ),
    ("all-zero-file", "latch-pull", _latch_csv([("0", "0")] * N), r"column 'dT_N' is zero on every row"),
    ("too-few-rows", "latch-pull", _latch_csv(_latch_rows(5)), r"5 data row\(s\); latch-pull needs at least 10"),
    ("header-only", "latch-pull", "x_mm,dT_N\n", r"0 data row\(s\)"),
    (
        "time-backwards",
        "latch-pull",
        _latch_csv(
            [(r[0], r[1], f"{(i if i != 7 else 2):g}") for i, r in enumerate(_latch_rows())], header="x_mm,dT_N,t_s"
        ),
        r"line 9, column 't_s': time goes backwards",
    ),
    ("binary", "latch-pull", b"\xff\xfe\x00\x01\x89PNG\r\n", r"not a text \(UTF-8\) CSV file"),
    ("nul-byte", "latch-pull", "x_mm,dT_N\n1.0,\x002.0\n", r"line 2: not valid CSV|line 2, column 'dT_N'"),
    (
        "mast-missing-dz",
        "mast-top",
        _mast_csv(header="fx_N,fy_N,fz_N,mx_Nm,my_Nm,mz_Nm,dx_m,dy_m,dzz_m,t_s"),
        r"column 'dzz_m' is not a mast-top column.*did you mean 'dz_m'",
    ),
    (
        "mast-extra-column",
        "mast-top",
        _mast_csv(
            lambda rows: [r.append("20") for r in rows],
            header="fx_N,fy_N,fz_N,mx_Nm,my_Nm,mz_Nm,dx_m,dy_m,dz_m,t_s,temp_C",
        ),
        r"column 'temp_C' is not a mast-top column",
    ),
    (
        "mast-constant-dx",
        "mast-top",
        _mast_csv(lambda rows: [r.__setitem__(6, "1e-3") for r in rows]),
        r"column 'dx_m' has the same value 0.001 m on every row",
    ),
    (
        "mast-zero-dy",
        "mast-top",
        _mast_csv(lambda rows: [r.__setitem__(7, "0") for r in rows]),
        r"column 'dy_m' is zero on every row",
    ),
    ("mast-1e308-force", "mast-top", _mast_csv(_set(3, 0, "1e308")), r"line 5, column 'fx_N': 1e\+308 N is beyond"),
    ("mast-nan-time", "mast-top", _mast_csv(_set(2, 9, "nan")), r"line 4, column 't_s': nan is not a finite"),
    ("mast-time-backwards", "mast-top", _mast_csv(_set(10, 9, "0.05")), r"line 12, column 't_s': time goes backwards"),
    ("mast-semicolons", "mast-top", _mast_csv().replace(",", ";"), r"semicolons.*comma-separated"),
    ("mast-text-moment", "mast-top", _mast_csv(_set(1, 3, "n/a")), r"line 3, column 'mx_Nm': 'n/a' is not a number"),
]


@pytest.mark.parametrize("name,experiment,content,message", CASES, ids=[c[0] for c in CASES])
def test_malformed_data_file(name, experiment, content, message, tmp_path):
    path = tmp_path / f"{name}.csv"
    if isinstance(content, bytes):
        path.write_bytes(content)
    elif content is not None:
        path.write_text(content)
    with pytest.raises(DataFileError) as info:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DataWarning)
            read_data(get_experiment(experiment), path)
    msg = str(info.value)
    assert f"{name}.csv" in msg, msg  # the file is named
    assert __import__("re").search(message, msg), msg  # and the item (line, column, separator)


ARRAY_CASES = [
    ("lengths-differ", dict(x_mm=np.arange(12.0), dT_N=np.arange(11.0)), r"different lengths"),
    ("nan", dict(x_mm=np.arange(12.0), dT_N=np.r_[np.arange(11.0), np.nan]), r"row 11, column 'dT_N'"),
    ("inf", dict(x_mm=np.arange(12.0), dT_N=np.r_[np.inf, np.arange(11.0)]), r"row 0, column 'dT_N'"),
    ("huge", dict(x_mm=np.arange(12.0) * 1e16, dT_N=np.arange(12.0)), r"column 'x_mm': 1e\+16 mm is beyond"),
]


@pytest.mark.parametrize("name,cols,message", ARRAY_CASES, ids=[c[0] for c in ARRAY_CASES])
def test_malformed_arrays(name, cols, message):
    with pytest.raises(DataFileError, match=message):
        from_arrays(get_experiment("latch-pull"), **cols)


def test_battery_size():
    assert len(CASES) + len(ARRAY_CASES) >= 40


def test_duplicated_rows_warn_and_say_how_they_bias_the_noise(tmp_path):
    rows = _latch_rows()
    doubled = [r for r in rows for _ in range(2)]
    path = tmp_path / "doubled.csv"
    path.write_text(_latch_csv(doubled))
    with pytest.warns(
        DataWarning,
        match=r"doubled.csv: 20 row\(s\) repeat the row before them exactly "
        r"\(line\(s\) 3, 5, 7.*noise floor too small",
    ):
        data = read_data(get_experiment("latch-pull"), path)
    assert data.n == 2 * N  # accepted, not altered


def test_the_noise_floor_effect_the_warning_names():
    """The warning's claim, checked: doubling every row of pure white noise roughly halves the
    second-difference noise estimate (of a generator sharing nothing with noise_floor)."""
    from femast.experiments.residuals import noise_floor

    rng = np.random.default_rng(16)
    r = rng.normal(0.0, 1.0, 4000)
    single, doubled = noise_floor(r), noise_floor(np.repeat(r, 2))
    assert 0.9 < single < 1.1  # the estimator is right on white noise (4000 samples: ~3%)
    assert 0.3 < doubled / single < 0.75  # doubled rows: well below the truth


def test_cli_reports_a_bad_data_file_in_one_line(tmp_path, capsys):
    path = tmp_path / "semi.csv"
    path.write_text(_latch_csv(sep=";", header="x_mm;dT_N"))
    assert main(["compare", "latch-pull", str(path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "semi.csv line 1" in err[0] and "comma-separated" in err[0]
