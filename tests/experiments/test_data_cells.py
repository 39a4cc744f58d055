"""A data file's cells are read as a CSV file writes numbers, and its path must be a regular file:
"1_0" is not 10 and full-width "１２" is not 12 (Python's float() reads both), a negative frequency
is refused, and a folder, FIFO or loop of links given as the data file is named as what it is."""

import os

import pytest

from femast.errors import DataFileError
from femast.experiments import get_experiment, read_data

LATCH = "x_mm,dT_N\n" + "".join(f"{0.1 * k:.3g},{0.3 * k + 0.01 * k * k:.4g}\n" for k in range(-10, 11))


def _with_cell(text):
    rows = LATCH.splitlines()
    cells = rows[5].split(",")
    cells[1] = text
    rows[5] = ",".join(cells)
    return "\n".join(rows) + "\n"


@pytest.mark.parametrize("cell", ["1_0", "１２", "٣", "1,5".replace(",", ";"), "0x10", "1e5_0"])
def test_a_cell_that_is_not_a_plain_decimal_number_is_refused(tmp_path, cell):
    p = tmp_path / "pull.csv"
    p.write_text(_with_cell(cell), encoding="utf-8")
    with pytest.raises(DataFileError, match=rf"line 6, column 'dT_N': '{cell}' is not a number"):
        read_data(get_experiment("latch-pull"), p)


@pytest.mark.parametrize(
    "cell, value", [("12", 12.0), ("-1.5e-3", -1.5e-3), (".5", 0.5), ("+3.", 3.0), ("2E+2", 200.0)]
)
def test_plain_decimal_numbers_are_read(tmp_path, cell, value):
    p = tmp_path / "pull.csv"
    p.write_text(_with_cell(cell))
    assert read_data(get_experiment("latch-pull"), p).columns["dT_N"][4] == value


def test_a_negative_frequency_is_refused(tmp_path):
    p = tmp_path / "modes.csv"
    p.write_text("mode,f_Hz\n1,3.2\n2,-11.5\n3,25.0\n")
    with pytest.raises(DataFileError, match=r"line 3, column 'f_Hz': -11.5 Hz; a value in Hz is positive"):
        read_data(get_experiment("vibration"), p)


def test_a_path_that_is_not_a_data_file_is_named_as_what_it_is(tmp_path):
    exp = get_experiment("latch-pull")
    folder = tmp_path / "run1"
    folder.mkdir()
    (folder / "pull.csv").write_text(LATCH)
    with pytest.raises(DataFileError, match=r"run1: a folder, not a data file \(it holds pull.csv\)"):
        read_data(exp, folder)
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    with pytest.raises(DataFileError, match=r"pipe.csv: a FIFO \(named pipe\), not a data file"):
        read_data(exp, fifo)  # (refused before it is opened: opening a FIFO would wait for a writer)
    loop = tmp_path / "loop.csv"
    loop.symlink_to(loop)
    with pytest.raises(DataFileError, match=r"loop.csv: a loop of symbolic links"):
        read_data(exp, loop)
    dangling = tmp_path / "gone.csv"
    dangling.symlink_to(tmp_path / "moved.csv")
    with pytest.raises(DataFileError, match=r"gone.csv: a symbolic link to .*moved.csv, which does not exist"):
        read_data(exp, dangling)
    link = tmp_path / "link.csv"
    link.symlink_to(folder / "pull.csv")  # a link to a data file is the user's choice: read
    assert read_data(exp, link).n == 21
