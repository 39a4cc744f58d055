"""Friction ball joint (Stohlman & Pellegrino, Sec. II.B.1): moment-rotation loops and dissipated energy.

Three panels, all computed with ``fm.solve`` (real analyses, not the kernel alone):

(a) one joint under constant compressive forces F = 250, 500, 1000 N, its corner node
    rotated about z through two cycles 0 -> +A -> -A -> +A -> -A -> +A (A = 0.03 rad,
    k_stick = 200 N m/rad so the stick branches are visible); dashed lines: the analytic
    plateaus +-mu B |F| (mu = 0.5, B = 4 mm);
(b) the dissipated energy of those runs against time, with the closed form
    4 mu B |F| (A - mu B |F| / k_stick) per cycle marked at the end of each cycle;
(c) two aluminium tubes meeting at a ball joint (default stiffnesses), compressed by
    200 N and bent by a prescribed end rotation: the transmitted moment and +-mu B |F|,
    with |F| the force the joint transmits (axial load plus shear).

Run:  python benchmarks/ball_joint_friction.py
      -> benchmarks/out/ball_joint_loop.png, docs/figures/ball_joint_loop.png,
         benchmarks/out/ball_joint_friction.txt
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
from femast.post import plotstyle  # noqa: E402  (the one femast figure style)

plotstyle.use()
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import femast as fm  # noqa: E402
from femast.elements.ball_joint import add_ball_joints, friction_loop_energy  # noqa: E402

OUT = Path(__file__).resolve().parent / "out"
DOCS = Path(__file__).resolve().parents[1] / "docs" / "figures"
MU, B = 0.5, 0.004  # Stohlman & Pellegrino, Sec. II.B.1
A, K_STICK = 0.03, 200.0  # rotation amplitude (rad), stick stiffness (N m/rad)
FORCES = (250.0, 500.0, 1000.0)
TABLE_T = [0.0, 1.0, 3.0, 5.0, 7.0, 9.0]  # step times of the turning points
TABLE_V = [0.0, 1.0, -1.0, 1.0, -1.0, 1.0]


def single_joint(P, folder):
    m = fm.Model("ball_joint_loop")
    a, b = m.node(0, 0, 0), m.node(0, 0, 0)
    add_ball_joints(m, [(a, b)], MU, B, k_pen=1e8, k_stick=K_STICK)
    m.fix(a)
    m.fix(b, "uy", "uz", "rx", "ry")
    m.step("press").load(b, fx=-P).prescribe(b, rz=0.0)
    m.step("cycle", period=TABLE_T[-1], max_increment=0.05).prescribe(b, amplitude=fm.Amplitude(TABLE_T, TABLE_V), rz=A)
    res = fm.solve(m, folder, progress=False)
    return dict(
        t=res.time,
        rz=res.node_history(b, "rz"),
        M=res.element_history("ball_joint", 1, "moment")[:, 2],
        D=res.element_history("ball_joint", 1, "dissipated"),
        F=res.element_history("ball_joint", 1, "F"),
    )


def two_beams(folder, P=200.0, rot=0.01, L=0.5):
    sec = fm.circular_tube(0.02, 0.016, E=70e9)
    m = fm.Model("two_beams")
    n1, n2, n3, n4 = m.node(0, 0, 0), m.node(L, 0, 0), m.node(L, 0, 0), m.node(2 * L, 0, 0)
    m.beam(n1, n2, sec, up=(0, 1, 0), n=4)
    m.beam(n3, n4, sec, up=(0, 1, 0), n=4)
    add_ball_joints(m, [(n2, n3)])
    m.fix(n1)
    m.fix(n4, "uy", "uz", "rx", "ry")
    m.step("press").load(n4, fx=-P).prescribe(n4, rz=0.0)
    m.step("cycle", period=5.0, max_increment=0.05).prescribe(
        n4, amplitude=fm.Amplitude(TABLE_T[:4], TABLE_V[:4]), rz=rot
    )
    res = fm.solve(m, folder, progress=False)
    M = res.element_history("ball_joint", 1, "moment")
    return dict(
        t=res.time,
        Mz=M[:, 2],
        limit=res.element_history("ball_joint", 1, "limit"),
        F=res.element_history("ball_joint", 1, "F"),
        slip=res.element_history("ball_joint", 1, "slip"),
    )


def main(show=False):
    tmp = Path(tempfile.mkdtemp(prefix="femast_ball_joint_"))
    runs = {P: single_joint(P, tmp / f"P{int(P)}") for P in FORCES}
    beams = two_beams(tmp / "beams")
    lines = [
        "Friction ball joint, ADAM (Stohlman & Pellegrino), Sec. II.B.1 (mu = 0.5, B = 4 mm)",
        f"single joint, A = {A} rad, k_stick = {K_STICK} N m/rad, two cycles",
        f"{'F (N)':>8} {'plateau (N m)':>14} {'mu B F':>8} {'cycle':>6} {'D numeric (J)':>14} "
        f"{'D analytic (J)':>15} {'rel. err':>9}",
    ]
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.6))
    colors = plt.cm.viridis(np.linspace(0.1, 0.8, len(FORCES)))
    for c, P in zip(colors, FORCES):
        h = runs[P]
        Y = MU * B * P
        ax[0].plot(h["rz"], h["M"], "-", color=c, lw=1.6, label=f"|F| = {P:g} N")
        for s in (1, -1):
            ax[0].axhline(s * Y, color=c, ls="--", lw=0.8)
        ax[1].plot(h["t"], h["D"], "-", color=c, lw=1.6, label=f"|F| = {P:g} N")
        exact = friction_loop_energy(MU, B, P, A, K_STICK)
        i_start = int(np.argmin(np.abs(h["t"] - 2.0)))  # first +A (step 'cycle' starts at total time 1)
        for k, t_end in enumerate((6.0, 10.0)):
            i_end = int(np.argmin(np.abs(h["t"] - t_end)))
            D_num = h["D"][i_end] - h["D"][int(np.argmin(np.abs(h["t"] - (t_end - 4.0))))]  # one cycle
            ax[1].plot(t_end, h["D"][i_start] + (k + 1) * exact, "o", mfc="none", color="k", ms=8)
            lines.append(
                f"{P:8.0f} {np.abs(h['M']).max():14.6f} {Y:8.4f} {k + 1:6d} {D_num:14.8f} "
                f"{exact:15.8f} {abs(D_num / exact - 1):9.1e}"
            )
    ax[0].set_xlabel("relative rotation about z (rad)")
    ax[0].set_ylabel("friction moment M_z (N m)")
    ax[0].set_title("(a) moment-rotation loops; dashed: +-mu B |F|", fontsize=10)
    ax[0].legend(loc="upper left", fontsize=8)
    ax[0].grid(alpha=0.3)
    ax[1].plot([], [], "o", mfc="none", color="k", label="analytic 4 mu B|F| (A - mu B|F|/k_stick)")
    ax[1].set_xlabel("total time (s)")
    ax[1].set_ylabel("dissipated energy (J)")
    ax[1].set_title("(b) dissipated energy; circles: closed form per cycle", fontsize=10)
    ax[1].legend(loc="upper left", fontsize=8)
    ax[1].grid(alpha=0.3)
    ax[2].plot(beams["t"], beams["Mz"], "-", color="C3", lw=1.6, label="joint moment M_z")
    ax[2].plot(beams["t"], beams["limit"], "k--", lw=0.9, label="+-mu B |F| (|F| transmitted)")
    ax[2].plot(beams["t"], -beams["limit"], "k--", lw=0.9)
    ax[2].set_xlabel("total time (s)")
    ax[2].set_ylabel("moment (N m)")
    ax[2].set_title("(c) two tubes at a joint, 200 N, end rotated +-0.01 rad", fontsize=10)
    ax[2].legend(loc="center", fontsize=8)
    ax[2].grid(alpha=0.3)
    fig.tight_layout()
    slip = beams["slip"] > 0
    lines += [
        "",
        "two tubes with a ball joint (default k_pen, k_stick), 200 N compression:",
        f"  |F| range {beams['F'][1:].min():.4f} .. {beams['F'].max():.4f} N; slipping increments "
        f"{int(slip.sum())}; max | |M| - mu B |F| | while slipping "
        f"{np.abs(np.abs(beams['Mz'][slip]) - beams['limit'][slip]).max():.2e} N m",
    ]
    OUT.mkdir(parents=True, exist_ok=True)
    DOCS.mkdir(parents=True, exist_ok=True)
    png = OUT / "ball_joint_loop.png"
    plotstyle.save(fig, png, dpi=150)
    shutil.copy(png, DOCS / "ball_joint_loop.png")
    (OUT / "ball_joint_friction.txt").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    shutil.rmtree(tmp, ignore_errors=True)
    if show:
        plt.show()
    return lines


if __name__ == "__main__":
    main(show="--show" in sys.argv)
