"""Where a Newton iteration's time goes, against the linear solve in the same run.

    python benchmarks/iteration_breakdown.py [--bays 40 400 1000] [--runs 8]

Solves the truss mast of ``benchmarks/peers/mast.py`` (beam-columns, tip torsion + shear, 10 load
increments) --runs times per size, with a timer (wall clock and the thread's CPU time) around each
part of the Newton loop, and prints the time per iteration of each part next to the time spent
inside the linear solver (factorisation + triangular solves, whichever back-end: SuperLU or the
band solver, measured by femast's SparseLU in the same runs).  Indented parts are inside the part
above them.  Timers cost about 1 us per call, a few per iteration.

It draws ``benchmarks/out/iteration_breakdown.png``: one bar per size, each part in units of the
linear solver's time.  Parts that do not exist in an older femast are skipped, so the same command measures a checkout
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

PARTS = [  # (module, attribute path, label); an indented label is part of the one above it
    ("femast.analysis.newton", "Newton.solve", "Newton.solve (whole increments)"),
    ("femast.analysis.system", "System.evaluate", "element evaluation (all families + finiteness)"),
    ("femast.elements.beam_corot", "BeamFamily.evaluate", "  beam kernel (element forces + tangents)"),
    ("femast.analysis.system", "System.residual", "residual assembly (internal forces - loads)"),
    ("femast.analysis.assembly", "Assembler.tangent_into", "tangent assembly into the solver's matrix"),
    ("femast.analysis.assembly", "Assembler.tangent", "tangent assembly into CSR"),
    ("femast.analysis.linalg.linear", "SparseLU.factorize_values", "factorisation (from the solver's matrix)"),
    ("femast.analysis.linalg.banded", "_fill_split", "  band: symmetric part + asymmetry (_fill_split)"),
    ("femast.analysis.linalg.banded", "lapack.dpbtrf", "  band: Cholesky (dpbtrf)"),
    ("femast.analysis.linalg.banded", "lapack.dgbtrf", "  band: LU (dgbtrf)"),
    ("femast.analysis.linalg.linear", "SparseLU.factorize", "factorisation (CSR path)"),
    ("femast.analysis.linalg.linear", "SparseLU.solve", "solve (incl. refinement)"),
    ("femast.analysis.linalg.banded", "lapack.dpbtrs", "  band: Cholesky solves (dpbtrs)"),
    ("femast.analysis.linalg.banded", "_residual_split", "  band: refinement residual (_residual_split)"),
    ("femast.analysis.system", "System.converged", "convergence test"),
    ("femast.analysis.system", "System.update", "configuration update"),
    ("femast.analysis.system", "System.commit", "commit (per increment)"),
    ("femast.analysis.output", "ResultsObserver.converged", "results frame (per increment)"),
    # older femast: the same parts under their names of then
    ("femast.analysis", "Analysis._residual", "residual assembly"),
    ("femast.analysis", "Analysis._converged", "convergence test"),
    ("femast.analysis", "Analysis._update", "configuration update"),
    ("femast.analysis", "Analysis._write", "results frame (gather + hand-over)"),
    ("femast.analysis.linalg.linear", "SparseLU._factor_permuted", "  of which SuperLU factorisations (all)"),
]


def _wrap(fn, label, acc):
    @functools.wraps(fn)
    def timed(*a, **k):
        t0, c0 = time.perf_counter(), time.thread_time()
        try:
            return fn(*a, **k)
        finally:
            rec = acc.setdefault(label, [0.0, 0.0, 0])
            rec[0] += time.perf_counter() - t0
            rec[1] += time.thread_time() - c0
            rec[2] += 1

    return timed


def instrument():
    """Timers (wall and this thread's CPU time) around the parts of PARTS that exist in the
    femast imported; returns the {label: [wall s, CPU s, calls]} they add to."""
    import importlib
    import types

    acc = {}
    for mod, path, label in PARTS:
        try:
            owner = importlib.import_module(mod)
        except ImportError:
            continue
        *outer, name = path.split(".")
        for part in outer:
            owner = getattr(owner, part, None)
            if owner is None:
                break
        if owner is None:
            continue
        if isinstance(owner, type):
            fn = owner.__dict__.get(name)
        else:
            fn = getattr(owner, name, None)
        if fn is None:
            continue
        if outer and isinstance(owner, types.ModuleType):
            # a function of a library module called through ours (banded.lapack.dpbtrf): our module
            # gets a proxy of the library module with that function timed
            m = importlib.import_module(mod)
            proxy = getattr(m, outer[0])
            if not isinstance(proxy, types.SimpleNamespace):
                proxy = types.SimpleNamespace(**{k: getattr(owner, k) for k in dir(owner) if not k.startswith("__")})
                setattr(m, outer[0], proxy)
            setattr(proxy, name, _wrap(fn, label, acc))
        else:
            setattr(owner, name, _wrap(fn, label, acc))
    return acc


def breakdown(n_bays, runs):
    import femast_mast
    from mast import build_mast

    acc = instrument()
    femast_mast.warm_up()
    mast = build_mast(n_bays)
    femast_mast.solve(mast, 10)
    acc.clear()
    total = cpu = superlu = increments = 0.0
    iters = facts = 0
    for _ in range(runs):
        r = femast_mast.solve(mast, 10)
        total += r["analyze"]
        cpu += r["cpu_analyze"]
        increments += getattr(r["analysis"].summary, "increment_time", float("nan"))
        iters += r["iterations"]
        superlu += getattr(r["analysis"].solver, "superlu_seconds", float("nan"))
        facts += getattr(r["analysis"].solver, "factorizations", 0)
    ms = 1e3 / iters
    print(
        f"\n{n_bays}-bay mast ({len(mast.conn)} beams), {runs} runs, {iters // runs} iterations and "
        f"{facts // runs} factorisations each; per Newton iteration, ms (load {os.getloadavg()[0]:.1f}):"
    )
    print(f"  {'':58} {'wall':>8} {'CPU':>8} {'calls/it':>8}")
    print(f"  {'whole run (analysis.run)':<58} {total * ms:8.3f} {cpu * ms:8.3f}")
    print(f"  {'  increments only (no per-run set-up, close)':<58} {increments * ms:8.3f}")
    print(f"  {'  inside the linear solver (factorise + solve)':<58} {superlu * ms:8.3f}")
    order = [label for _, _, label in PARTS]
    for label in sorted(acc, key=order.index):
        w, c, n = acc[label]
        print(f"  {label:<58} {w * ms:8.3f} {c * ms:8.3f} {n / iters:8.2f}")
    print(
        f"  iteration / linear solver: {total / superlu:.2f} (whole run), {increments / superlu:.2f} (increments only)"
    )
    linear = [
        label
        for label in (
            "factorisation (from the solver's matrix)",
            "factorisation (CSR path)",
            "solve (incl. refinement)",
        )
        if label in acc
    ]
    if linear:  # the figure in CPU time (contention disturbs it less): the timed parts' own CPU
        lin_cpu = sum(acc[label][1] for label in linear)
        print(f"  iteration / linear solver, CPU: {cpu / lin_cpu:.2f} (whole run)")
        return {
            "bays": n_bays,
            "whole": cpu * ms,
            "superlu": lin_cpu * ms,
            "cpu": True,
            "parts": {k: v[1] * ms for k, v in acc.items()},
        }
    return {
        "bays": n_bays,
        "whole": total * ms,
        "superlu": superlu * ms,
        "parts": {k: v[0] * ms for k, v in acc.items()},
    }


def plot(results, path):
    """One bar per size: each part of an iteration in units of the linear solver's time of the same runs."""
    import matplotlib

    matplotlib.use("Agg")
    from femast.post import plotstyle  # noqa: E402  (the one femast figure style)

    plotstyle.use()
    import matplotlib.pyplot as plt

    shown = [
        "element evaluation (all families + finiteness)",
        "beam kernel (element forces + tangents)",
        "tangent assembly into the solver's matrix",
        "tangent assembly into CSR",
        "residual assembly (internal forces - loads)",
        "residual assembly",
        "convergence test",
        "configuration update",
        "commit (per increment)",
        "results frame (per increment)",
        "results frame (gather + hand-over)",
    ]
    fig, ax = plt.subplots(figsize=(9, 1.2 + 0.9 * len(results)))
    for y, r in enumerate(results):
        left = 1.0
        ax.barh(y, 1.0, color="0.75", edgecolor="k", label="linear solver (factorise + solve)" if y == 0 else None)
        for i, name in enumerate(shown):
            w = r["parts"].get(name, 0.0) / r["superlu"]
            if w > 0:
                ax.barh(y, w, left=left, color=f"C{i}", label=name if y == 0 else None)
                left += w
        rest = r["whole"] / r["superlu"] - left
        ax.barh(
            y,
            max(rest, 0.0),
            left=left,
            color="w",
            edgecolor="k",
            hatch="//",
            label="the rest (Python between the parts)" if y == 0 else None,
        )
        ax.text(r["whole"] / r["superlu"] + 0.02, y, f"{r['whole'] / r['superlu']:.2f}", va="center")
    ax.axvline(1.3, color="r", ls=":", label="target 1.3")
    ax.set(
        yticks=range(len(results)),
        yticklabels=[f"{r['bays']} bays" for r in results],
        xlabel=("CPU" if results[0].get("cpu") else "wall")
        + " time per Newton iteration / linear solver's in the same runs",
        title="where a Newton iteration goes (truss mast of beam-columns)",
    )
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
    if all(r["superlu"] == r["superlu"] for r in results):  # an old femast has no SuperLU timer (nan)
        out = os.path.join(HERE, "out", "iteration_breakdown.png")
        os.makedirs(os.path.dirname(out), exist_ok=True)
        plot(results, out)
        print(f"\nfigure {out}")


if __name__ == "__main__":
    sys.exit(main())
