"""Newton variants: factorisations and wall time per increment.

    python benchmarks/newton_variants.py [--bays 40 400] [--png docs/figures/newton_variants.png]

Runs each model with every tangent update of :class:`femast.analysis.newton.Newton` --
"full" (Newton-Raphson), "modified" (a tangent per increment, again when convergence slows or
after ``refactor_every`` iterations), "quasi-newton" (the same with Broyden's update between
factorisations) and "auto" (the default) -- and records, for each converged increment, its Newton
iterations, its factorisations and its wall and CPU time.  Models:

* the corotational truss mast of benchmarks/peers (10 load increments);
* the ADAM bay with ball-joint friction and latches along the bay-torsion example path (history:
  "auto" runs full Newton there).

Prints per model and variant: increments, cutbacks, iterations, factorisations, wall and CPU
time of the run, and the largest difference of the final displacements from full Newton
(relative).  The machine's load is printed with the timings.  Writes a PNG with the
factorisations and the CPU time per increment of each variant.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks" / "peers"))

import femast.analysis as fa  # noqa: E402
from femast.analysis import Analysis  # noqa: E402
from femast.analysis.output import Observer  # noqa: E402

VARIANTS = ("full", "modified", "quasi-newton", "auto")


class PerIncrement(Observer):
    """Iterations, factorisations and wall time of each converged increment; cutbacks counted."""

    def __init__(self):
        self.rows = []
        self.cutbacks = 0
        self._t = None
        self._f = 0

    def started(self, analysis):
        self._t = (time.perf_counter(), time.process_time())
        self._f = analysis.solver.factorizations

    def cutback(self, analysis, *args):
        self.cutbacks += 1

    def converged(self, analysis, step, increment, attempt, iterations, *args):
        t = (time.perf_counter(), time.process_time())
        f = analysis.solver.factorizations
        t0 = self._t or t
        self.rows.append((iterations, f - self._f, t[0] - t0[0], t[1] - t0[1]))
        self._t, self._f = t, f


def run_mast(n_bays, tangent):
    import femast_mast
    from mast import build_mast

    m, _ = femast_mast.model(build_mast(n_bays), 10)
    obs = PerIncrement()
    an = Analysis(m, None, progress=False, on_frame=lambda f: None, tangent=tangent, observers=[obs])
    c0, t0 = time.process_time(), time.perf_counter()
    an.run()
    return dict(
        obs=obs,
        wall=time.perf_counter() - t0,
        cpu=time.process_time() - c0,
        u=an.x - an.X0,
        iterations=an.summary.iterations,
        factorizations=an.solver.factorizations,
        increments=an.summary.increments,
    )


def run_adam_bay(tangent):
    import femast.rigs.bay_torsion as bt
    from femast.experiments import get_experiment, read_data

    exp = get_experiment("bay-torsion")
    prep = bt._prepare(read_data(exp, ROOT / "femast" / "examples" / "bay_torsion_example.csv"), exp.options)
    drive = np.column_stack([prep["theta"], prep["ux"], prep["uy"]])[prep["rows"]]
    inputs = bt.bay_inputs({"latch_k": 1.08e5, "latch_mu": 0.065}, exp.options)
    obs = PerIncrement()
    kept = {}

    class Variant(Analysis):
        def __init__(self, model, out=None, **kw):
            kw["observers"] = list(kw.get("observers", ())) + [obs]
            super().__init__(model, out, tangent=tangent, **kw)
            kept["an"] = self

    fa.Analysis = Variant  # run_bay imports Analysis from femast.analysis when called
    try:
        c0, t0 = time.process_time(), time.perf_counter()
        out = bt.run_bay(inputs, drive)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    finally:
        fa.Analysis = Analysis
    an = kept["an"]
    return dict(
        obs=obs,
        wall=wall,
        cpu=cpu,
        u=np.asarray(out["Mz"], dtype=float),
        iterations=an.summary.iterations,
        factorizations=an.solver.factorizations,
        increments=an.summary.increments,
    )


def plot(all_runs, png):
    from femast.post import plotstyle

    plt = plotstyle.pyplot()
    models = list(all_runs)
    fig, axes = plt.subplots(2, len(models), figsize=(4.2 * len(models), 6.4), squeeze=False)
    for j, model in enumerate(models):
        for (v, r), style in zip(all_runs[model].items(), ("o-", "s--", "^-.", "x:")):
            rows = np.array(r["obs"].rows)
            if rows.size == 0:
                continue
            k = np.arange(1, len(rows) + 1)
            label = f"{v} ({r['factorizations']} fact., {r['iterations']} it., {r['cpu']:.2f} s CPU)"
            axes[0, j].plot(k, rows[:, 1], style, ms=3, label=label)
            axes[1, j].plot(k, rows[:, 3] * 1e3, style, ms=3, label=v)
        axes[0, j].set_title(model, fontsize=9)
        axes[0, j].legend(fontsize=7)
        axes[0, j].set_ylabel("factorisations per increment")
        axes[1, j].set_ylabel("CPU time per increment (ms)")
        axes[1, j].set_xlabel("increment")
        axes[1, j].set_yscale("log")
        for ax in axes[:, j]:
            ax.grid(True, alpha=0.3)
    fig.suptitle(
        f"Newton variants, 'auto' = full (load {os.getloadavg()[0]:.1f} on 2 shared cores: CPU time of this process)",
        fontsize=10,
    )
    plotstyle.save(fig, png)
    print(f"figure: {png}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bays", type=int, nargs="+", default=[40, 400])
    ap.add_argument("--no-adam", action="store_true")
    ap.add_argument("--png", default=str(ROOT / "docs" / "figures" / "newton_variants.png"))
    args = ap.parse_args(argv)
    import femast_mast

    femast_mast.warm_up()
    models = {f"mast {n} bays": (lambda v, n=n: run_mast(n, v)) for n in args.bays}
    if not args.no_adam:
        models["ADAM bay, friction + latches"] = run_adam_bay
    all_runs = {}
    for model, run in models.items():
        run("full")  # warm-up, discarded: the numba caches of the model's families load here
        runs = {v: run(v) for v in VARIANTS}
        all_runs[model] = runs
        ref = runs["full"]["u"]
        print(f"\n{model}   [load {os.getloadavg()[0]:.1f}]")
        print(
            f"  {'variant':13s} {'incs':>5s} {'cutbacks':>8s} {'iters':>6s} {'facts':>6s} {'wall s':>7s} {'cpu s':>6s} "
            f"{'diff vs full':>12s}"
        )
        for v, r in runs.items():
            d = np.abs(r["u"] - ref).max() / max(np.abs(ref).max(), 1e-300) if r["u"].shape == ref.shape else np.nan
            print(
                f"  {v:13s} {r['increments']:5d} {r['obs'].cutbacks:8d} {r['iterations']:6d} {r['factorizations']:6d} "
                f"{r['wall']:7.3f} {r['cpu']:6.3f} {d:12.1e}"
            )
    plot(all_runs, args.png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
