"""History of model versions: every ``compare`` run appends one record to ``history.jsonl``.

A record (one JSON object per line) holds the version number (1, 2, ... in the order of the
runs in that output folder), the time, the experiment, the data file, the effects switched on,
whether the parameters were fitted, the parameters with their standard errors and units, the
overall and per-channel RMS errors, the noise floor and the BIC.  :func:`plot_history` draws the
error against the version, which is how one watches the error fall as effects are added.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

HISTORY_FILE = "history.jsonl"


def read_history(folder) -> list:
    """All records of ``folder/history.jsonl`` (empty list if there is none)."""
    path = Path(folder) / HISTORY_FILE
    if not path.is_file():
        return []
    out = []
    for line in path.read_text().splitlines():
        line = line.strip()
        if line:
            out.append(json.loads(line))
    return out


def append_history(folder, record: dict) -> int:
    """Append ``record`` to ``folder/history.jsonl`` with the next version number; returns it."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    version = len(read_history(folder)) + 1
    rec = {"version": version, "time": time.strftime("%Y-%m-%dT%H:%M:%S"), **record}
    with open(folder / HISTORY_FILE, "a") as fh:
        fh.write(json.dumps(rec) + "\n")
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
