"""Single ADAM bay in torsion: Stohlman & Pellegrino, Figs. 16 (idealised path) and 17 (actual path).

    femast run benchmarks/adam_bay_torsion.py [--path ideal|actual|both] [--out DIR] [--docs]
                                              [--hysteresis F_h ell] [--quick] [--no-progress]

* ideal: bottom corners fixed; the control node (centre of the rigid top frame) turns about z to
  3.5 degrees in the folding sense and back, x and y held, z and tilts free (displacement control
  of rz, the moment is the load factor); then the moment is brought back to zero to read the
  residual rotation.  The bay is symmetric, so the four latches release together.
* actual: the control node follows a measured-style table of theta_z, x and y (synthetic, with
  off-axis drift up to about 1 cm: Stohlman & Pellegrino, Sec. VI); the bay turns about the side that stays
  latched, and the other three release one after the other.

Each path writes to DIR/<path>/: the results folder (frames, status.sta, summary.json), the VTK
series (vtk/series.pvd), the curve (curve.csv: moment, rotation, drift, bead positions, zones,
force jumps) and the figure (torsion.png: moment-rotation curve with the four latch-status bars,
zones of Stohlman & Pellegrino, Fig. 6).  --docs copies the figures to docs/figures/adam_bay_<path>.png.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
from pathlib import Path

import numpy as np

import femast as fm
from femast.adam import build_bay
from femast.adam.post import bay_curve, plot_bay_torsion, relatch_angles, release_angles, write_curve_csv
from femast.adam.steps import (
    CONVERGENCE,
    add_idealised_torsion,
    add_initial_steps,
    add_measured_torsion,
    measured_style_path,
)
from femast.elements.latch_law import ZONE_LABELS
from femast.post.vtk import export_vtk

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs" / "figures"

PAPER_NOTE = {
    "ideal": "Stohlman & Pellegrino Fig. 16: model of the ideal path, all four latches\n"
    "release together; experiment: -35 N m to start, about\n"
    "3 deg to unlatch three of four latches",
    "actual": "Stohlman & Pellegrino Fig. 17: model driven by the measured theta_z, x, y;\n"
    "one latch stays latched after the other three release\n"
    "(here: a synthetic measured-style path)",
}


def run_path(
    kind: str, out: Path, theta_max_deg: float, progress: bool, hysteresis=None, quick=False, params_changes=None
) -> dict:
    changes = {"seat": "tied", **(params_changes or {})}  # the paper's joints (Figs. 16-17)
    if hysteresis is not None:
        changes.update(hysteresis_force=hysteresis[0], hysteresis_length=hysteresis[1])
    am = build_bay(**changes)
    inc = 0.04 if quick else 0.01
    if kind == "ideal":
        add_initial_steps(am, hold_control=("ux", "uy"))
        add_idealised_torsion(am, np.radians(theta_max_deg), name="twist", max_increment=inc)
        path = None
    else:
        add_initial_steps(am, hold_control=("ux", "uy", "rz"))
        path = measured_style_path(
            am.params.b, theta_max=np.radians(theta_max_deg), hold_side=0, n=41 if quick else 161
        )
        add_measured_torsion(am, path, name="twist-path", max_increment=4 * inc / 2 if quick else 0.0125)
    folder = out / kind
    t0 = time.perf_counter()
    an = fm.Analysis(am.model, folder / "results", progress=progress, convergence=CONVERGENCE)
    res = an.run()
    wall = time.perf_counter() - t0
    curve = bay_curve(res, am)
    write_curve_csv(curve, folder / "curve.csv")
    if path is not None:
        path.to_csv(folder / "path.csv")
    export_vtk(res, folder / "vtk", every=1 if not quick else 4)
    title = (
        "ADAM bay, idealised path (cf. Stohlman & Pellegrino Fig. 16)"
        if kind == "ideal"
        else "ADAM bay, measured-style path with off-axis drift (cf. Stohlman & Pellegrino Fig. 17)"
    )
    if hysteresis is not None:
        title += f"\nlatch hysteresis F_h = {hysteresis[0]:g} N, ell = {hysteresis[1] * 1e3:g} mm"
    png = plot_bay_torsion(curve, folder / "torsion.png", title=title, note=PAPER_NOTE[kind])
    rel = np.degrees(release_angles(curve))
    back = np.degrees(relatch_angles(curve))
    twist = np.array(["twist" in s for s in curve["step"]])
    out_branch = twist & (np.gradient(np.abs(curve["theta"])) >= 0)
    i_peak = int(np.argmax(np.where(out_branch, np.abs(curve["M"]), -1)))
    info = {
        "path": kind,
        "png": str(png),
        "csv": str(folder / "curve.csv"),
        "vtk": str(folder / "vtk" / "series.pvd"),
        "increments": an.summary.increments,
        "iterations": an.summary.iterations,
        "cutbacks": an.summary.cutbacks,
        "wall_time_s": wall,
        "stabilization_ratio": an.summary.steps[0].get("stabilization_ratio"),
        "release_deg": rel.tolist(),
        "relatch_deg": back.tolist(),
        "peak_moment_Nm": float(curve["M"][i_peak]),
        "peak_at_deg": float(np.degrees(curve["theta"][i_peak])),
        "latched_at_end": int(np.sum(curve["zone"][-1] == 0)),
        "final_rotation_deg": float(np.degrees(curve["theta"][-1])),
        "final_moment_Nm": float(curve["M"][-1]),
        "pretension_N": float(
            np.mean(
                curve["tension"][
                    0
                    if len(curve["tension"]) == 1
                    else len(curve["step"]) - 1 - list(curve["step"])[::-1].index("pretension")
                ]
            )
        ),
    }
    (folder / "summary.json").write_text(json.dumps(info, indent=2))
    return info


def print_summary(info: dict):
    rel = ", ".join("held" if np.isnan(v) else f"{v:.2f}" for v in info["release_deg"])
    print(f"\n== {info['path']} path ==")
    print(
        f"  initial step: cables at {info['pretension_N']:.1f} N in equilibrium; stabilisation energy / strain "
        f"energy = {info['stabilization_ratio']:.2e}"
    )
    print(
        f"  peak moment {info['peak_moment_Nm']:.1f} N m (the bay's moment on the rig) at {info['peak_at_deg']:.3f} deg"
    )
    print(f"  latches reach zone {ZONE_LABELS[3]} at (deg), sides 0-3: {rel}")
    print(
        f"  end: rotation {info['final_rotation_deg']:.4f} deg, moment {info['final_moment_Nm']:.3f} N m, "
        f"{info['latched_at_end']} of 4 latches on their backstop"
    )
    print(
        f"  increments {info['increments']}, Newton iterations {info['iterations']}, cutbacks {info['cutbacks']}, "
        f"wall time {info['wall_time_s']:.1f} s"
    )
    print(f"  outputs: {info['png']}, {info['csv']}, {info['vtk']}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--path", choices=("ideal", "actual", "both"), default="both")
    ap.add_argument("--out", default="results/adam_bay_torsion")
    ap.add_argument("--theta", type=float, default=None, help="largest twist, degrees (ideal 3.5, actual 3.2)")
    ap.add_argument(
        "--hysteresis",
        type=float,
        nargs=2,
        metavar=("F_h", "ell"),
        default=None,
        help="latch hysteresis option: force (N) and length (m)",
    )
    ap.add_argument("--docs", action="store_true", help="copy the figures to docs/figures/")
    ap.add_argument("--quick", action="store_true", help="coarse increments (for tests)")
    ap.add_argument("--no-progress", action="store_true")
    args = ap.parse_args(argv)
    out = Path(args.out)
    kinds = ("ideal", "actual") if args.path == "both" else (args.path,)
    infos = []
    for kind in kinds:
        theta = args.theta if args.theta is not None else (3.5 if kind == "ideal" else 3.2)
        info = run_path(kind, out, theta, progress=not args.no_progress, hysteresis=args.hysteresis, quick=args.quick)
        print_summary(info)
        infos.append(info)
        if args.docs:
            suffix = "" if args.hysteresis is None else "_hysteresis"
            shutil.copy(info["png"], DOCS / f"adam_bay_{kind}{suffix}.png")
    total = sum(i["wall_time_s"] for i in infos)
    print(
        f"\nadam_bay_torsion: {len(infos)} path(s), {sum(i['increments'] for i in infos)} increments, "
        f"{sum(i['iterations'] for i in infos)} Newton iterations, wall time {total:.1f} s; results in {out}/"
    )
    return infos


if __name__ == "__main__":
    main(sys.argv[1:])
