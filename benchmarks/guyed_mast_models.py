"""Mast-1 top displacement of the Rocaspect robot predicted by the Rocaspect paper's mast models (Figs. 5-6).

The platform follows a trajectory like the Rocaspect paper, Fig. 5a (:func:`femast.guyed.rocaspect.fig5a_trajectory`).
At each pose the cable tensions come from the barycentric tension distribution, the cable
wrench on the top of mast 1 from Eq. 7, and each model maps the change of that wrench from
the initial pose, ``dw = w(pose) - w(POSE_0)``, to a top displacement, as in the paper's
Section IV-C.  Three shroud cases as in Fig. 6: 1200 N, 400 N, no shrouds.

Parameters (all from the paper unless stated):

* 3R: Table III, tests "1 and 8" (1200 N), "4" (400 N), "7 and 10" (no shrouds); the torsion
  joint is rigid (the paper found it unidentifiable).
* beam: E_1200N = 1.55e11 Pa and E_no_shroud = 6.55e10 Pa.  The paper gives no E for 400 N;
  here it is identified (``fit_beam_E``) from the 3R model's predicted displacements, so the
  400 N beam curve is the closest beam model to the 3R one, not an independent estimate.
* complete: the bare beam (E_no_shroud) plus three shrouds at the case's pretension, Dyneema
  law of Eq. 25 with the tangent stiffness, shroud geometry assumed in
  :mod:`femast.guyed.rocaspect`; linearised at the pretension (constant K_m).
* FE: the same mast in the FE core (:class:`femast.guyed.fe_mast.MastFE`: 16 corotational beam
  elements, E_no_shroud, three Eq. 25 shroud cables pretensioned to the case's tension at
  equilibrium).  Nonlinear: after the pretension step the full mast-1 cable wrench at the initial
  pose, w(POSE_0), is applied (dead loads at the top), then w(pose) for every pose; the displacement
  is measured from the state at POSE_0.  So, unlike the linear models, it sees the beam's geometric
  stiffness, the shroud tensions changing (and going slack) under the cable loads, and the law's
  progressive stiffness.

Adding a model: write ``predict(case, dw) -> (k, 6)`` and put it in ``MODELS`` (or pass
``models=`` to :func:`compute`); the plot and table pick it up.

Run:  python benchmarks/guyed_mast_models.py  [--docs]   (PNG in benchmarks/out/; --docs also
copies it to docs/figures/guyed_fe_mast_models.png; about 4 s, most of it the FE model)
"""

from __future__ import annotations

import shutil
import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
from femast.post import plotstyle  # noqa: E402  (the one femast figure style)

plotstyle.use()
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from femast.guyed import (  # noqa: E402
    cable_vectors,
    cantilever_compliance,
    cantilever_stiffness,
    compliance_3r,
    displacement_complete,
    fit_beam_E,
    mast_section,
    mast_stiffness,
    mast_top_wrenches,
    tension_distribution,
    trajectory_loads,
)
from femast.guyed.fe_mast import MastFE  # noqa: E402
from femast.guyed.rocaspect import (  # noqa: E402
    E_1200N,
    E_NO_SHROUD,
    L_BEAM,
    POSE_0,
    TABLE_III,
    fig5a_trajectory,
    mast_bases,
    mast_tops,
    rocaspect_geometry,
    rocaspect_shrouds,
)

OUT = Path(__file__).resolve().parent / "out"
DOCS_FIG = Path(__file__).resolve().parents[1] / "docs" / "figures" / "guyed_fe_mast_models.png"
MAST = 0  # mast 1


@dataclass
class Case:
    """One shroud configuration of the Rocaspect paper, Fig. 6."""

    name: str
    pretension: float | None  # N per shroud; None = shrouds detached
    k_theta: tuple  # 3R joint stiffnesses, N m/rad
    E_beam: float | None  # beam-model E, Pa (None: identified from the 3R prediction)
    fe_tension: np.ndarray | None = None  # filled by predict_fe: shroud tensions along the path, N


CASES = [
    Case("1200 N", 1200.0, (*TABLE_III["1 and 8"][2:], np.inf), E_1200N),
    Case("400 N", 400.0, (*TABLE_III["4"][2:], np.inf), None),
    Case("no shrouds", None, (*TABLE_III["7 and 10"][2:], np.inf), E_NO_SHROUD),
]
R_OC = mast_tops()[MAST] - mast_bases()[MAST]


def predict_3r(case: Case, dw):
    """3R model (Eqs. 4-6, corrected J)."""
    return dw @ compliance_3r(case.k_theta, R_OC).T


def predict_beam(case: Case, dw):
    """Cantilever model (Eqs. 8-15) with the case's E (identified from the 3R curve if the paper gives none)."""
    if case.E_beam is None:
        fit = fit_beam_E(dw, predict_3r(case, dw), L=L_BEAM, rows=(0, 1, 2))
        case.E_beam = float(fit.x[0])
    return dw @ cantilever_compliance(L_BEAM, mast_section(case.E_beam)).T


def predict_complete(case: Case, dw):
    """Beam (E_no_shroud) + shrouds at the pretension (Eqs. 16-26, tangent Dyneema stiffness)."""
    K_beam = cantilever_stiffness(L_BEAM, mast_section(E_NO_SHROUD))
    shrouds = None if case.pretension is None else rocaspect_shrouds(MAST, case.pretension)
    return displacement_complete(mast_stiffness(K_beam, mast_tops()[MAST], shrouds), dw)


def predict_fe(case: Case, dw):
    """Nonlinear FE mast (module note): pretension, then w(POSE_0), then w(POSE_0) + dw per pose."""
    geom = rocaspect_geometry()
    w0 = mast_top_wrenches(geom, POSE_0, tension_distribution(geom, POSE_0).tau)[MAST]
    fe = MastFE(case.pretension, mast=MAST, E=E_NO_SHROUD, n_beam=16)
    fe.equilibrate()
    out = fe.run_wrenches(np.vstack([w0, w0 + np.asarray(dw)]))
    case.fe_tension = out["tension"]  # shroud tensions along the trajectory (first row: at POSE_0), N
    return out["u"][1:] - out["u"][0]


MODELS = {"3R": predict_3r, "beam": predict_beam, "complete": predict_complete, "FE": predict_fe}


def compute(models=None, n_per_segment: int = 25):
    """Trajectory, mast-1 wrench changes and every model's top displacement (m, rad) per case."""
    models = MODELS if models is None else models
    geom = rocaspect_geometry()
    traj = fig5a_trajectory(n_per_segment)
    assert np.allclose(traj[0], POSE_0)
    tau, wrenches = trajectory_loads(geom, traj)
    dw = wrenches[:, MAST] - wrenches[0, MAST]
    cases = [replace(c) for c in CASES]  # predict_beam may fill in E_beam: keep CASES untouched
    pred = {c.name: {m: f(c, dw) for m, f in models.items()} for c in cases}
    return {"trajectory": traj, "tau": tau, "dw": dw, "pred": pred, "cases": cases}


def table(res, ref: str | None = None) -> str:
    """Max and RMS horizontal top displacement per model, and RMS / max differences to model ``ref``
    (default: the first model), in mm."""
    names0 = ref or next(iter(next(iter(res["pred"].values()))))
    lines = [
        f"{'case':<11} {'model':<9} {'max |dc|':>9} {'rms |dc|':>9} {'rms diff':>9} {'max diff':>9}"
        f"   (mm, x-y plane; diff to {names0})"
    ]
    for case, preds in res["pred"].items():
        ref_d = preds[names0][:, :2]
        for m in preds:
            d = preds[m][:, :2]
            mag = np.linalg.norm(d, axis=1) * 1e3
            diff = np.linalg.norm(d - ref_d, axis=1) * 1e3
            lines.append(
                f"{case:<11} {m:<9} {mag.max():9.2f} {np.sqrt((mag**2).mean()):9.2f} "
                f"{np.sqrt((diff**2).mean()):9.2f} {diff.max():9.2f}"
            )
    return "\n".join(lines)


def plot(res, path: Path):
    traj = res["trajectory"]
    fig = plt.figure(figsize=(12, 9.5))
    ax = fig.add_subplot(2, 2, 1, projection="3d")
    tops, bases = mast_tops(), mast_bases()
    for i, (b, t) in enumerate(zip(bases, tops)):
        ax.plot([b[0], t[0]], [b[1], t[1]], [0, t[2]], "k-", lw=2)
        ax.text(t[0], t[1], t[2] + 0.15, f"mast {i + 1}")
    geom = rocaspect_geometry()
    l, _, _, Rb = cable_vectors(geom, traj[0])
    B = Rb + traj[0, :3]
    for j, (a, b) in enumerate(zip(geom.exit_points, B)):
        ax.plot(
            [a[0], b[0]], [a[1], b[1]], [a[2], b[2]], color="0.6", lw=0.8, label="cables at POSE_0" if j == 0 else None
        )
    corners = np.array([[sx, sy, sz] for sx in (-0.5, 0.5) for sy in (-0.5, 0.5) for sz in (-0.25, 0.25)])
    for i in range(8):
        for k in range(i + 1, 8):
            if np.count_nonzero(corners[i] != corners[k]) == 1:
                e = traj[0, :3] + corners[[i, k]]
                ax.plot(e[:, 0], e[:, 1], e[:, 2], color="0.3", lw=0.8)
    ax.plot(traj[:, 0], traj[:, 1], traj[:, 2], "C3-", lw=2, label="platform centre")
    ax.scatter(*traj[0, :3], color="C3", s=30)
    ax.set(
        xlabel="x (m)",
        ylabel="y (m)",
        zlabel="z (m)",
        title="(a) platform trajectory (cf. Rocaspect paper Fig. 5a)",
        zlim=(0, 4.2),
    )
    ax.set_box_aspect((8.3, 6.8, 4.0))
    ax.legend(loc="upper right")
    styles = {
        "3R": dict(color="C0", lw=2.5),
        "beam": dict(color="C1", ls="--", lw=2),
        "complete": dict(color="C2", lw=1.5),
        "FE": dict(color="k", ls=":", lw=1.5),
    }
    for k, (case, preds) in enumerate(res["pred"].items()):
        a = fig.add_subplot(2, 2, k + 2)
        for m, d in preds.items():
            a.plot(d[:, 0] * 1e3, d[:, 1] * 1e3, label=m, **styles.get(m, {}))
        a.plot(0, 0, "ko", ms=4)
        a.set(
            xlabel="dx of mast-1 top (mm)",
            ylabel="dy (mm)",
            title=f"({'bcd'[k]}) " + (case if case == "no shrouds" else f"shroud pretension {case}"),
            aspect="equal",
        )
        a.grid(alpha=0.3)
        a.legend()
    fig.suptitle("Rocaspect mast 1: top displacement from the initial pose, analytic and FE models (cf. Fig. 6)")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    plotstyle.save(fig, path, dpi=110)
    plt.close(fig)


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    t0 = time.perf_counter()
    res = compute()
    png = OUT / "guyed_mast_models.png"
    plot(res, png)
    print(
        f"trajectory: {len(res['trajectory'])} poses; tensions {res['tau'].min():.0f}..{res['tau'].max():.0f} N; "
        f"mast-1 top force change |df| up to {np.linalg.norm(res['dw'][:, :3], axis=1).max():.0f} N"
    )
    print(
        "beam E per case (Pa): "
        + ", ".join(f"{c.name}: {c.E_beam:.3g}" for c in res["cases"])
        + "  (400 N: identified from the 3R curve; the paper gives none)"
    )
    print(table(res))
    if any(c.fe_tension is not None and c.fe_tension.size for c in res["cases"]):
        print(table(res, ref="FE"))
        for c in res["cases"]:
            if c.fe_tension is not None and c.fe_tension.size:
                t = c.fe_tension
                print(
                    f"FE shroud tensions, {c.name}: at POSE_0 {np.round(t[0]).tolist()} N; along the path "
                    + ", ".join(f"#{r + 1} {t[:, r].min():.0f}..{t[:, r].max():.0f}" for r in range(t.shape[1]))
                    + " N"
                )
    print(f"figure: {png}  ({time.perf_counter() - t0:.1f} s)")
    if "--docs" in argv:
        DOCS_FIG.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(png, DOCS_FIG)
        print(f"copied to {DOCS_FIG}")
    return res


if __name__ == "__main__":
    main()
