"""History of model versions: every ``compare`` run appends one record to ``history.jsonl``.

A record (one JSON object per line) holds the version number (1, 2, ... in the order of the
runs in that output folder), the time, the experiment, the data file, the effects switched on,
whether the parameters were fitted, the parameters with their standard errors and units, the
overall and per-channel RMS errors, the noise floor and the BIC.  :func:`plot_history` draws the
error against the version, which is how one watches the error fall as effects are added.
"""

from __future__ import annotations

import json
import math
import numbers
import os
import time
import warnings
from pathlib import Path

from ..errors import FemastError
from ..post.folder import FolderLock, open_regular, open_write, parse_json

HISTORY_FILE = "history.jsonl"
LOCK_WAIT_S = 60.0  # how long an append waits for another compare's append to the same history


class HistoryWarning(UserWarning):
    """A history line cut short by an interrupted append (ignored)."""


def read_history(folder) -> list:
    """All records of ``folder/history.jsonl`` (empty list if there is none).  A last line cut short
    (an append interrupted by a kill) is ignored with a :class:`HistoryWarning`; any other line that
    is not a record femast writes is a FemastError naming the file, the line and the field."""
    path = Path(folder) / HISTORY_FILE
    if not path.exists() and not path.is_symlink():
        return []
    with open_regular(path) as fh:
        text = fh.read().decode("utf-8", errors="replace")
    lines = text.split("\n")
    torn = lines.pop() if lines else ""  # text after the last newline: an interrupted append
    out = []
    for k, line in enumerate(lines, start=1):
        if line.strip():
            out.append(_record(parse_json(line, f"{path} line {k}", "history record"), f"{path} line {k}"))
    if torn.strip():
        warnings.warn(
            f"{path}: ignoring line {len(lines) + 1}, cut short by an interrupted run ({len(torn)} characters)",
            HistoryWarning,
            stacklevel=2,
        )
    return out


_TYPES = {  # field: (check, what it must be)
    "version": (lambda v: isinstance(v, int) and not isinstance(v, bool) and v >= 1, "a whole number >= 1"),
    "rms": (lambda v: _finite(v) and v >= 0, "a number >= 0"),
    "noise_rms": (lambda v: _finite(v) and v >= 0, "a number >= 0"),
    "ratio": (lambda v: v is None or _finite(v), "a number"),
    "bic": (lambda v: v is None or _finite(v), "a number"),
    "effects": (lambda v: isinstance(v, list) and all(isinstance(e, str) for e in v), "a list of effect names"),
    "fit": (lambda v: isinstance(v, bool), "true or false"),
    "experiment": (lambda v: isinstance(v, str), "a text"),
    "data": (lambda v: isinstance(v, str), "a text"),
    "error_unit": (lambda v: isinstance(v, str), "a text"),
}


def _finite(v) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool) and math.isfinite(v)


_DAMAGED = "the file is damaged or was edited: fix or delete that line, or compare into another --out folder"


def _record(rec, where: str) -> dict:
    if not isinstance(rec, dict):
        raise FemastError(f"{where}: a {type(rec).__name__}, not a history record; {_DAMAGED}")
    for field in ("version", "rms", "noise_rms", "experiment", "data"):
        if field not in rec:
            raise FemastError(f"{where}: the history record has no '{field}'; {_DAMAGED}")
    for field, (ok, what) in _TYPES.items():
        if field in rec and not ok(rec[field]):
            shown = repr(rec[field])
            shown = shown if len(shown) <= 60 else shown[:57] + "..."
            raise FemastError(f"{where}: '{field}' = {shown} is not {what}; {_DAMAGED}")
    return rec


def append_history(folder, record: dict) -> int:
    """Append ``record`` to ``folder/history.jsonl`` with the next version number; returns it.  The
    history is locked while its versions are counted and the line is written (a compare run writing
    to the same folder at the same moment waits up to :data:`LOCK_WAIT_S` s, then gets a
    FolderInUseError naming the other process), so concurrent runs get versions 1, 2, 3, ..."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    with FolderLock(folder, "history folder", name=HISTORY_FILE + ".lock").acquire(wait_s=LOCK_WAIT_S):
        path = folder / HISTORY_FILE
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", HistoryWarning)  # (the torn tail is cut off below)
            version = len(read_history(folder)) + 1
        rec = {"version": version, "time": time.strftime("%Y-%m-%dT%H:%M:%S"), **record}
        fd = open_write(path, read=True)
        try:
            data = os.pread(fd, os.fstat(fd).st_size, 0)
            cut = data.rfind(b"\n") + 1  # an interrupted append's partial line goes (femast's own)
            os.ftruncate(fd, cut)
            line = (json.dumps(rec) + "\n").encode()
            done = 0
            while done < len(line):
                done += os.pwrite(fd, line[done:], cut + done)
        finally:
            os.close(fd)
    return version


def _label(rec: dict) -> str:
    eff = "+".join(rec.get("effects") or []) or "baseline"
    return f"v{rec['version']}: {eff}" + (" (fit)" if rec.get("fit") else "")


def plot_history(folder, png=None):
    """Plot the RMS error (and the noise floor) against the model version; returns the PNG path."""
    from ..post import plotstyle
    from ..post.plotstyle import display_scale, fit_title

    plt = plotstyle.pyplot()

    recs = read_history(folder)
    if not recs:
        return None
    png = Path(png) if png else Path(folder) / "history.png"
    unit = recs[-1].get("error_unit", "")
    f, ulabel = display_scale(unit)
    v = [r["version"] for r in recs]
    fig, ax = plt.subplots(figsize=(max(6.0, 0.9 * len(recs) + 3), 4.2))
    ax.plot(v, [f * r["rms"] for r in recs], "o-", color="C3", label="RMS error")
    ax.plot(v, [f * r["noise_rms"] for r in recs], "s--", color="0.5", ms=4, label="noise floor")
    ax.set_xticks(v)
    ax.set_xticklabels([_label(r) for r in recs], rotation=25, ha="right", fontsize=8)
    ax.set_ylabel(f"RMS error ({ulabel})")
    ax.set_xlabel("model version")
    ax.set_ylim(bottom=0)
    ax.set_title(
        fit_title(
            ax,
            f"{recs[-1]['experiment']}: error against model version ({Path(str(recs[-1]['data']).split()[-1]).name})",
        )
    )
    ax.legend()
    return plotstyle.save(fig, png, dpi=110)
