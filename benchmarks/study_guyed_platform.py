"""A study script: the platform error of the Rocaspect cable robot (the Rocaspect paper, Fig. 7) over the
scatter of its 12 shroud lengths, 12 shroud pretensions and the temperature.

    femast study benchmarks/study_guyed_platform.py --samples 64 --workers 2
    python benchmarks/study_guyed_platform.py [--samples 64] [--workers 2]   # + the figure

The controller works in a rigid frame calibrated at the installation (exit points measured at the
pose ``POSE_0`` with the masts as they stand: their shroud errors and pretensions included, so the
static lean these give the tops is calibrated away).  Afterwards the masts still move:

* under the changing cable wrenches along the trajectory, with a compliance that depends on each
  mast's shroud tensions (:class:`~femast.guyed.fe_mast.MastFE`'s condensed tangent);
* with the temperature change ``dT`` after the calibration (tube +23e-6 /K, Dyneema -12e-6 /K): the
  top displacement of each FE mast from its calibration state (step ``thermal``), fed to the pose
  solve as the masts' remainder ``delta`` (:func:`femast.guyed.platform_pose.solve_pose`).

Scatter as in ``benchmarks/study_guyed.py`` (per shroud: length error normal 0.5 mm truncated at
+-1 mm, pretension normal 1200 +- 60 N; dT uniform -20..+20 K).  Outputs: the platform position error
(m) at the calibration pose and at the farthest corner of the Fig. 5a path, and the largest
|position error| (m) over the path.  Linear mast compliance per sample (the FE remainder of large
wrenches is left out: below 2e-4 of the pose error for the Rocaspect, docs/guyed_masts.md).
"""

import argparse
import sys
from pathlib import Path

import numpy as np

import femast.studies as st
from femast.elements.shroud_cable import unstretched_length
from femast.elements.shroud_law import DyneemaLaw
from femast.guyed.fe_mast import MastFE
from femast.guyed.platform_pose import CableRobot, MastSet, rigid_masts, solve_pose
from femast.guyed.rocaspect import POSE_0, fig5a_trajectory, rocaspect_geometry, rocaspect_shrouds

T_NOMINAL = 1200.0  # N
ALPHA_SHROUD, ALPHA_TUBE = -12e-6, 23e-6  # 1/K
ROBOT = CableRobot(rocaspect_geometry())
PATH = fig5a_trajectory(3)  # 19 poses (m, rad): the Fig. 5a rectangle and climb
FAR = int(np.argmax(np.linalg.norm(PATH[:, :3] - POSE_0[:3], axis=1)))
CAL = solve_pose(ROBOT, rigid_masts(4), POSE_0)  # the calibration state (rigid frame)
_LAW = DyneemaLaw()
_L0_NOM, _LENGTHS = [], []
for _i in range(4):
    _sh = rocaspect_shrouds(_i, T_NOMINAL)
    _LENGTHS.append(np.linalg.norm(_sh.lower - _sh.upper, axis=1))
    _L0_NOM.append(unstretched_length(_LAW, T_NOMINAL, _LENGTHS[-1]))


def mast_response(i, dL, pretension, dT):
    """Top compliance (6, 6) of mast i at its (heated) state and its top displacement (6,) from the
    calibration state to the end of the temperature change."""
    dL_pre = unstretched_length(_LAW, np.asarray(pretension), _LENGTHS[i]) - _L0_NOM[i]
    fe = MastFE(
        T_NOMINAL,
        mast=i,
        length_error=np.asarray(dL) + dL_pre,
        temperature_change_K=dT,
        shroud_alpha_per_K=ALPHA_SHROUD,
        beam_alpha_per_K=ALPHA_TUBE,
    )
    fe.solve()
    last = {step: u for step, u, _ in fe._frames}
    u_cal = last["pretension"]
    u_now = last.get("thermal", u_cal)
    return np.linalg.inv(fe.top_stiffness("full")), u_now - u_cal


def platform(dL_shroud, pretension, dT):
    """One sample: 12 length errors (m) and pretensions (N), masts 1-4 x shrouds 1-3; dT (K)."""
    C, delta = [], []
    for i in range(4):
        c, d = mast_response(i, dL_shroud[3 * i : 3 * i + 3], pretension[3 * i : 3 * i + 3], dT)
        C.append(c)
        delta.append(d)
    masts = MastSet("sample", np.array(C))
    err = []
    for p in PATH:
        s = solve_pose(ROBOT, masts, p, w_cal=CAL.wrench, delta=np.array(delta))
        if not s.feasible:
            raise RuntimeError(f"pose {np.round(p[:3], 3).tolist()} infeasible: {s.reason}")
        err.append(s.error[:3])
    err = np.array(err)
    return {"error_cal": err[0], "error_far": err[FAR], "error_max": float(np.linalg.norm(err, axis=1).max())}


study = st.Study(
    run=platform,
    inputs=[
        st.TruncatedNormal("dL_shroud", 0.0, 0.5e-3, low=-1e-3, high=1e-3, size=12),
        st.Normal("pretension", T_NOMINAL, 60.0, size=12),
        st.Uniform("dT", -20.0, 20.0),
    ],
    outputs=["error_cal", "error_far", "error_max"],
    units={"error_cal": "m", "error_far": "m", "error_max": "m"},
    sensitivity=True,
    seed=1,
    timeout_s=300.0,
    name="guyed_platform",
)


def figure(folder, png):
    import matplotlib.pyplot as plt

    res = st.load(folder)
    e_cal = res.output("error_cal") * 1e3
    e_max = res.output("error_max") * 1e3
    dT = res.inputs("dT")
    pre = res.inputs("pretension")
    fig, ax = plt.subplots(1, 3, figsize=(13, 4.2))
    for k, lab in enumerate("xyz"):
        ax[0].plot(dT, e_cal[:, k], "o", ms=3, alpha=0.6, label=f"error {lab}")
    ax[0].set_xlabel("temperature change after calibration dT (K)")
    ax[0].set_ylabel("platform error at the calibration pose (mm)")
    ax[1].plot(np.abs(pre - T_NOMINAL).max(axis=1), e_max, "o", ms=3, alpha=0.6)
    ax[1].set_xlabel("largest pretension deviation of the 12 shrouds (N)")
    ax[1].set_ylabel("largest |position error| over the path (mm)")
    ax[2].hist(e_max, bins=25, histtype="step", lw=1.5)
    ax[2].set_xlabel("largest |position error| over the path (mm)")
    ax[2].set_ylabel("samples")
    for a in ax:
        a.grid(alpha=0.3)
    ax[0].legend(fontsize=8)
    fig.suptitle(f"Rocaspect platform error over {len(dT)} samples (FE masts; exit points calibrated at POSE_0)")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--samples", type=int, default=64)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--out", default="studies/study_guyed_platform")
    p.add_argument("--figures", default=None, help="also copy the figures here (e.g. docs/figures)")
    a = p.parse_args(argv)
    s = st.run(study, a.out, samples=a.samples, workers=a.workers)
    print(s)
    from femast.studies.report import report

    report(a.out, print_table=True, figures=True)
    figure(a.out, Path(a.out) / "figures" / "platform_error.png")
    res = st.load(a.out)
    e = res.output("error_max") * 1e3
    q = st.percentile(e, 0.95)
    print(
        f"largest |platform position error| over the path: median {np.median(e):.2f} mm, 95th percentile "
        f"{q['estimate']:.2f} mm (95 % interval {q['low']:.2f}-{q['high']:.2f} mm) over {len(e)} samples"
    )
    if a.figures:
        import shutil

        for src, dst in (
            ("platform_error.png", "studies_guyed_platform_error.png"),
            ("sensitivity.png", "studies_guyed_platform_sensitivity.png"),
        ):
            shutil.copy(Path(a.out) / "figures" / src, Path(a.figures) / dst)
    return 0 if s.failed == 0 else 3


if __name__ == "__main__":
    sys.exit(main())
