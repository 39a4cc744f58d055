"""Linear-solver back-ends on femast's own tangents.

    python benchmarks/solver_backends.py [--bays 40 400 1000] [--reps 7] [--png docs/figures/solver_backends.png]

Each model is run once with SuperLU, every factorised tangent is kept, and the tangent of the
middle iteration (a mid-increment, out-of-balance state) is factorised and solved ``--reps``
times by each back-end (:mod:`femast.analysis.linalg.backends`):

* the corotational truss mast of benchmarks/peers (40, 400, 1000 bays: 960 to 24 000 DOFs);
* the ADAM bay with ball-joint friction and latches, along the bay-torsion example path (a
  constrained model: its rigid top and bottom frames make the reduced tangent T^T K T);
* the 40-bay ADAM mast (rigid frames, cables, latches, friction) through Table 1's first M+F.

Fill: SuperLU and PARDISO count L and U, the Cholesky back-ends one triangle (banded: the
band n (b + 1), whatever its zeros).  Printed per tangent and back-end: the best and median factorisation wall time and its median CPU
time (ms), the solve time,
the fill (entries of the factors / entries of K), what the back-end did (Cholesky of the symmetric
part + refinement, or LU), the normwise backward error ||b - K x|| / (||K|| ||x|| + ||b||) and the
difference from SuperLU's solution.  Then the behaviour on an indefinite and on a nearly singular
tangent: the 40-bay mast's tangent shifted by its smallest eigenvalues (as at a limit point).
The machine's load and this process' CPU time are printed with the timings (a shared machine).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks" / "peers"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from femast.analysis.linalg import (
    backends,  # noqa: E402
    linear,  # noqa: E402
)
from femast.errors import SingularModelError  # noqa: E402

NAMES = ("superlu", "banded", "cholmod", "pardiso")


class Capture:
    """Keep a copy of every tangent SuperLU factorises (the permuted matrix, RCM order)."""

    def __init__(self):
        self.tangents = []
        self._orig = linear.SparseLU._timed

    def __enter__(self):
        cap = self

        def timed(solver, factor, *args):
            if args and args[0] is solver._B:
                cap.tangents.append(solver._B.copy())
            return cap._orig(solver, factor, *args)

        linear.SparseLU._timed = timed
        return self

    def __exit__(self, *exc):
        linear.SparseLU._timed = self._orig


def mast_tangents(n_bays):
    import femast_mast
    from mast import build_mast

    from femast.analysis import Analysis

    m, _ = femast_mast.model(build_mast(n_bays), 10)
    with Capture() as cap:
        Analysis(m, None, progress=False, on_frame=lambda f: None, linear_solver="superlu").run()
    return cap.tangents


def adam_bay_tangents():
    import femast.rigs.bay_torsion as bt
    from femast.experiments import get_experiment, read_data

    exp = get_experiment("bay-torsion")
    prep = bt._prepare(read_data(exp, ROOT / "femast" / "examples" / "bay_torsion_example.csv"), exp.options)
    drive = np.column_stack([prep["theta"], prep["ux"], prep["uy"]])[prep["rows"]]
    inputs = bt.bay_inputs({"latch_k": 1.08e5, "latch_mu": 0.065}, exp.options)
    with Capture() as cap:
        bt.run_bay(inputs, drive)
    return cap.tangents


def adam_mast_tangents():
    from adam_mast_table1 import build

    import femast as fm
    from femast.adam import BayParameters
    from femast.adam.steps import CONVERGENCE

    am = build(BayParameters(), 1, 1)
    names = [s.name for s in am.model.steps]
    am.model.steps = am.model.steps[: names.index("M+F#1") + 1]
    with Capture() as cap:
        fm.Analysis(am.model, None, progress=False, on_frame=lambda f: None, convergence=CONVERGENCE).run()
    return cap.tangents


def backward_error(K, x, b):
    return float(np.abs(b - K @ x).max() / (abs(K).sum(axis=1).max() * np.abs(x).max() + np.abs(b).max()))


def measure(K, name, reps, rhs):
    """Factorise and solve K (CSC, RCM order) with back-end ``name``; dict of the figures, or None
    if the back-end is not installed."""
    if name in ("cholmod", "pardiso") and not backends.available(name)[0]:
        return None
    lu = linear.SparseLU(ordering="rcm", backend=name)
    lu.factorize(K)
    B = lu._B
    fact, solve, cfact, csolve = [], [], [], []
    for _ in range(reps):
        c0, t0 = time.process_time(), time.perf_counter()
        f = lu._factor_permuted(B, superlu=(name == "superlu"))
        c1, t1 = time.process_time(), time.perf_counter()
        y = f.solve(rhs[lu._perm])
        c2, t2 = time.process_time(), time.perf_counter()
        fact.append(t1 - t0)
        solve.append(t2 - t1)
        cfact.append(c1 - c0)
        csolve.append(c2 - c1)
    x = np.empty_like(y)
    x[lu._perm] = y
    kind = getattr(f, "kind", "lu")
    return dict(
        fact_best=min(fact),
        fact_med=statistics.median(fact),
        solve_med=statistics.median(solve),
        cpu_fact_med=statistics.median(cfact),
        cpu_solve_med=statistics.median(csolve),
        fill=f.nnz / K.nnz,
        kind=kind,
        berr=backward_error(K, x, rhs),
        x=x,
        refinements=getattr(f, "refinements", 0),
        engine=lu.engine,
    )


def near_singular(K, rhs):
    """The 40-bay tangent made symmetric and shifted (a) between its two smallest eigenvalues
    (indefinite, as past a limit point) and (b) to 1e-14 of its smallest (a limit point)."""
    S = (0.5 * (K + K.T)).toarray()
    w = np.linalg.eigvalsh(S)
    out = {}
    for label, shift in (
        ("indefinite (shift between eigenvalues 1 and 2)", 0.5 * (w[0] + w[1])),
        ("nearly singular (smallest eigenvalue 1e-14 x largest)", w[0] - 1e-14 * w[-1]),
    ):
        A = sp.csc_matrix(S - shift * np.eye(S.shape[0]))
        row = {}
        for name in NAMES:
            if name in ("cholmod", "pardiso") and not backends.available(name)[0]:
                continue
            lu = linear.SparseLU(ordering="rcm", backend=name, pivot_check="always")
            try:
                lu.factorize(A)
                x = lu.solve(rhs)
                kind = getattr(lu._lu, "kind", "lu")
                row[name] = f"solved ({kind}), backward error {backward_error(A, x, rhs):.1e}"
            except SingularModelError as exc:
                row[name] = f"SingularModelError ({exc})"
        out[label] = row
    return out


def plot(rows, png):
    from femast.post import plotstyle

    plt = plotstyle.pyplot()
    models = list(rows)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    width = 0.8 / len(NAMES)
    for k, name in enumerate(NAMES):
        t = [
            (rows[m][name]["cpu_fact_med"] + rows[m][name]["cpu_solve_med"]) * 1e3 if rows[m].get(name) else np.nan
            for m in models
        ]
        f = [rows[m][name]["fill"] if rows[m].get(name) else np.nan for m in models]
        xs = np.arange(len(models)) + (k - 1.5) * width
        axes[0].bar(xs, t, width, label=name)
        axes[1].bar(xs, f, width, label=name)
    for ax, lab in (
        (axes[0], "factorisation + solve, CPU ms (median)"),
        (axes[1], "entries of the factors / entries of K"),
    ):
        ax.set_xticks(np.arange(len(models)))
        ax.set_xticklabels(models, rotation=20, ha="right", fontsize=8)
        ax.set_yscale("log")
        ax.set_ylabel(lab)
        ax.grid(True, axis="y", alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[0].set_title("time per tangent (lower is better)")
    axes[1].set_title("fill-in")
    fig.suptitle(
        f"linear-solver back-ends on femast tangents (load {os.getloadavg()[0]:.1f}, 2 cores shared)", fontsize=10
    )
    plotstyle.save(fig, png)
    print(f"figure: {png}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bays", type=int, nargs="+", default=[40, 400, 1000])
    ap.add_argument("--reps", type=int, default=7)
    ap.add_argument("--no-adam", action="store_true", help="leave out the ADAM bay and mast")
    ap.add_argument("--png", default=str(ROOT / "docs" / "figures" / "solver_backends.png"))
    args = ap.parse_args(argv)
    import femast_mast

    femast_mast.warm_up()
    for name in ("cholmod", "pardiso"):
        ok, why = backends.available(name)
        print(f"{name}: {'installed' if ok else 'NOT INSTALLED (' + why + '): ' + backends.INSTALL[name]}")
    print("UMFPACK: not measured (scikit-umfpack does not build here; see docs/performance.md)")
    models = {f"mast {n} bays": (lambda n=n: mast_tangents(n)) for n in args.bays}
    if not args.no_adam:
        models["ADAM bay (friction, latches, rigid frames)"] = adam_bay_tangents
        models["ADAM 40-bay mast (constrained)"] = adam_mast_tangents
    rows = {}
    first_K = None
    c0 = time.process_time()
    for label, make in models.items():
        tangents = make()
        K = tangents[len(tangents) // 2].tocsc()
        first_K = K if first_K is None else first_K
        rhs = np.random.default_rng(0).normal(size=K.shape[0])
        asym = abs(K - K.T).max() / abs(K).max()
        band = backends.band_of(K.indptr, K.indices)
        auto = backends.choose("auto", K, "rcm")
        print(
            f"\n{label}: {K.shape[0]} DOFs, nnz(K) {K.nnz}, RCM half-bandwidth {band}, |K - K^T| / |K| = "
            f"{asym:.1e}, {len(tangents)} tangents in the run; auto choice: {auto}   [load {os.getloadavg()[0]:.1f}]"
        )
        print(
            f"  {'back-end':9s} {'fact best':>9s} {'fact med':>9s} {'CPU med':>8s} {'solve':>8s} {'fill':>6s}  {'did':9s} "
            f"{'refine':>6s} {'backward err':>12s} {'x vs SuperLU':>12s}"
        )
        rows[label] = {}
        ref = None
        for name in NAMES:
            r = measure(K, name, args.reps, rhs)
            rows[label][name] = r
            if r is None:
                print(f"  {name:9s} not installed")
                continue
            ref = r["x"] if name == "superlu" else ref
            dx = np.abs(r["x"] - ref).max() / np.abs(ref).max()
            print(
                f"  {name:9s} {r['fact_best'] * 1e3:8.2f}  {r['fact_med'] * 1e3:8.2f}  {r['cpu_fact_med'] * 1e3:7.2f} "
                f"{r['solve_med'] * 1e3:7.2f} "
                f"{r['fill']:6.2f}  {r['kind']:9s} {r['refinements']:6d} {r['berr']:12.1e} {dx:12.1e}"
            )
    print("\nbehaviour on an indefinite and a nearly singular tangent (the first model's, symmetrised):")
    for label, row in near_singular(first_K, np.random.default_rng(1).normal(size=first_K.shape[0])).items():
        print(f"  {label}:")
        for name, what in row.items():
            print(f"    {name:9s} {what}")
    print(f"\nCPU time of this process: {time.process_time() - c0:.1f} s; load average {os.getloadavg()}")
    plot(rows, args.png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
