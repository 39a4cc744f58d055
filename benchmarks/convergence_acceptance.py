"""How far from equilibrium the accepted increments are, strict and predicted correction test.

    python benchmarks/convergence_acceptance.py [--bays 40 400 1000] [--docs]

For each model, three runs on the same increments: femast's default tolerances (force and
correction 1e-6) with the strict correction test (``Convergence(predicted=False)``), the same with
the predicted-correction acceptance (``predicted=True``, the default), and a tightly converged
reference (force 1e-9 or 1e-8 where round-off allows, correction 1e-11, strict).  The models are
path-independent under load control, so the equilibrium of every increment is unique and each
accepted state can be compared with the reference's state of the same increment.

Per model it prints the Newton iterations of each run and, over all increments, the largest error
of an accepted state in units of the correction tolerance: for translations and rotations
separately, max |u - u_ref| / (disp_tol max |Du_ref|), with Du_ref the reference's increment (the
correction test's own measure); <= 1 is "within the tolerance".  Models: the peer masts of
benchmarks/peers (10 load increments), the 45-degree bend (180 increments) and the 8-element
cantilever of docs/solver.md (4 increments).  Writes benchmarks/out/convergence_acceptance.png
(``--docs``: docs/figures/performance_convergence_acceptance.png): each increment's error ratio, strict
and predicted.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "peers"))

import bend45  # noqa: E402
import femast_mast  # noqa: E402
from mast import build_mast  # noqa: E402

import femast as fm  # noqa: E402
from femast.analysis import Analysis  # noqa: E402

TOL = 1e-6


def _mast(n_bays):
    def build():
        return femast_mast.model(build_mast(n_bays), 10)[0]

    return build


def _bend():
    m = fm.Model("bend45")
    n = np.asarray(m.nodes(bend45.geometry(8)))
    m.beams(
        np.column_stack([n[:-1], n[1:]]),
        fm.Section(E=bend45.E, G=bend45.G, A=bend45.A, Iy=bend45.I, Iz=bend45.I, J=bend45.J),
        up=(0.0, 0.0, 1.0),
    )
    m.fix(n[0])
    m.step("load", initial_increment=1.0 / 180, max_increment=1.0 / 180).load(n[-1], fz=bend45.P_END)
    return m


def _cantilever():
    m = fm.Model("cantilever")
    a, b = m.node(0, 0, 0), m.node(1.0, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), up=(0, 0, 1), n=8)
    m.fix(a)
    m.step("bend", initial_increment=0.25, max_increment=0.25).load(b, fz=-400.0, my=30.0)
    return m


def frames(model, conv):
    """(iterations, [(U, UR) per increment]) of one run."""
    out = []
    an = Analysis(
        model,
        None,
        progress=False,
        convergence=conv,
        on_frame=lambda fr: out.append((np.array(fr["U"]), np.array(fr["UR"]))),
    )
    an.run()
    return an.summary.iterations, out[1:]


def error_ratios(run, ref):
    """Per increment: max over the two fields of max|x - x_ref| / (TOL max|Dx_ref|)."""
    ratios = []
    prev = (np.zeros_like(ref[0][0]), np.zeros_like(ref[0][1]))
    for (U, UR), (Ur, URr) in zip(run, ref):
        q = []
        for a, b, p in ((U, Ur, prev[0]), (UR, URr, prev[1])):
            scale = np.abs(b - p).max()
            if scale > 0:
                q.append(np.abs(a - b).max() / (TOL * scale))
        ratios.append(max(q))
        prev = (Ur, URr)
    return np.array(ratios)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bays", type=int, nargs="*", default=[40, 400, 1000])
    ap.add_argument("--docs", action="store_true", help="also copy the figure to docs/figures/")
    args = ap.parse_args(argv)
    models = [(f"mast, {n} bays", _mast(n), 1e-9) for n in args.bays]
    models += [("45-degree bend, 8 elements", _bend, 1e-9), ("cantilever (docs/solver.md)", _cantilever, 1e-8)]
    rows = []
    print(
        f"error of the accepted states in units of the correction tolerance (disp_tol = {TOL:g}); "
        f"load average {os.getloadavg()[0]:.1f}"
    )
    print(
        f"{'model':32s} {'iterations strict/predicted/reference':>38s} {'worst error strict':>19s} {'predicted':>10s}"
    )
    for name, build, ftol in models:
        it_s, f_s = frames(build(), fm.Convergence(force_tol=TOL, disp_tol=TOL, predicted=False))
        it_p, f_p = frames(build(), fm.Convergence(force_tol=TOL, disp_tol=TOL))
        it_r, f_r = frames(build(), fm.Convergence(force_tol=ftol, disp_tol=1e-11, predicted=False))
        e_s, e_p = error_ratios(f_s, f_r), error_ratios(f_p, f_r)
        rows.append((name, e_s, e_p))
        print(f"{name:32s} {f'{it_s} / {it_p} / {it_r}':>38s} {e_s.max():19.2e} {e_p.max():10.2e}")
    worst = max(r[2].max() for r in rows)
    print(
        f"largest error of a state accepted on its prediction: {worst:.2e} of the tolerance "
        f"({'within' if worst <= 1 else 'NOT within'} it)"
    )

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.5))
    for k, (name, e_s, e_p) in enumerate(rows):
        x = np.arange(1, len(e_s) + 1) / len(e_s)
        ax.semilogy(x, np.maximum(e_s, 1e-12), "o", ms=3, color=f"C{k}", alpha=0.4)
        ax.semilogy(x, np.maximum(e_p, 1e-12), "x", ms=4, color=f"C{k}", label=name)
    ax.axhline(1.0, color="k", lw=1)
    ax.text(0.01, 1.3, "correction tolerance", fontsize=8)
    ax.set_xlabel("load level (fraction of the step)")
    ax.set_ylabel("error / (disp_tol |Du|)")
    ax.set_title("accepted states against a tightly converged run: strict (o), predicted (x)")
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    out = HERE / "out"
    out.mkdir(exist_ok=True)
    png = out / "convergence_acceptance.png"
    fig.savefig(png, dpi=110)
    print(f"figure: {png}")
    if args.docs:
        dst = HERE.parent / "docs" / "figures" / "performance_convergence_acceptance.png"
        shutil.copy(png, dst)
        print(f"figure: {dst}")
    return 0 if worst <= 1 and not math.isnan(worst) else 1


if __name__ == "__main__":
    sys.exit(main())
