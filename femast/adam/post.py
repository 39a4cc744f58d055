"""Post-processing of ADAM analyses: the bay's moment-rotation curve with the four latch-status
bars (Stohlman & Pellegrino, Figs. 16-17, zones of Fig. 6), CSV files, release angles, residual rotations, and the
tip table of the 40-bay mast in the layout of Stohlman & Pellegrino, Table 1.  Reads :class:`~femast.post.results.Results`
only (never the live solver)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from .._moved import renamed, renamed_attributes
from ..elements.latch_law import (
    ZONE_BACKSTOP,
    ZONE_BEHIND_AXIS,
    ZONE_FREE,
    ZONE_IN_FRONT,
    ZONE_LABELS,
    latch_zone,
)
from ..post.results import Results
from .build import AdamModel

ARCSEC = 180.0 / np.pi * 3600.0  # arcsec per rad

#: Colours of the zones of Stohlman & Pellegrino, Fig. 6: red latched, yellow intermediate, green unlatched.
ZONE_COLORS = {ZONE_BACKSTOP: "#d7191c", ZONE_BEHIND_AXIS: "#fdae61", ZONE_IN_FRONT: "#ffe55c", ZONE_FREE: "#1a9641"}


def bay_curve(res: Results, am: AdamModel, bay: int = -1) -> dict:
    """Moment-rotation history of the top frame and the latch state of bay ``bay``.

    Returns a dict of arrays, one value per frame: ``step`` (name), ``time`` (total time, s),
    ``theta`` (rz of the control node, rad), ``ux``, ``uy``, ``uz`` (m), ``M`` (moment about z,
    N m, in the sign of Stohlman & Pellegrino: the moment of the bay on the loading rig, i.e. minus
    the moment applied to the bay; the rig holds the bay against stowing with a negative moment), ``M_applied`` (N m),
    ``bead`` (n, 4) bead positions (m), ``zone`` (n, 4) zones of Fig. 6, ``dT`` (n, 4) N,
    ``tension`` (n, 4, 2) N (sections 1 and 2 of each latch cable).  With a bearing sheave in the units
    (``BayParameters.pulley``) ``dT`` is the jump across the whole unit, latch and bearing."""
    j = range(am.n_bays)[bay]
    labels = am.latch_labels[j]
    fam = am.latch_family
    ctl = am.control
    rows = [np.flatnonzero(res.mesh[f"labels/{fam}"] == lab)[0] for lab in labels]
    n = len(res)
    out = {k: np.empty(n) for k in ("time", "theta", "ux", "uy", "uz", "M_applied", "M_reaction")}
    out["bead"] = np.empty((n, 4))
    out["zone"] = np.empty((n, 4), dtype=int)
    out["dT"] = np.empty((n, 4))
    out["tension"] = np.empty((n, 4, 2))
    row = int(np.flatnonzero(res.node_labels == ctl)[0])
    for i in range(n):
        fr = res.frame(i)
        out["time"][i] = float(fr["total_time"])
        out["theta"][i] = fr["URA"][row, 2]
        out["ux"][i], out["uy"][i], out["uz"][i] = fr["U"][row]
        out["M_applied"][i] = fr["P"][row, 5]
        out["M_reaction"][i] = fr["RF"][row, 5]
        out["bead"][i] = np.ravel(fr[f"el/{fam}/bead_position"][rows])
        out["tension"][i] = fr[f"el/{fam}/tension"][rows]
        if f"el/{fam}/latch_zone" in fr:  # the paper's cable/latch element
            out["zone"][i] = fr[f"el/{fam}/latch_zone"][rows]
            out["dT"][i] = fr[f"el/{fam}/latch_dT"][rows]
        else:  # a latch over a bearing sheave (BayParameters.pulley): the jump across the whole unit
            out["zone"][i] = latch_zone(out["bead"][i], am.params.latch)
            out["dT"][i] = out["tension"][i][:, 1] - out["tension"][i][:, 0]
    out["step"] = np.array(res.steps)
    # the moment the rig applies is a load (displacement control) or a reaction (prescribed rz)
    out["M"] = -(out["M_applied"] + out["M_reaction"])
    return out


def write_curve_csv(curve: dict, path) -> Path:
    """CSV of a :func:`bay_curve`: one row per converged increment (SI; theta also in degrees)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    head = (
        ["step", "total_time_s", "theta_z_deg", "Mz_Nm", "ux_m", "uy_m", "uz_m"]
        + [f"bead{k}_m" for k in range(4)]
        + [f"zone{k}" for k in range(4)]
        + [f"dT{k}_N" for k in range(4)]
    )
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        fh.write(
            "# ADAM bay torsion (Stohlman & Pellegrino, Figs. 16-17). Mz: moment of the bay on the rig "
            "(minus the moment applied to the top frame). "
            "zone: Fig. 6, 0 (a) backstop, 1 (b) behind roller axis, 2 (c) in front, 3 (d) free\n"
        )
        w.writerow(head)
        for i in range(len(curve["theta"])):
            w.writerow(
                [
                    curve["step"][i],
                    f"{curve['time'][i]:.9g}",
                    f"{np.degrees(curve['theta'][i]):.9g}",
                    f"{curve['M'][i]:.9g}",
                    f"{curve['ux'][i]:.9g}",
                    f"{curve['uy'][i]:.9g}",
                    f"{curve['uz'][i]:.9g}",
                ]
                + [f"{v:.9g}" for v in curve["bead"][i]]
                + [int(v) for v in curve["zone"][i]]
                + [f"{v:.9g}" for v in curve["dT"][i]]
            )
    return path


def release_angles(curve: dict) -> np.ndarray:
    """Twist (rad) at which each of the four beads first reaches zone (d) (off the rollers); NaN
    for a latch that never releases."""
    out = np.full(4, np.nan)
    for k in range(4):
        idx = np.flatnonzero(curve["zone"][:, k] == ZONE_FREE)
        if idx.size:
            out[k] = curve["theta"][idx[0]]
    return out


def relatch_angles(curve: dict) -> np.ndarray:
    """Twist (rad) at which each bead is back on its backstop for good (zone (a) from there on);
    NaN if it does not get back."""
    out = np.full(4, np.nan)
    for k in range(4):
        z = curve["zone"][:, k]
        not_a = np.flatnonzero(z != ZONE_BACKSTOP)
        if not_a.size and not_a[-1] + 1 < z.size:
            out[k] = curve["theta"][not_a[-1] + 1]
    return out


def plot_bay_torsion(curve: dict, png, title: str = "", note: str = "", reference=None, *, seed_note=None):
    """Figure in the style of Figs. 16-17 of Stohlman & Pellegrino: moment about z against the twist
    (top) and the four latch-status bars (zones of Fig. 6) along the path (bottom; the twist is drawn
    over them).

    note : a line above the axes (what the paper shows for this path; ``seed_note=``, its old name,
        warns and is removed in femast 0.3).
    reference : optional (theta_deg, M) curve drawn in black (e.g. measured data)."""
    if seed_note is not None:
        renamed("plot_bay_torsion(seed_note=...)", "plot_bay_torsion(note=...)")
        note = seed_note
    import matplotlib

    matplotlib.use("Agg")
    from ..post import plotstyle  # noqa: E402  (the one femast figure style)

    plotstyle.use()
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    steps = curve["step"]
    moving = np.array([("twist" in s) or ("path" in s) for s in steps])
    if moving.any():  # start the path at the last frame before the twist (the pretensioned bay)
        first = max(int(np.flatnonzero(moving)[0]) - 1, 0)
        moving[first] = True
    else:
        moving[:] = True
    th = np.degrees(curve["theta"])[moving]
    t = curve["time"][moving] - curve["time"][moving][0]
    zones = curve["zone"][moving]
    Mm = curve["M"][moving]
    fig = plt.figure(figsize=(8.0, 7.0))
    gs = fig.add_gridspec(2, 1, height_ratios=[3.0, 1.5], hspace=0.32)
    ax = fig.add_subplot(gs[0])
    if reference is not None:
        ax.plot(reference[0], reference[1], "k-", lw=1.2, label="reference")
    ax.plot(th, Mm, "-", color="#c0392b", lw=1.6, label="femast model")
    # arrows on the out and back branches
    for frac in (0.3, 0.75):
        i = int(frac * len(th))
        if 0 < i < len(th) - 1:
            ax.annotate(
                "",
                xy=(th[i + 1], Mm[i + 1]),
                xytext=(th[i], Mm[i]),
                arrowprops=dict(arrowstyle="->", color="#c0392b", lw=1.4),
            )
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.set_xlabel("z-axis rotation (degrees)")
    ax.set_ylabel("Moment about z-axis (N m)")
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize=9)
    if title:
        fig.suptitle(title, fontsize=11)
    if note:  # above the axes, never over the curve
        ax.set_title(note, loc="left", fontsize=8.5, color="0.25")
    bx = fig.add_subplot(gs[1])
    for k in range(4):
        z = zones[:, k]
        for i in range(len(t) - 1):
            bx.fill_between([t[i], t[i + 1]], k + 0.1, k + 0.9, color=ZONE_COLORS[int(z[i])], lw=0)
    bx.set_yticks([k + 0.5 for k in range(4)])
    bx.set_yticklabels([f"side {k}" for k in range(4)])
    bx.set_ylim(0, 4)
    bx.set_xlim(t[0], t[-1])
    bx.set_xlabel("along the path (step time, s)")
    tw = bx.twinx()
    tw.plot(t, th, "k-", lw=1.0)
    tw.set_ylabel("rotation (deg)")
    handles = [Patch(color=ZONE_COLORS[z], label=ZONE_LABELS[z]) for z in range(4)]
    bx.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.38), ncol=4, fontsize=8, frameon=False)
    plotstyle.save(fig, png, dpi=130)
    plt.close(fig)
    return Path(png)


# ---------------------------------------------------------------------------- Table 1
#: Stohlman & Pellegrino, Table 1, rows 0, M+F, 0, -M-F, 0, ... (x, y, z in um; theta_x, theta_y, theta_z in
#: arcsec).  The extracted table prints the x displacement under -M-F as "-1.740" and under M+F
#: after the first cycle as "1.740": read here as -1740 and 1740 um (a thousands separator).
ADAM_TABLE1 = np.array(
    [
        # x      y      z       thx    thy     thz
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [1740, -1.0, -0.3, 0.6, 210, 3030],
        [0.8, -1.0, 0.0, 0.0, 0.02, 7.9],
        [-1740, -2.0, -0.3, 0.6, -210, -3030],
        [0.01, -2.1, -0.001, 0.02, 0.0, 0.03],
        [1740, -2.0, -0.3, 0.6, 210, 3030],
        [0.03, -2.1, -0.001, 0.03, 0.0, 0.30],
        [-1740, -2.0, -0.3, 0.6, -210, -3030],
        [0.02, -2.1, -0.001, 0.03, 0.001, 0.43],
        [1740, -2.0, -0.3, 0.6, 210, 3030],
        [0.02, -2.1, -0.001, 0.03, 0.001, 0.38],
        [-1740, -2.0, -0.3, 0.6, -210, -3030],
        [0.02, -2.1, -0.001, 0.03, 0.001, 0.38],
    ]
)
TABLE1_ROWS = ("0", "M+F", "0", "-M-F", "0", "M+F", "0", "-M-F", "0", "M+F", "0", "-M-F", "0")
TABLE1_COLUMNS = ("x (um)", "y (um)", "z (um)", "thx (asec)", "thy (asec)", "thz (asec)")


def tip_table(res: Results, am: AdamModel, reference_step: str = "pretension") -> tuple[list, np.ndarray]:
    """Tip (control node) position and rotation at the end of each step after ``reference_step``,
    relative to the state at the end of ``reference_step`` (the pretensioned mast), in the units
    of Table 1: x, y, z in um and theta_x, theta_y, theta_z in arcsec.  Returns (row labels,
    (n, 6) array), the first row being the reference (zeros)."""
    steps = res.steps
    ends = [i for i in range(len(steps)) if i == len(steps) - 1 or steps[i + 1] != steps[i]]
    names = [steps[i] for i in ends]
    if reference_step not in names:
        raise ValueError(f"tip_table: no step '{reference_step}' in the results (steps: {names})")
    k0 = names.index(reference_step)
    row = int(np.flatnonzero(res.node_labels == am.control)[0])
    vals = []
    for i in ends[k0:]:
        fr = res.frame(i)
        vals.append(np.concatenate([fr["U"][row] * 1e6, fr["URA"][row] * ARCSEC]))
    vals = np.array(vals)
    vals -= vals[0]
    labels = ["0"] + [n.split("#")[0].rstrip("ab") or "0" for n in names[k0 + 1 :]]
    return labels, vals


def format_table1(labels, model_vals, paper=ADAM_TABLE1, note_width: int = 0, *, seed=None) -> str:
    """The tip table in the paper's layout, model value beside the paper's value (um, arcsec).

    paper : (n, 6) the values printed beside the model's (default Table 1 of the paper; ``seed=``,
        its old name, warns and is removed in femast 0.3)."""
    if seed is not None:
        renamed("format_table1(seed=...)", "format_table1(paper=...)")
        paper = seed
    n = min(len(labels), len(paper))
    head = f"{'load':>6} | " + " | ".join(f"{c:^21}" for c in TABLE1_COLUMNS)
    sub = f"{'':>6} | " + " | ".join(f"{'femast':>10} {'paper':>10}" for _ in TABLE1_COLUMNS)
    lines = [head, sub, "-" * len(head)]
    for i in range(n):
        cells = []
        for j in range(6):
            cells.append(f"{model_vals[i, j]:>10.4g} {paper[i, j]:>10.4g}")
        lines.append(f"{labels[i]:>6} | " + " | ".join(cells))
    return "\n".join(lines)


#: old names, kept for one release (they warn): femast 0.3 removes them
__getattr__ = renamed_attributes(__name__, {"SEED_TABLE1": "ADAM_TABLE1"})
