"""Where a Newton iteration's time goes, against the linear solve in the same run (issue 8).

    python benchmarks/iteration_breakdown.py [--bays 40 400] [--runs 8]

Solves the truss mast of ``benchmarks/peers/mast.py`` (beam-columns, tip torsion + shear, 10 load
increments) --runs times per size, with a wall-clock timer around each part of the Newton loop,
and prints the time per iteration of each part next to the time spent inside SuperLU
(factorisation + triangular solves, measured by femast's SparseLU in the same runs).  Timers cost
about 1 us per call, a few per iteration.

It draws ``benchmarks/out/iteration_breakdown.png``: one bar per size, each part in units of the
SuperLU time.  Parts that do not exist in an older femast are skipped, so the same command measures a checkout
put first on ``PYTHONPATH`` (the "before" column of docs/performance.md).
"""

from __future__ import annotations

import argparse
import functools
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "peers"))

PARTS = [  # (module, class, method, label)
    ("femast.elements.beam_corot", "BeamFamily", "evaluate", "beam kernel (element forces + tangents)"),
    ("femast.analysis", "Analysis", "_residual", "residual assembly"),
    ("femast.analysis.assembly", "Assembler", "tangent", "tangent assembly into CSR"),
    ("femast.analysis.assembly", "Assembler", "tangent_into", "tangent assembly into the solver's matrix"),
    ("femast.analysis.solvers.linear", "SparseLU", "factorize", "SparseLU.factorize (CSR path, incl. SuperLU)"),
    ("femast.analysis.solvers.linear", "SparseLU", "factorize_values", "SparseLU.factorize_values (incl. SuperLU)"),
    ("femast.analysis.solvers.linear", "SparseLU", "solve", "SparseLU.solve (incl. SuperLU)"),
    ("femast.analysis.solvers.linear", "SparseLU", "_factor_permuted", "  of which SuperLU factorisations (all)"),
    ("femast.analysis", "Analysis", "_converged", "convergence test"),
    ("femast.analysis", "Analysis", "_update", "configuration update"),
    ("femast.analysis", "Analysis", "_write", "results frame (gather + hand-over)"),
    ("femast.post.results", "ResultsWriter", "status", "status line (.sta)"),
]


def instrument():
    import importlib

    acc = {}
    for mod, cls_name, meth, label in PARTS:
        cls = getattr(importlib.import_module(mod), cls_name)
        fn = cls.__dict__.get(meth)
        if fn is None:
            continue

        @functools.wraps(fn)
        def timed(*a, _fn=fn, _label=label, **k):
            t0 = time.perf_counter()
            try:
                return _fn(*a, **k)
            finally:
                acc[_label] = acc.get(_label, 0.0) + time.perf_counter() - t0

        setattr(cls, meth, timed)
    return acc


def breakdown(n_bays, runs):
    import femast_mast
    from mast import build_mast

    acc = instrument()
    femast_mast.warm_up()
    mast = build_mast(n_bays)
    femast_mast.solve(mast, 10)
    acc.clear()
    total = superlu = increments = 0.0
    iters = 0
    for _ in range(runs):
        r = femast_mast.solve(mast, 10)
        total += r["analyze"]
        increments += getattr(r["analysis"].summary, "increment_time", float("nan"))
        iters += r["iterations"]
        superlu += getattr(r["analysis"].solver, "superlu_seconds", float("nan"))
    ms = 1e3 / iters
    print(f"\n{n_bays}-bay mast ({len(mast.conn)} beams), {runs} runs, {iters // runs} iterations each; "
          f"ms per Newton iteration:")
    print(f"  {'whole iteration (run wall time / iterations)':<48} {total * ms:8.3f}")
    print(f"  {'  increments only (no per-run set-up, close)':<48} {increments * ms:8.3f}")
    print(f"  {'inside SuperLU (factorise + solve, same runs)':<48} {superlu * ms:8.3f}")
    for label, t in sorted(acc.items(), key=lambda kv: -kv[1]):
        print(f"  {label:<48} {t * ms:8.3f}")
    print(f"  iteration / SuperLU: {total / superlu:.2f} (whole run), {increments / superlu:.2f} (increments only); "
          "target <= 1.5")
    return {"bays": n_bays, "whole": total * ms, "superlu": superlu * ms, "parts": {k: v * ms for k, v in acc.items()}}


def plot(results, path):
    """One bar per size: each part of an iteration in units of the SuperLU time of the same runs."""
    import matplotlib

    matplotlib.use("Agg")
    from femast.post import plotstyle  # noqa: E402  (the one femast figure style, issue 17)

    plotstyle.use()
    import matplotlib.pyplot as plt

    shown = ["beam kernel (element forces + tangents)", "tangent assembly into the solver's matrix",
             "tangent assembly into CSR", "residual assembly", "convergence test", "configuration update",
             "results frame (gather + hand-over)", "status line (.sta)"]
    fig, ax = plt.subplots(figsize=(9, 1.2 + 0.9 * len(results)))
    for y, r in enumerate(results):
        left = 1.0
        ax.barh(y, 1.0, color="0.75", edgecolor="k", label="SuperLU (factorise + solve)" if y == 0 else None)
        for i, name in enumerate(shown):
            w = r["parts"].get(name, 0.0) / r["superlu"]
            if w > 0:
                ax.barh(y, w, left=left, color=f"C{i}", label=name if y == 0 else None)
                left += w
        rest = r["whole"] / r["superlu"] - left
        ax.barh(y, max(rest, 0.0), left=left, color="w", edgecolor="k", hatch="//",
                label="the rest (Python between the parts)" if y == 0 else None)
        ax.text(r["whole"] / r["superlu"] + 0.02, y, f"{r['whole'] / r['superlu']:.2f}", va="center")
    ax.axvline(1.5, color="r", ls=":", label="target 1.5")
    ax.set(yticks=range(len(results)), yticklabels=[f"{r['bays']} bays" for r in results],
           xlabel="time per Newton iteration / SuperLU time in the same runs",
           title="where a Newton iteration goes (truss mast of beam-columns)")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.35), ncol=3)
    fig.tight_layout()
    plotstyle.save(fig, path, dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bays", type=int, nargs="+", default=[40, 400])
    ap.add_argument("--runs", type=int, default=8)
    args = ap.parse_args(argv)
    import femast

    print(f"femast at {os.path.dirname(femast.__file__)}")
    results = [breakdown(nb, args.runs) for nb in args.bays]
    if all(r["superlu"] == r["superlu"] for r in results):   # an old femast has no SuperLU timer (nan)
        out = os.path.join(HERE, "out", "iteration_breakdown.png")
        os.makedirs(os.path.dirname(out), exist_ok=True)
        plot(results, out)
        print(f"\nfigure {out}")


if __name__ == "__main__":
    sys.exit(main())
