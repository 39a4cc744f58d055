"""Measured-data files: format, example files, and bad input."""

from pathlib import Path

import numpy as np
import pytest

from femast.cli import main
from femast.errors import DataFileError, ModelError
from femast.experiments import compare, diagnose, from_arrays, get_experiment, read_data, write_data
from femast.rigs.synthetic import mast_top_data

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "femast" / "examples"
MT = get_experiment("mast-top")
HEADER = "fx_N,fy_N,fz_N,mx_Nm,my_Nm,mz_Nm,dx_m,dy_m,dz_m"


def _write(tmp_path, lines, name="d.csv"):
    p = tmp_path / name
    p.write_text("\n".join(lines) + "\n")
    return p


def _rows(n=12, cols=9):
    return [",".join(f"{0.1 * (i + j):g}" for j in range(cols)) for i in range(n)]


@pytest.mark.parametrize(
    "name,exp",
    [
        ("mast_top_example.csv", "mast-top"),
        ("latch_pull_example.csv", "latch-pull"),
        ("tip_cycle_table1.csv", "tip-cycle"),
        ("bay_torsion_format.csv", "bay-torsion"),
    ],
)
def test_example_files_follow_their_format(name, exp):
    e = get_experiment(exp)
    d = read_data(e, DATA / name)
    assert d.n >= e.min_rows
    assert all(c.name in d.columns for c in e.columns if c.required)


def test_tip_cycle_example_is_adam_table1_in_si():
    d = read_data(get_experiment("tip-cycle"), DATA / "tip_cycle_table1.csv")
    assert d.n == 13
    # the file holds 6 significant digits
    np.testing.assert_allclose(d["ux_m"][1], 1740e-6, rtol=1e-5)  # 1740 um under M + F
    np.testing.assert_allclose(d["rz_rad"][1], np.radians(3030 / 3600), rtol=1e-5)  # 3030 arcsec
    np.testing.assert_allclose(d["mz_Nm"][:4], [0, 6.8, 0, -6.8])


def test_write_read_round_trip_with_comments_and_time(tmp_path):
    data, _ = mast_top_data(seed=1)
    data.columns["t_s"] = np.arange(data.n) * 0.1
    p = write_data(tmp_path / "x.csv", data, MT, comments=["a comment", "another"])
    back = read_data(MT, p)
    for k in data.columns:
        np.testing.assert_allclose(back[k], data[k], rtol=1e-8)  # written with 9 significant digits
    assert back.lines[0] == 4  # two comments and the header come first


def test_missing_column(tmp_path):
    p = _write(tmp_path, [HEADER.replace(",dz_m", "")] + _rows(cols=8))
    with pytest.raises(
        DataFileError, match=r"d\.csv line 1: missing column\(s\) dz_m; mast-top needs .*dx_m, dy_m, dz_m"
    ):
        read_data(MT, p)


def test_extra_column(tmp_path):
    p = _write(tmp_path, [HEADER + ",temp_C"] + _rows(cols=10))
    with pytest.raises(
        DataFileError,
        match=r"d\.csv line 1: column 'temp_C' is not a mast-top column; accepted "
        r"columns: fx_N, .*dz_m, t_s \(optional\)",
    ):
        read_data(MT, p)


def test_misnamed_column_suggests_the_right_name(tmp_path):
    p = _write(tmp_path, ["# a comment first", HEADER.replace("fy_N", "fy")] + _rows())
    with pytest.raises(DataFileError, match=r"line 2: column 'fy' is not a mast-top column \(did you mean 'fy_N'\?\)"):
        read_data(MT, p)
    p = _write(tmp_path, [HEADER.replace("dx_m", "dx_mn")] + _rows())  # a typo, not a unit
    with pytest.raises(DataFileError, match=r"did you mean 'dx_m'"):
        read_data(MT, p)
    # a unit suffix is a unit: dx_mm is read as dx_m, in mm (docs/experiments.md, "Units of the data")
    p = _write(tmp_path, [HEADER.replace("dx_m", "dx_mm")] + _rows())
    q = _write(tmp_path, [HEADER] + _rows(), name="m.csv")
    np.testing.assert_allclose(read_data(MT, p)["dx_m"], 1e-3 * read_data(MT, q)["dx_m"], rtol=1e-15)


def test_nan_cell(tmp_path):
    rows = _rows()
    rows[4] = rows[4].replace("0.5,", "nan,", 1)
    p = _write(tmp_path, [HEADER] + rows)
    with pytest.raises(DataFileError, match=r"d\.csv line 6, column 'fy_N': nan is not a finite number.* in N"):
        read_data(MT, p)


def test_non_numeric_and_empty_cells(tmp_path):
    rows = _rows()
    cells = rows[2].split(",")
    cells[7] = "1.2.3"
    rows[2] = ",".join(cells)
    p = _write(tmp_path, [HEADER] + rows)
    with pytest.raises(
        DataFileError,
        match=r"line 4, column 'dy_m': '1\.2\.3' is not a number; every cell must be a "
        r"decimal number in m",
    ):
        read_data(MT, p)
    rows = _rows()
    cells = rows[0].split(",")
    cells[3] = " "
    rows[0] = ",".join(cells)
    p = _write(tmp_path, [HEADER] + rows)
    with pytest.raises(DataFileError, match=r"line 2, column 'mx_Nm': an empty cell"):
        read_data(MT, p)


def test_ragged_row(tmp_path):
    rows = _rows()
    rows[5] += ",7"
    p = _write(tmp_path, [HEADER] + rows)
    with pytest.raises(DataFileError, match=r"line 7: 10 cells but the header \(line 1\) has 9 columns"):
        read_data(MT, p)


def test_too_few_rows(tmp_path):
    p = _write(tmp_path, [HEADER] + _rows(n=4))
    with pytest.raises(DataFileError, match=r"d\.csv: 4 data row\(s\); mast-top needs at least 10"):
        read_data(MT, p)


def test_no_header_duplicate_column_time_backwards_missing_file(tmp_path):
    with pytest.raises(DataFileError, match=r"no header row; the first non-comment line must name the columns: fx_N"):
        read_data(MT, _write(tmp_path, ["# only a comment", ""]))
    with pytest.raises(DataFileError, match=r"column 'fx_N' appears twice"):
        read_data(MT, _write(tmp_path, ["fx_N," + HEADER] + _rows(cols=10)))
    rows = [r + f",{t}" for r, t in zip(_rows(), [0, 1, 2, 3, 2.5, 5, 6, 7, 8, 9, 10, 11])]
    with pytest.raises(DataFileError, match=r"line 6, column 't_s': time goes backwards"):
        read_data(MT, _write(tmp_path, [HEADER + ",t_s"] + rows))
    with pytest.raises(DataFileError, match=r"no such data file"):
        read_data(MT, tmp_path / "nope.csv")


def test_latch_pull_bad_column_lists_the_latch_columns(tmp_path):
    p = _write(tmp_path, ["x_mn,dT_N"] + [f"{i},{i}" for i in range(12)])
    with pytest.raises(
        DataFileError,
        match=r"column 'x_mn' is not a latch-pull column \(did you mean 'x_mm'\?\); "
        r"accepted columns: x_mm, dT_N, side \(optional\), t_s \(optional\)",
    ):
        read_data(get_experiment("latch-pull"), p)


def test_from_arrays_checks_too():
    with pytest.raises(DataFileError, match="row 3, column 'dT_N'"):
        from_arrays(get_experiment("latch-pull"), x_mm=np.zeros(12), dT_N=np.r_[0, 0, 0, np.nan, np.zeros(8)])


def test_unknown_effect_names_the_effect_and_the_accepted_ones():
    data, _ = mast_top_data(seed=2)
    with pytest.raises(
        ModelError, match=r"unknown effect 'backlash' for mast-top; accepted effects: .*joint_clearance"
    ):
        compare(MT, data, ["backlash"])
    with pytest.raises(
        ModelError,
        match=r"effect 'latch_hysteresis' does not apply to mast-top \(it applies to "
        r"latch-pull.*accepted effects: .*friction_hysteresis",
    ):
        compare(MT, data, ["latch_hysteresis"])
    with pytest.raises(ModelError, match=r"effect 'ball_joint_friction' does not apply to mast-top"):
        diagnose(MT, data, ["ball_joint_friction"], workers=1)


PENDING_SCRIPT = """
from femast.experiments import Column, Experiment
experiment = Experiment(name="rig-x", title="a rig whose model is not written yet",
                        columns=(Column("F_N", "N"), Column("u_m", "m")), channels=("u_m",), model=None,
                        doc="Pending a model: the rig's FE model is not built yet.")
"""


def test_unknown_and_pending_experiments(tmp_path):
    with pytest.raises(
        ModelError,
        match=r"unknown experiment 'mast' \(did you mean 'mast-top'\?\); accepted: mast-top, latch-pull, bay-torsion, "
        r"tip-cycle, vibration, platform-pose, joint-test or the path of a Python script",
    ):
        get_experiment("mast")
    # an experiment may be registered with its data format before its model exists (model=None)
    script = tmp_path / "rig_x.py"
    script.write_text(PENDING_SCRIPT)
    rig = get_experiment(str(script))
    data = from_arrays(rig, F_N=np.arange(12.0), u_m=np.linspace(0.0, 1e-3, 12))  # the format is checked already
    with pytest.raises(
        ModelError,
        match=r"experiment 'rig-x' is registered with its data format but is pending "
        r"a model, so compare cannot run yet",
    ):
        compare(rig, data)
    with pytest.raises(ModelError, match="pending a model"):
        diagnose(rig, data)
    with pytest.raises(ModelError, match=r"unknown option\(s\) L_m; accepted: .*r_oc_m"):
        get_experiment("mast-top", L_m=3.0)


def test_cli_reports_bad_input_and_exits_2(tmp_path, capsys):
    p = _write(tmp_path, [HEADER.replace("fy_N", "fy")] + _rows())
    assert main(["compare", "mast-top", str(p), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "femast: error:" in err and "d.csv line 1: column 'fy'" in err and "fy_N" in err
    assert (
        main(
            [
                "compare",
                "mast-top",
                str(DATA / "mast_top_example.csv"),
                "--effects",
                "nonsense",
                "--out",
                str(tmp_path / "o"),
            ]
        )
        == 2
    )
    assert "unknown effect 'nonsense' for mast-top; accepted effects:" in capsys.readouterr().err
    script = tmp_path / "rig_x.py"
    script.write_text(PENDING_SCRIPT)
    rows = ["F_N,u_m"] + [f"{i},0" for i in range(12)]
    assert main(["diagnose", str(script), str(_write(tmp_path, rows, "rig.csv"))]) == 2
    assert "pending a model" in capsys.readouterr().err
