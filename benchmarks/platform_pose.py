"""Pose error of the Rocaspect platform on compliant masts (the Rocaspect paper, Figs. 5a and 7).

    PYTHONPATH=$PWD python benchmarks/platform_pose.py [--out docs/figures] [--n 25] [--no-speed]

For each mast model (3R, beam, beam+shroud, FE guyed mast) and shroud pretension (0, 400, 800,
1200 N): the 8.3 x 6.8 x 4.0 m robot, 50 kg platform, trajectory like Fig. 5a from the paper's
initial pose (:func:`femast.guyed.rocaspect.fig5a_trajectory`), tensions from Eq. 2 (barycentric,
20-1500 N), swivel pulleys of 0.03 m, exit geometry calibrated at the initial pose.  Prints the
largest and RMS position error and the largest orientation error of the platform against the
rigid-frame controller, writes the figures, and times a 200-pose trajectory with FE masts
(wall and CPU time, load average).
"""

from __future__ import annotations

import argparse
import os
import resource
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from tqdm import tqdm  # noqa: E402

from femast.guyed.mast_sets import MODELS, mast_set  # noqa: E402
from femast.guyed.platform_pose import CableRobot, pose_trajectory  # noqa: E402
from femast.guyed.rocaspect import fig5a_trajectory, rocaspect_geometry  # noqa: E402

PRETENSIONS = (0.0, 400.0, 800.0, 1200.0)


def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def run_all(n_per_segment: int):
    robot = CableRobot(rocaspect_geometry())
    traj = fig5a_trajectory(n_per_segment)
    res = {}
    cases = [(m, p) for m in MODELS for p in PRETENSIONS]
    for model, pt in tqdm(cases, desc="mast model x pretension"):
        res[model, pt] = pose_trajectory(robot, mast_set(model, pt), traj)
    return traj, res


def speed(n_poses: int = 200):
    robot = CableRobot(rocaspect_geometry())
    traj = fig5a_trajectory(34)[:n_poses]
    load0 = os.getloadavg()[0]
    t0, c0 = time.perf_counter(), cpu()
    masts = mast_set("FE", 1200.0)
    res = pose_trajectory(robot, masts, traj)
    wall, cp = time.perf_counter() - t0, cpu() - c0
    return len(traj), wall, cp, load0, os.getloadavg()[0], res.fe_passes


def figures(traj, res, out: Path):
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(traj[:, :3], axis=0), axis=1))]
    fig, axs = plt.subplots(2, 2, figsize=(12, 7.5), sharex=True)
    colors = dict(zip(MODELS, ("C0", "C1", "C2", "C3")))
    for ax, pt in zip(axs.ravel(), PRETENSIONS):
        for model in MODELS:
            r = res[model, pt]
            e = np.where(r.feasible, 1e3 * r.position_error, np.nan)  # a slack cable: reported, not plotted
            ax.plot(s, e, color=colors[model], label=model)
            bad = ~r.feasible
            if bad.any():
                ax.plot(
                    s[bad],
                    np.zeros(bad.sum()),
                    "x",
                    color=colors[model],
                    ms=5,
                    label=f"{model}: pose not held ({bad.sum()}, a cable goes slack)",
                )
        ax.set_title(f"shroud pretension {pt:g} N", fontsize=10)
        ax.set_ylabel("platform position error, mm")
        ax.grid(alpha=0.3)
    for ax in axs[1]:
        ax.set_xlabel("path length along the Fig. 5a-like trajectory, m")
    for ax in axs.ravel():
        ax.legend(fontsize=7)
    fig.suptitle("Rocaspect: platform pose error against the rigid-frame controller (calibrated at the initial pose)")
    fig.tight_layout()
    p1 = out / "platform_pose_error.png"
    fig.savefig(p1, dpi=100)
    plt.close(fig)

    fig, axs = plt.subplots(1, 2, figsize=(13, 5))
    for model in MODELS:
        axs[0].plot(
            PRETENSIONS,
            [1e3 * res[model, p].position_error[res[model, p].feasible].max() for p in PRETENSIONS],
            "o-",
            color=colors[model],
            label=model,
        )
    axs[0].set_xlabel("shroud pretension, N")
    axs[0].set_ylabel("largest platform position error, mm (poses held)")
    axs[0].legend()
    axs[0].grid(alpha=0.3)
    r = res["FE", 1200.0]
    ax = axs[1]
    ax.plot(traj[:, 0], traj[:, 1], "k-", lw=0.8, label="commanded (rigid-frame controller)")
    scale = 20.0
    ax.plot(
        traj[:, 0] + scale * r.error[:, 0],
        traj[:, 1] + scale * r.error[:, 1],
        "C3-",
        label=f"actual, error x{scale:g} (FE masts, 1200 N)",
    )
    E0 = r.exit_points[0]
    dE = r.exit_points - E0
    k = int(np.argmax(r.position_error))
    ax.quiver(
        E0[:, 0],
        E0[:, 1],
        dE[k, :, 0],
        dE[k, :, 1],
        angles="xy",
        scale_units="xy",
        scale=1 / 30.0,
        color="C0",
        width=0.004,
        label="exit-point correction x30 (worst pose)",
    )
    ax.plot(E0[:, 0], E0[:, 1], "C0.", ms=4)
    ax.set_aspect("equal")
    ax.set_xlim(-0.8, 9.1)
    ax.set_ylim(-0.8, 7.6)
    ax.set_xlabel("x, m")
    ax.set_ylabel("y, m")
    ax.set_title("plan view: FE masts, 1200 N", fontsize=10)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2)
    fig.tight_layout()
    p2 = out / "platform_pose_summary.png"
    fig.savefig(p2, dpi=100)
    plt.close(fig)
    return p1, p2


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/figures")
    ap.add_argument("--n", type=int, default=25, help="poses per trajectory segment")
    ap.add_argument("--no-speed", action="store_true")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    traj, res = run_all(args.n)
    print(f"{len(traj)} poses; errors against the rigid-frame prediction")
    print(
        f"{'model':<12} {'pretension N':>12} {'max pos mm':>11} {'rms pos mm':>11} {'max rot mrad':>13} {'infeasible':>10}"
    )
    for (model, pt), r in res.items():
        ok = r.feasible
        pe = r.position_error[ok]
        print(
            f"{model:<12} {pt:>12g} {1e3 * pe.max():>11.2f} {1e3 * np.sqrt(np.mean(pe**2)):>11.2f} "
            f"{1e3 * r.orientation_error[ok].max():>13.2f} {int((~ok).sum()):>10d}"
        )
    for p in figures(traj, res, out):
        print(f"figure: {p}")
    if not args.no_speed:
        n, wall, cp, l0, l1, passes = speed()
        print(
            f"speed: {n}-pose trajectory with FE masts (1200 N, {passes} FE passes): wall {wall:.1f} s, "
            f"CPU {cp:.1f} s, load average {l0:.1f} -> {l1:.1f} (2 cores)"
        )


if __name__ == "__main__":
    main()
