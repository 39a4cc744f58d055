"""Reading and writing measured-data files (CSV with a header row, rows in time order).

Format
------
* Plain CSV (comma-separated, read with the standard :mod:`csv` module).  Lines starting
  with ``#`` and empty lines are comments and are skipped anywhere in the file.
* The first other line is the header: the column names of the experiment, unit suffix
  included (``fx_N``, ``x_mm``), in any order.  Every required column must be present, an
  optional column may be, and no other column is accepted.  ``t_s`` (time, s) is accepted
  by every experiment.
* Each further line is one sample, rows in time order, one finite decimal number per column
  (a column with ``codes`` also accepts its words, e.g. ``out`` / ``in`` for the loaded side of a
  latch pull test).

Every error is a :class:`~femast.errors.DataFileError` naming the file, the line and the
column, and listing the accepted values.  Beyond the format, the values are checked:
every value within 1e15 of its unit (a larger one is a corrupt cell and would overflow the fit);
no measured channel (``experiment.channels``) all zero or constant (nothing was measured: a
disconnected sensor or a wrong column); a file separated by ';', tabs or '|' is refused with an
error saying femast reads comma-separated files.  Consecutive identical rows are accepted with a
:class:`DataWarning`: a repeated sample weighs twice in a fit, and its zero difference from the
previous row makes the noise floor estimated from second differences too small (every row doubled
roughly halves it), so the "at the noise floor" verdicts become too strict.  Not warned: a row that
repeats a reading at rest at the recorder's resolution (every column on a grid of counts, the row
before moved by at most one count: the same counts read again, a genuine sample).
"""

from __future__ import annotations

import csv
import difflib
import errno
import math
import os
import re
import stat
import warnings
from pathlib import Path

import numpy as np

from .. import progress
from ..errors import DataFileError
from .core import Experiment, Measured
from .resolution import resolution

#: largest accepted magnitude of a data value in the unit of its column
MAX_VALUE = 1e15


class DataWarning(UserWarning):
    """A data file is readable but has something that biases the results (duplicated rows)."""


def _separator_error(path, line, text, exp):
    for sep, name in ((";", "semicolons (';')"), ("\t", "tabs"), ("|", "bars ('|')")):
        if sep in text:
            return DataFileError(
                f"{path} line {line}: the header is separated by {name}; femast reads "
                "comma-separated files (CSV with ',' between columns and '.' as the decimal "
                f"point): save the file as comma-separated. {exp.name} accepts: {_accepted(exp)}"
            )
    if len(text.split()) > 1:
        return DataFileError(
            f"{path} line {line}: the header is separated by spaces; femast reads comma-separated "
            f"files (CSV with ',' between columns): save the file as comma-separated. {exp.name} "
            f"accepts: {_accepted(exp)}"
        )
    return None


#: a cell's number as a CSV file writes it: ASCII digits, an optional sign, point and exponent
#: (and the words nan / inf, refused as not finite below)
_DECIMAL = re.compile(r"^[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?$|^[+-]?(?:nan|inf|infinity)$", re.ASCII | re.I)
#: units whose values are positive by nature (a frequency of -3 Hz is a sign or column error)
POSITIVE_UNITS = ("Hz",)


def check_values(exp: Experiment, cols: dict, path: str, lines, measured: bool = True) -> None:
    """Plausibility of the values of a data set (see the module docstring): magnitudes; for
    ``measured`` data (a file) also all-zero or constant measured channels (errors) and consecutive
    duplicated rows (a :class:`DataWarning`).  Arrays built in code (:func:`from_arrays`, e.g. an
    experiment's model-side placeholders) get the magnitude check only."""
    for name, a in cols.items():
        big = np.flatnonzero(np.abs(a) > MAX_VALUE)
        if big.size:
            i = int(big[0])
            unit = exp.column(name).unit
            raise DataFileError(
                f"{path} line {lines[i]}, column '{name}': {a[i]:g} {unit} is beyond {MAX_VALUE:g} "
                f"{unit}, not a plausible measurement (a corrupt cell?); fix or remove the row"
            )
        unit = exp.column(name).unit
        if measured and unit in POSITIVE_UNITS and np.any(a <= 0.0):
            i = int(np.flatnonzero(a <= 0.0)[0])
            raise DataFileError(
                f"{path} line {lines[i]}, column '{name}': {a[i]:g} {unit}; a value in {unit} is positive "
                "(a sign error, or the wrong column?); fix or remove the row"
            )
    if not measured:
        return
    for name in exp.channels:
        if name not in cols or cols[name].size == 0:
            continue
        a = cols[name]
        unit = exp.column(name).unit
        if np.all(a == 0.0):
            raise DataFileError(
                f"{path}: column '{name}' is zero on every row: nothing was measured (a disconnected "
                f"sensor, or the wrong column?); give the measured {name} in {unit}"
            )
        if np.all(a == a[0]):
            raise DataFileError(
                f"{path}: column '{name}' has the same value {a[0]:g} {unit} on every row: a constant "
                "channel carries no measurement (a stuck sensor, or a fill value?); give the "
                f"measured {name}"
            )
    if cols:
        table = np.column_stack(list(cols.values()))
        if len(table) > 1:
            dup = np.flatnonzero(np.all(table[1:] == table[:-1], axis=1)) + 1
            dup = dup[~_repeats_at_rest(table, dup)]
            if dup.size:
                shown = ", ".join(str(lines[i]) for i in dup[:5]) + (", ..." if dup.size > 5 else "")
                warnings.warn(
                    f"{path}: {dup.size} row(s) repeat the row before them exactly (line(s) {shown}): a "
                    "repeated sample counts twice in a fit, and its zero difference from the previous "
                    "row makes the estimated noise floor too small (every row doubled roughly halves "
                    "it), so fits look worse than the noise; remove the duplicated rows",
                    DataWarning,
                    stacklevel=3,
                )


def _repeats_at_rest(table, dup) -> np.ndarray:
    """(len(dup),) bool: which repeated rows ``dup`` (indices into ``table`` (n, k), each equal to the
    row before it) are a reading at rest at the recorder's resolution rather than a sample written
    twice: every column lies on a grid (:func:`~femast.experiments.resolution.resolution`) and the
    row before the pair moved by at most one step in every column -- the signal was at rest within a
    count, where the same counts are read again (a load cell flickering between 10 and 20 N at rest
    reads 20, 10, 20, 20)."""
    q = np.array([resolution(table[:, j]) for j in range(table.shape[1])])
    at_rest = np.zeros(dup.size, bool)
    if dup.size == 0 or np.any(q <= 0.0):
        return at_rest
    for i, r in enumerate(dup):
        if r >= 2:
            at_rest[i] = bool(np.all(np.abs(table[r - 1] - table[r - 2]) <= 1.001 * q))
    return at_rest


def _accepted(exp: Experiment) -> str:
    parts = [c.name + ("" if c.required else " (optional)") for c in exp.all_columns]
    return ", ".join(parts)


def _suggest(name: str, choices) -> str:
    close = difflib.get_close_matches(name, list(choices), n=1, cutoff=0.5)
    if not close:  # 'fx' -> 'fx_N': compare without the unit suffix
        stems = {c.rsplit("_", 1)[0].lower(): c for c in choices}
        hit = stems.get(name.rsplit("_", 1)[0].lower())
        close = [hit] if hit else []
    return f" (did you mean '{close[0]}'?)" if close else ""


def check_header(exp: Experiment, header, path: str = "<arrays>", line: int = 1) -> list:
    """Check the column names of a data file against the experiment; return them stripped."""
    names = [h.strip() for h in header]
    known = [c.name for c in exp.all_columns]
    where = f"{path} line {line}"
    for i, h in enumerate(names):
        if not h:
            raise DataFileError(
                f"{where}: column {i + 1} of the header has no name; {exp.name} accepts: {_accepted(exp)}"
            )
    seen = set()
    for h in names:
        if h in seen:
            raise DataFileError(
                f"{where}: column '{h}' appears twice in the header; {exp.name} accepts: {_accepted(exp)}"
            )
        seen.add(h)
    unknown = [h for h in names if h not in known]
    if unknown:
        h = unknown[0]
        raise DataFileError(
            f"{where}: column '{h}' is not a {exp.name} column{_suggest(h, known)}; accepted columns: {_accepted(exp)}"
        )
    missing = [c.name for c in exp.all_columns if c.required and c.name not in names]
    if missing:
        raise DataFileError(
            f"{where}: missing column(s) {', '.join(missing)}; {exp.name} needs "
            f"{', '.join(c.name for c in exp.all_columns if c.required)}"
            f" and accepts {_accepted(exp)}"
        )
    return names


def _fast_values(exp: Experiment, header, rows, ncol: int, column_done=None):
    """The (rows, columns) values when every row has ``ncol`` cells and every cell of a column
    without words (codes) is a plain ASCII decimal number, finite; None otherwise (the cell-by-cell
    reader then finds and names the first bad cell).  ``column_done()`` is called after each column
    (a long record's progress)."""
    if any(len(cells) != ncol for cells in rows):
        return None
    values = np.empty((len(rows), ncol))
    for c, column in enumerate(zip(*rows)) if rows else ():
        if exp.column(header[c]).codes:
            return None
        text = ",".join(column)
        if not text.isascii() or "_" in text:  # digit separators, other scripts' digits: looked at one by one
            return None
        try:
            values[:, c] = np.array(column, dtype=float)
        except ValueError:
            return None
        if column_done is not None:
            column_done()
    if not np.all(np.isfinite(values)):
        return None
    return values


def _cell_values(exp: Experiment, header, rows, lines, path, header_line) -> np.ndarray:
    """The values read cell by cell, raising DataFileError at the first bad cell."""
    ncol = len(header)
    values = np.empty((len(rows), ncol))
    for r, (cells, line) in enumerate(zip(rows, lines)):
        if len(cells) != ncol:
            raise DataFileError(
                f"{path} line {line}: {len(cells)} cells but the header (line {header_line}) has "
                f"{ncol} columns ({', '.join(header)})"
            )
        for c, text in enumerate(cells):
            col = exp.column(header[c])
            s = text.strip()
            codes = dict((t.lower(), v) for t, v in col.codes)
            try:
                if s.lower() in codes:
                    v = codes[s.lower()]
                elif _DECIMAL.match(s):
                    v = float(s)
                else:  # (Python's float() also reads "1_0" as 10 and full-width digits "１２" as 12)
                    raise ValueError(s)
            except ValueError:
                what = "an empty cell" if not s else f"'{s}' is not a number"
                words = f" or one of {', '.join(t for t, _ in col.codes)}" if col.codes else ""
                raise DataFileError(
                    f"{path} line {line}, column '{header[c]}': {what}; every cell must be a "
                    f"decimal number in {col.unit}{words}"
                ) from None
            if not math.isfinite(v):
                raise DataFileError(
                    f"{path} line {line}, column '{header[c]}': {s} is not a finite number; "
                    f"every cell must be a finite decimal number in {col.unit} "
                    "(remove the row or fill in the value)"
                )
            values[r, c] = v
    return values


def _group_labels(header, rows, lines, path) -> list:
    """The labels of the ``group`` column (any text), each cell replaced by ``0`` for the number
    reader; [] without a group column.  Rows of the wrong length are left to the number reader."""
    if "group" not in header:
        return []
    g, labels = header.index("group"), []
    for cells, line in zip(rows, lines):
        if len(cells) != len(header):
            continue
        label = cells[g].strip()
        if not label:
            raise DataFileError(f"{path} line {line}, column 'group': an empty cell; every row needs its group's label")
        labels.append(label)
        cells[g] = "0"
    return labels


def _check_data_path(path: Path) -> None:
    """A DataFileError naming what ``path`` is if it is not a readable regular file (a folder, a FIFO
    or device, a link to nothing or a loop of links), before anything is opened (a FIFO would block)."""
    try:
        st = os.stat(path)  # (follows a link to the data file: that is the user's choice)
    except FileNotFoundError:
        if path.is_symlink():
            raise DataFileError(
                f"{path}: a symbolic link to {os.readlink(path)}, which does not exist; point it at the data file"
            ) from None
        raise DataFileError(f"{path}: no such data file") from None
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise DataFileError(
                f"{path}: a loop of symbolic links (it leads back to itself); point it at the data file"
            ) from None
        raise DataFileError(f"{path}: cannot be read ({exc.strerror}); check the path and its permissions") from None
    if stat.S_ISDIR(st.st_mode):
        csvs = sorted(p.name for p in path.glob("*.csv"))[:3]
        hint = f" (it holds {', '.join(csvs)})" if csvs else ""
        raise DataFileError(f"{path}: a folder, not a data file{hint}; give the CSV file itself")
    if not stat.S_ISREG(st.st_mode):
        kind = "a FIFO (named pipe)" if stat.S_ISFIFO(st.st_mode) else "a device or socket"
        raise DataFileError(f"{path}: {kind}, not a data file; femast reads measured data from a regular CSV file")
    if not os.access(path, os.R_OK):
        raise DataFileError(f"{path}: cannot be read (permission denied); check its permissions")


def read_data(exp: Experiment, path, units=None, *, time_continuous: bool = False, offsets: bool = False) -> Measured:
    """Read and check a measured-data file of experiment ``exp`` (see the module docstring), or
    several: ``path`` a list of files, each a group of the data (its rows' ``group`` labels prefixed
    by the file name where it has a ``group`` column).

    A header may name a column in another unit (``dx_mm`` for ``dx_m``): its values are converted
    (:mod:`femast.experiments.units`).  ``units``: ``{column: unit}`` or ``"dx_m=mm,fx_N=lbf"``,
    the unit the values of a column are really in (a header that says the wrong unit).
    time_continuous : the files (or groups) are one test whose time goes on from one to the next,
        rather than separate tests whose time restarts (:class:`~femast.experiments.measured.Measured`).
    offsets : fit a zero of its own for every group and channel.

    Returns a :class:`~femast.experiments.measured.Measured` whose ``lines`` give the file line of
    every row.  Raises :class:`~femast.errors.DataFileError` on any malformed content.
    """
    from .units import CONFIRMED

    if isinstance(path, (list, tuple)):
        if len(path) == 1:
            path = path[0]
        else:
            parts = [read_data(exp, p, units) for p in path]
            data = combine(parts, time_continuous=time_continuous, offsets=offsets)
            data.cache[CONFIRMED] = parts[0].cache.get(CONFIRMED, ())  # the same --units for every file
            return data
    data = _read_one(exp, path, units)
    data.time_continuous, data.offsets = bool(time_continuous), bool(offsets)
    return data


def _read_one(exp: Experiment, path, units) -> Measured:
    from . import units as _units

    override = _units.parse_override(units)
    path = Path(path)
    _check_data_path(path)
    header, header_line, rows, lines = None, 0, [], []
    with open(path, newline="", encoding="utf-8-sig") as fh, progress.task(f"reading {path.name}", "rows", 2.0) as bar:
        reader = csv.reader(fh)
        try:
            for cells in reader:
                if len(rows) % 100_000 == 99_999:  # a long record: the count moves
                    bar.update(100_000)
                line = reader.line_num
                if not cells or not "".join(cells).strip() or cells[0].lstrip().startswith("#"):
                    continue
                if header is None:
                    if len(cells) == 1:
                        err = _separator_error(path, line, cells[0], exp)
                        if err is not None:
                            raise err
                    named, factors = _units.header_columns(exp, [c.strip() for c in cells], f"{path} line {line}")
                    header, header_line = check_header(exp, named, str(path), line), line
                    continue
                rows.append(cells)
                lines.append(line)
        except csv.Error as exc:
            raise DataFileError(f"{path} line {reader.line_num}: not valid CSV ({exc})") from None
        except UnicodeDecodeError as exc:
            raise DataFileError(f"{path}: not a text (UTF-8) CSV file ({exc.reason})") from None
    if header is None:
        raise DataFileError(
            f"{path}: no header row; the first non-comment line must name the columns: {_accepted(exp)}"
        )
    ncol = len(header)
    labels = _group_labels(header, rows, lines, path)
    with progress.task(f"reading {path.name}: numbers of {len(rows)} rows", "columns", 2.0) as bar:
        values = _fast_values(exp, header, rows, ncol, bar.update)  # whole columns: 2 million rows in seconds
        if values is None:  # some cell needs looking at: cell by cell, naming the first bad one
            values = _cell_values(exp, header, rows, lines, path, header_line)
    if len(rows) < exp.min_rows:
        raise DataFileError(
            f"{path}: {len(rows)} data row(s); {exp.name} needs at least {exp.min_rows} (one per sample, in time order)"
        )
    scaled = _units.override_factors(exp, header, override, str(path))
    for i, h in enumerate(header):
        f = factors[i] * scaled.get(h, 1.0)
        if f != 1.0:
            values[:, i] *= f
    cols = {h: values[:, i] for i, h in enumerate(header) if h != "group"}
    check_values(exp, cols, str(path), lines)
    if "t_s" in cols and np.any(np.diff(cols["t_s"]) < 0):
        bad = int(np.flatnonzero(np.diff(cols["t_s"]) < 0)[0]) + 1
        raise DataFileError(
            f"{path} line {lines[bad]}, column 't_s': time goes backwards "
            f"({cols['t_s'][bad - 1]:g} s then {cols['t_s'][bad]:g} s); rows must be in time order"
        )
    groups, names = group_codes(labels) if labels else (None, ())
    data = Measured(exp.name, cols, str(path), np.asarray(lines), groups=groups, group_names=names)
    data.cache[_units.CONFIRMED] = tuple(c for c, f in scaled.items() if f == 1.0)  # --units dx_m=m
    return data


def group_codes(labels) -> tuple:
    """``(codes (n,) int, names)`` of group labels, numbered in order of first appearance."""
    names = list(dict.fromkeys(str(x) for x in labels))
    index = {n: i for i, n in enumerate(names)}
    return np.array([index[str(x)] for x in labels], dtype=int), tuple(names)


def combine(parts, *, time_continuous: bool = False, offsets: bool = False) -> Measured:
    """One data set of several (files, runs), each a group (its own groups kept, labelled
    ``part/label``).  With ``time_continuous`` the time of each part is shifted to start one of its
    steps after the end of the part before (one test recorded in parts); otherwise each part's time
    restarts (separate tests)."""
    parts = list(parts)
    if not parts:
        raise DataFileError("no data to combine")
    cols = set(parts[0].columns)
    for d in parts[1:]:
        if set(d.columns) != cols:
            raise DataFileError(
                f"{d.path}: its columns ({', '.join(sorted(d.columns))}) differ from those of {parts[0].path} "
                f"({', '.join(sorted(cols))}); give every file the same columns"
            )
    labels, end = [], None
    columns = {k: [] for k in parts[0].columns}
    for d in parts:
        stem = Path(d.path).stem
        if d.groups is None:
            labels += [stem] * d.n
        else:
            labels += [f"{stem}/{d.group_names[g]}" for g in d.groups]
        for k, v in d.columns.items():
            if k == "t_s" and time_continuous and end is not None:
                step = float(np.median(np.diff(v))) if v.size > 1 else 1.0
                v = v - v[0] + end + max(step, 0.0)
            columns[k].append(v)
        if "t_s" in columns:
            end = float(columns["t_s"][-1][-1])
    groups, names = group_codes(labels)
    return Measured(
        parts[0].experiment,
        {k: np.concatenate(v) for k, v in columns.items()},
        ", ".join(str(d.path) for d in parts),
        np.concatenate([d.lines for d in parts]),
        groups=groups,
        group_names=names,
        time_continuous=time_continuous,
        offsets=offsets,
    )


def from_arrays(exp: Experiment, **columns) -> Measured:
    """Build :class:`Measured` data from arrays (same checks as :func:`read_data`); a ``group``
    column holds any labels (text or numbers)."""
    check_header(exp, list(columns), "<arrays>", 0)
    labels = columns.pop("group", None)
    arrs = {k: np.asarray(v, dtype=float).ravel() for k, v in columns.items()}
    sizes = {k: a.size for k, a in arrs.items()}
    if len(set(sizes.values())) != 1:
        raise DataFileError(f"<arrays>: columns have different lengths {sizes}")
    for k, a in arrs.items():
        if not np.all(np.isfinite(a)):
            i = int(np.flatnonzero(~np.isfinite(a))[0])
            raise DataFileError(f"<arrays> row {i}, column '{k}': {a[i]} is not a finite number")
    n = next(iter(sizes.values()))
    if n < exp.min_rows:
        raise DataFileError(f"<arrays>: {n} rows; {exp.name} needs at least {exp.min_rows}")
    check_values(exp, arrs, "<arrays>", np.arange(n), measured=False)
    if labels is None:
        return Measured(exp.name, arrs)
    labels = list(np.asarray(labels).ravel())
    if len(labels) != n:
        raise DataFileError(f"<arrays>: the group column has {len(labels)} rows, the others {n}")
    groups, names = group_codes(labels)
    return Measured(exp.name, arrs, groups=groups, group_names=names)


def write_data(path, data: Measured, exp: Experiment | None = None, comments=(), fmt: str = "%.9g") -> Path:
    """Write ``data`` as a CSV file readable by :func:`read_data`; ``comments`` become ``#`` lines."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    names = list(data.columns)
    if exp is not None:  # the experiment's column order
        names = [c.name for c in exp.all_columns if c.name in data.columns]
    group = [data.group_names[g] for g in data.groups] if data.groups is not None else None
    with open(path, "w", newline="") as fh:
        for c in comments:
            fh.write(f"# {c}\n")
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(names + (["group"] if group else []))
        for i, row in enumerate(np.column_stack([data.columns[k] for k in names])):
            w.writerow([fmt % v for v in row] + ([group[i]] if group else []))
    return path
