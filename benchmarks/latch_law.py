"""Reproduce Stohlman & Pellegrino, Fig. 10 (with the zones of Fig. 6): latch force jump vs bead position.

Plots, for the paper's fitted latch (r = 1.1 mm, x_backstop = 2.0 mm, k = 100 N/mm,
mu = 0.07, h = 1.5 mm, R = 2.4 mm):

* the two branches of Eq. 14 (latching dx < 0, unlatching dx > 0) and the static
  friction band between them;
* the quasi-static paths of the two pull tests of Fig. 8, computed with the
  cable/latch element (one cable pulls, the other is slack): they follow a branch
  while it has the sign the pulling cable can give, snap where it changes sign, and
  run up the backstop;
* the zones (a)-(d) of Fig. 6.

Run:  python benchmarks/latch_law.py   ->  benchmarks/out/latch_law.png
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
from femast.post import plotstyle  # noqa: E402  (the one femast figure style)

plotstyle.use()
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from femast.elements.latch_law import (  # noqa: E402
    LATCHING,
    UNLATCHING,
    LatchParameters,
    contact_half_width,
    latch_force,
)
from femast.latch_identification import simulate_pull_test  # noqa: E402

OUT = Path(__file__).resolve().parent / "out"
DOCS = Path(__file__).resolve().parents[1] / "docs" / "figures"


def main(show_paths: bool = True) -> dict:
    p = LatchParameters.adam_fit()
    mm = 1e3
    xct = contact_half_width(p)
    x = np.linspace(-p.x_backstop, 4e-3, 2001)
    lat = latch_force(x, LATCHING, p)
    unl = latch_force(x, UNLATCHING, p)

    fig, ax = plt.subplots(figsize=(8.0, 5.2))
    ylo, yhi = -75, 85
    # zones of Fig. 6
    zones = [
        (-p.x_backstop - 0.12e-3, -p.x_backstop, "#e41a1c", "(a)\nbackstop"),
        (-p.x_backstop, 0.0, "#ffd92f", "(b) contact,\nbehind axis"),
        (0.0, xct, "#fff3a0", "(c) contact,\nin front"),
        (xct, 4.1e-3, "#a6d96a", "(d) no contact"),
    ]
    for a, b, c, lab in zones:
        ax.axvspan(a * mm, b * mm, color=c, alpha=0.45, lw=0)
        ax.text(0.5 * (a + b) * mm, yhi - 3, lab, ha="center", va="top", fontsize=8)
    ax.fill_between(x * mm, lat, unl, color="0.6", alpha=0.35, lw=0, label="static friction band (bead at rest)")
    ax.plot(x * mm, unl, "--", color="tab:red", lw=1.0, label=r"Eq. 14, $dx>0$ (unlatching branch)")
    ax.plot(x * mm, lat, "--", color="tab:blue", lw=1.0, label=r"Eq. 14, $dx<0$ (latching branch)")
    ax.plot([-p.x_backstop * mm] * 2, [ylo, unl[0]], color="k", lw=2.5, label="backstop (any inward pull)")
    result = {
        "peak_unlatching_N": float(unl.max()),
        "peak_latching_N": float(lat.min()),
        "x_contact_mm": xct * mm,
        "dT_out_backstop_N": float(unl[0]),
    }
    if show_paths:
        for direction, color, lab in (
            (UNLATCHING, "tab:red", "unlatching test (T2 pulls, T1 slack)"),
            (LATCHING, "tab:blue", "latching test (T1 pulls, T2 slack)"),
        ):
            t = simulate_pull_test(p, direction, EA=2e5, n_steps=800, x_far=4e-3, T_max=70.0)
            xs, ys = t.x_true * mm, t.dT()
            # a snap is a jump of the bead between two grip steps: draw it dotted
            jump = np.flatnonzero(np.abs(np.diff(xs)) > 0.05)
            segs = np.split(np.arange(xs.size), jump + 1)
            for i, seg in enumerate(segs):
                ax.plot(
                    xs[seg], ys[seg], color=color, lw=2.2, alpha=0.9, label=f"element path, {lab}" if i == 0 else None
                )
            for j in jump:
                ax.annotate(
                    "",
                    xy=(xs[j + 1], ys[j + 1]),
                    xytext=(xs[j], ys[j]),
                    arrowprops=dict(arrowstyle="->", color=color, ls=":", lw=1.5),
                )
                result[f"snap_{'out' if direction > 0 else 'in'}_mm"] = (float(xs[j]), float(xs[j + 1]))
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlim(-p.x_backstop * mm - 0.15, 4.0)
    ax.set_ylim(ylo, yhi)
    ax.set_xlabel("bead position x, distance to latch (mm)   [x > 0: outside, backstop at x = -x_backstop]")
    ax.set_ylabel(r"$\Delta T = T_2 - T_1$ (N)")
    ax.set_title(
        "Latch law of ADAM (Stohlman & Pellegrino), Fig. 10: r=1.1 mm, x_bs=2.0 mm, k=100 N/mm, mu=0.07, h=1.5 mm, R=2.4 mm",
        fontsize=9,
    )
    ax.plot([], [], ":", color="0.3", label="snap (bead jumps; dotted arrows)")
    ax.legend(loc="upper right", bbox_to_anchor=(1.0, 0.86), fontsize=7.5, framealpha=0.9)
    fig.tight_layout()
    OUT.mkdir(parents=True, exist_ok=True)
    png = OUT / "latch_law.png"
    plotstyle.save(fig, png, dpi=150)
    plt.close(fig)
    DOCS.mkdir(parents=True, exist_ok=True)
    shutil.copy(png, DOCS / "latch_law.png")
    result["png"] = str(png)
    return result


if __name__ == "__main__":
    res = main()
    for k, v in res.items():
        print(f"{k:>20s}: {v}")
    sys.exit(0)
