"""A study script: where the top of a guyed Rocaspect mast ends up over the scatter of
its shroud lengths, shroud pretensions and the temperature.

    femast study benchmarks/study_guyed.py --samples 128 --workers 2     # the study + its report
    python benchmarks/study_guyed.py [--samples 128] [--workers 2]      # the same, plus the error figure

Model: :class:`femast.guyed.fe_mast.MastFE` (mast 1: the 3.651 m aluminium tube as 16 corotational
beams, three Dyneema shrouds with the Rocaspect paper, Eq. 25 law on rigid offsets of the top).  Load
history: pretension, a uniform temperature change of tube and shrouds (step ``thermal``), then the
working pull of the robot's cable on the top (step ``load``, ``WORK_LOAD``).

Scatter (stated here; the paper gives none):
* shroud length errors ``dL_shroud``: each rope's lack of fit, normal 0.5 mm standard deviation
  truncated at +-1 mm (cut to length by hand on ~3.8 m of rope);
* pretensions ``pretension``: each rope tensioned to 1200 N within a normal 5 % (60 N) standard
  deviation (read on a tension gauge); it sets the rope's unstretched length in the nominal geometry
  (:func:`femast.elements.shroud_cable.unstretched_length`), to which the length error adds;
* temperature change ``dT`` from the installation: uniform -20..+20 K (a day outdoors), with
  Dyneema's -12e-6 /K along the fibre and aluminium's +23e-6 /K (the Rocaspect paper gives no expansion).

Outputs: the top displacement ``top_u`` (m) and spin ``top_rot`` (rad) from the initial geometry at
the end of the steps ``thermal`` (the unloaded mast) and ``load``; the error is their difference
from the nominal mast (all inputs at their nominal values), printed by the main block.
"""

import argparse
import sys
from pathlib import Path

import numpy as np

import femast.studies as st
from femast.elements.shroud_cable import unstretched_length
from femast.elements.shroud_law import DyneemaLaw
from femast.guyed.fe_mast import MastFE

T_NOMINAL = 1200.0  # N, the paper's pretension
ALPHA_SHROUD, ALPHA_TUBE = -12e-6, 23e-6  # 1/K (Dyneema along the fibre, aluminium)
WORK_LOAD = {"fx": 200.0, "fy": 160.0, "fz": -160.0}  # N, the cable's pull toward the platform
STEPS = ["thermal", "load"]

_nominal = MastFE(T_NOMINAL)
_nominal.build()
TOP = _nominal.top  # node label of the top
_sh = _nominal.shrouds_nominal
LENGTHS = np.linalg.norm(_sh.lower - _sh.upper, axis=1)  # m, rope lengths in the nominal geometry


def guyed_mast(dL_shroud, pretension, dT):
    """The model of one sample: length errors (3,) m, pretensions (3,) N, temperature change K."""
    law = DyneemaLaw()
    # a rope tensioned to T in the nominal geometry is that much shorter than one tensioned to 1200 N
    dL_pre = unstretched_length(law, np.asarray(pretension), LENGTHS) - _nominal.L0
    fe = MastFE(
        T_NOMINAL,
        length_error=np.asarray(dL_shroud) + dL_pre,
        temperature_change_K=dT,
        shroud_alpha_per_K=ALPHA_SHROUD,
        beam_alpha_per_K=ALPHA_TUBE,
    )
    m = fe.build()
    if dT == 0.0:  # keep the same steps (MastFE adds "thermal" only if dT != 0)
        m.step("thermal")
    m.step("load").load(fe.top, **WORK_LOAD)
    return m


study = st.Study(
    model=guyed_mast,
    inputs=[
        st.TruncatedNormal("dL_shroud", 0.0, 0.5e-3, low=-1e-3, high=1e-3, size=3),
        st.Normal("pretension", T_NOMINAL, 60.0, size=3),
        st.Uniform("dT", -20.0, 20.0),
    ],
    outputs=[
        st.NodeOutput("top_u", node=TOP, quantity="U", at=STEPS),
        st.NodeOutput("top_rot", node=TOP, quantity="URA", at=STEPS),
    ],
    sensitivity=True,
    seed=1,
    timeout_s=120.0,
    name="guyed_mast",
)


def nominal_outputs():
    """top_u, top_rot (2, 3) of the nominal mast (no error, 1200 N, dT = 0)."""
    import femast as fm

    frames = {}
    m = guyed_mast(np.zeros(3), np.full(3, T_NOMINAL), 0.0)
    row = m.index(TOP)
    fm.Analysis(m, None, progress=False, on_frame=lambda fr: frames.__setitem__(str(fr["step"]), fr)).run()
    return (np.array([frames[s]["U"][row] for s in STEPS]), np.array([frames[s]["URA"][row] for s in STEPS]))


def error_figure(folder, png):
    """The top position error (mm; position minus the nominal mast's) of every sample: the lateral
    error cloud, the vertical error against the temperature change, the distribution of |error|.
    Returns the errors (n, 2 steps, 3), m."""
    import matplotlib.pyplot as plt

    res = st.load(folder)
    u0, _ = nominal_outputs()
    err = res.output("top_u") - u0[None]  # (n, 2, 3) m
    e = err * 1e3
    dT = res.inputs("dT")
    fig, ax = plt.subplots(1, 3, figsize=(13, 4.2))
    for j, (step, mk) in enumerate(zip(STEPS, ("o", "x"))):
        ax[0].plot(e[:, j, 0], e[:, j, 1], mk, ms=3, alpha=0.5, label=f"after '{step}'")
        ax[1].plot(dT, e[:, j, 2], mk, ms=3, alpha=0.5, label=f"after '{step}'")
        ax[2].hist(np.linalg.norm(e[:, j], axis=1), bins=30, histtype="step", lw=1.5, label=f"after '{step}'")
    ax[0].set_aspect("equal", adjustable="datalim")
    ax[0].set_xlabel("top error x (mm)")
    ax[0].set_ylabel("top error y (mm)")
    ax[0].set_title("lateral error (shroud lengths, pretensions)")
    ax[1].set_xlabel("temperature change dT (K)")
    ax[1].set_ylabel("top error z (mm)")
    ax[1].set_title("vertical error (tube +23e-6 /K, Dyneema -12e-6 /K)")
    ax[2].set_xlabel("|top error| (mm)")
    ax[2].set_ylabel("samples")
    ax[2].set_title(f"distribution over {len(dT)} samples")
    for a in ax:
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    fig.suptitle("Guyed Rocaspect mast 1: top position minus the nominal mast's (FE, Rocaspect Dyneema law)")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return err


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--samples", type=int, default=128)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--out", default="studies/study_guyed")
    p.add_argument("--figures", default=None, help="also copy the figures here (e.g. docs/figures)")
    a = p.parse_args(argv)
    s = st.run(study, a.out, samples=a.samples, workers=a.workers)
    print(s)
    from femast.studies.report import report

    report(a.out, print_table=False, figures=True)
    err = error_figure(a.out, Path(a.out) / "figures" / "top_error.png")
    mag = np.linalg.norm(err, axis=2) * 1e3  # mm
    for j, step in enumerate(STEPS):
        p95 = st.percentile(mag[:, j], 0.95)
        print(
            f"after '{step}': |top error| median {np.median(mag[:, j]):.2f} mm, 95th percentile "
            f"{p95['estimate']:.2f} mm (95 % interval {p95['low']:.2f}-{p95['high']:.2f} mm), "
            f"max {mag[:, j].max():.2f} mm over {len(mag)} samples"
        )
    res = st.load(a.out)
    fA, fB, fAB, dropped = res.saltelli("top_u")
    u0, _ = nominal_outputs()
    names = [i.name for i in study.inputs]
    for j, step in enumerate(STEPS):
        e = [np.linalg.norm(f[..., j, :] - u0[j], axis=-1) for f in (fA, fB, fAB)]  # |error|, m
        idx = st.sobol_indices(*e, names)
        print(
            f"Sobol' indices of |top error| after '{step}' ({dropped} base samples dropped): "
            + ", ".join(
                f"{n}: S1 {idx['S1'][k]:.2f} [{idx['S1_low'][k]:.2f}, {idx['S1_high'][k]:.2f}] ST {idx['ST'][k]:.2f} "
                f"[{idx['ST_low'][k]:.2f}, {idx['ST_high'][k]:.2f}]"
                for k, n in enumerate(names)
            )
        )
    if a.figures:
        import shutil

        for src, dst in (
            ("top_error.png", "studies_guyed_top_error.png"),
            ("sensitivity.png", "studies_guyed_sensitivity.png"),
        ):
            shutil.copy(Path(a.out) / "figures" / src, Path(a.figures) / dst)
    return 0 if s.failed == 0 else 3


if __name__ == "__main__":
    sys.exit(main())
