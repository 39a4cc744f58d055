"""Linear solves of small tangents: SuperLU, the band back-end and a dense LAPACK LU.

    python benchmarks/small_systems.py [--rounds 5] [--png benchmarks/out/small_systems.png]

For a model of a few dozen to a few hundred DOFs the factorisation's arithmetic is microseconds;
the cost is the bookkeeping around it.  Each model is run once with SuperLU, its tangents are kept,
and the tangent of the middle iteration is factorised and solved through
:class:`~femast.analysis.linalg.linear.SparseLU` (the path of an analysis: the values gathered into
the permuted matrix, the back-end's factorisation, a solve with its permutation and checks) by

* ``superlu``: scipy's SuperLU;
* ``banded``: the band back-end as the automatic rule uses it on masts (the Cholesky of the
  symmetric part refined against the tangent, or the band LU);
* ``banded-lu``: the band back-end's LU alone (``dgbtrf``: no refinement);
* ``dense``: the dense LU (``dgetrf``/``dgetrs``, :mod:`femast.analysis.linalg.dense`).

Models: the 45-degree bend of benchmarks/peers/bend45.py with 4, 8, 16 and 32 elements (a chain:
24-192 DOFs, RCM half-band 11), the truss mast of benchmarks/peers with 2, 5 and 10 bays (72-264
DOFs), a compact beam grid (3 x 3 x 3 nodes: a wide band) and the ADAM bay of the bay-torsion
experiment (a constrained model).  Printed per tangent and back-end: CPU time of a
factorisation + solve (best of ``--rounds`` interleaved rounds, each the mean of many calls) and
the normwise backward error; then the automatic choice (:func:`femast.analysis.linalg.backends.choose`).
The figure plots the CPU time against the DOFs.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks" / "peers"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from solver_backends import Capture, adam_bay_tangents, backward_error  # noqa: E402

from femast.analysis.linalg import backends, linear  # noqa: E402
from femast.analysis.linalg.banded import BandedFactor, band_of  # noqa: E402

ENGINES = ("superlu", "banded", "banded-lu", "dense")


def bend_tangents(n_el):
    import bend45

    import femast as fm
    from femast.analysis import Analysis

    m = fm.Model("bend")
    n = np.asarray(m.nodes(bend45.geometry(n_el)))
    m.beams(
        np.column_stack([n[:-1], n[1:]]),
        fm.Section(E=bend45.E, G=bend45.G, A=1.0, Iy=bend45.I, Iz=bend45.I, J=bend45.J),
        up=(0.0, 0.0, 1.0),
    )
    m.fix(n[0])
    m.step("load", initial_increment=0.1, max_increment=0.1).load(n[-1], fz=300.0)
    with Capture() as cap:
        Analysis(m, None, progress=False, on_frame=lambda f: None, linear_solver="superlu").run()
    return cap.tangents


def mast_tangents(n_bays):
    import femast_mast
    from mast import build_mast

    from femast.analysis import Analysis

    m, _ = femast_mast.model(build_mast(n_bays), 4)
    with Capture() as cap:
        Analysis(m, None, progress=False, on_frame=lambda f: None, linear_solver="superlu").run()
    return cap.tangents


def grid_tangents(k=3):
    """A compact frame: k x k x k nodes 1 m apart joined by beams along x, y and z, the bottom
    layer clamped, a lateral load on the top."""
    import femast as fm
    from femast.analysis import Analysis

    m = fm.Model("grid")
    idx = np.arange(k**3).reshape(k, k, k)
    X = np.array([(i, j, l) for i in range(k) for j in range(k) for l in range(k)], float)
    labels = np.asarray(m.nodes(X))
    sec = fm.Section(E=2e11, G=8e10, A=1e-3, Iy=1e-6, Iz=1e-6, J=2e-6)
    for axis, up in ((0, (0.0, 0.0, 1.0)), (1, (0.0, 0.0, 1.0)), (2, (1.0, 0.0, 0.0))):
        a = np.moveaxis(idx, axis, 0)
        pairs = np.column_stack([a[:-1].ravel(), a[1:].ravel()])
        m.beams(labels[pairs], sec, up=up)
    for lab in labels[idx[:, :, 0].ravel()]:
        m.fix(lab)
    st = m.step("push", initial_increment=0.25, max_increment=0.25)
    for lab in labels[idx[:, :, -1].ravel()]:
        st.load(lab, fx=1e4)
    with Capture() as cap:
        Analysis(m, None, progress=False, on_frame=lambda f: None, linear_solver="superlu").run()
    return cap.tangents


def solver_for(engine, K):
    lu = linear.SparseLU(ordering="rcm", backend="banded" if engine == "banded-lu" else engine)
    lu.factorize(K)
    if engine == "banded-lu":
        lu._engine = BandedFactor(lu._B, cholesky=False)
        lu.factorize(K)
    return lu


def time_engine(lu, K, rhs, calls):
    c0 = time.process_time()
    for _ in range(calls):
        lu.factorize(K)
        x = lu.solve(rhs)
    return (time.process_time() - c0) / calls, x


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--png", default=str(ROOT / "benchmarks" / "out" / "small_systems.png"))
    args = ap.parse_args(argv)
    cases = [(f"bend {k} el", lambda k=k: bend_tangents(k)) for k in (4, 8, 16, 32)]
    cases += [(f"mast {b} bays", lambda b=b: mast_tangents(b)) for b in (2, 5, 10)]
    cases += [("grid 3x3x3", grid_tangents), ("ADAM bay", adam_bay_tangents)]
    rows = []
    print(
        f"load average {os.getloadavg()[0]:.2f} (2 shared cores); CPU us per factorisation + solve "
        f"through SparseLU, best of {args.rounds} interleaved rounds"
    )
    print(
        f"{'model':<14s} {'n':>4s} {'band':>4s} {'nnz':>6s} "
        + " ".join(f"{e:>10s}" for e in ENGINES)
        + "  auto      backward errors"
    )
    for name, make in cases:
        tangents = make()
        B = tangents[len(tangents) // 2]
        K = B.tocsr()
        n = K.shape[0]
        rhs = np.random.default_rng(0).normal(size=n)
        calls = max(20, int(2e5 / (n * 30)))
        solvers = {e: solver_for(e, K) for e in ENGINES}
        best = {e: math.inf for e in ENGINES}
        berr = {}
        for _ in range(args.rounds):
            for e, lu in solvers.items():
                t, x = time_engine(lu, K, rhs, calls)
                best[e] = min(best[e], t)
                berr[e] = backward_error(K, x, rhs)
        auto = linear.SparseLU(ordering="rcm")
        auto.factorize(K)
        b = band_of(B.indptr, B.indices)
        rows.append((name, n, best))
        print(
            f"{name:<14s} {n:4d} {b:4d} {K.nnz:6d} "
            + " ".join(f"{best[e] * 1e6:10.1f}" for e in ENGINES)
            + f"  {auto.engine:<9s} "
            + " ".join(f"{berr[e]:.0e}" for e in ENGINES)
        )
    print(
        f"load average {os.getloadavg()[0]:.2f}; automatic rule: dense LU up to "
        f"{backends.DENSE_MAX_DOFS} DOFs, then the band rule, PARDISO, SuperLU"
    )
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.2))
    for e, mk in zip(ENGINES, "osd^"):
        ax.plot([r[1] for r in rows], [r[2][e] * 1e6 for r in rows], mk, label=e, alpha=0.8)
    for name, n, best in rows:
        ax.annotate(name, (n, best["superlu"] * 1e6), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("DOFs of the tangent")
    ax.set_ylabel("CPU per factorisation + solve (us)")
    ax.set_title("small tangents through SparseLU (benchmarks/small_systems.py)")
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    Path(args.png).parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(args.png, dpi=110)
    print(f"figure: {args.png}")


if __name__ == "__main__":
    main()
