"""Reference runs as the predictor of the bay-torsion FE runs.

    python benchmarks/fe_reference_runs.py [--repeat 7]

Runs the FE bay of the shipped bay-torsion example (latch_k 107 477 N/m, latch_mu 0.06837: the
fitted baseline) once as the reference (recording its converged increments,
:mod:`femast.analysis.reference`), then runs of nearby parameter sets -- a finite-difference step
of each fitted parameter (0.1 %), a fit step (3 % of latch_k), the latch_hysteresis effect
(F_h 8.2 N), a pretension change and joint friction -- with and without the reference, alternated.
Prints Newton iterations, CPU time (min and median of ``--repeat``), the largest difference of the
predicted moment with and without the reference and the moment change against the reference (what
a fit resolves).  Writes ``benchmarks/out/fe_reference_runs.png``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CASES = {
    "FD step latch_k": {"latch_k": 107477.0 * 1.001},
    "FD step latch_mu": {"latch_mu": 0.06837 + 5e-5},
    "fit step": {"latch_k": 1.03e5, "latch_mu": 0.065},
    "latch_hysteresis": {"hysteresis_force": 8.2},
    "pretension -5 N": {"pretension": 165.0},
    "joint friction 0.05": {"mu": 0.05},
}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args(argv)
    from femast import examples
    from femast.analysis.reference import ReferencePath
    from femast.experiments import get_experiment, read_data
    from femast.rigs import bay_torsion as bt

    exp = get_experiment("bay-torsion")
    data = read_data(exp, examples.for_experiment("bay-torsion"))
    opt = exp.options
    prep = bt._prepare(data, opt)
    rows = prep["rows"]
    drive = np.column_stack([prep["theta"][rows], prep["ux"][rows], prep["uy"][rows]])
    inp = bt.bay_inputs({"latch_k": 107477.0, "latch_mu": 0.06837}, opt)
    ref = ReferencePath()
    a = bt.run_bay(inp, drive, 1, 1, record_path=ref)
    bt.run_bay(inp, drive, 1, 1)  # warm
    rows_out = []
    print(
        f"reference: {a['increments']} increments, {a['iterations']} iterations; "
        f"{len(ref)} recorded increments ({ref.nbytes() / 1e3:.0f} kB)"
    )
    for name, change in CASES.items():
        i2 = {**inp, **change}
        cpu = {False: [], True: []}
        out = {}
        for _ in range(args.repeat):
            for use in (False, True):
                c = time.process_time()
                out[use] = bt.run_bay(i2, drive, 1, 1, reference=ref if use else None)
                cpu[use].append(time.process_time() - c)
        diff = float(np.abs(out[True]["Mz"] - out[False]["Mz"]).max())
        change_ = float(np.abs(out[False]["Mz"] - a["Mz"]).max())
        r = (
            name,
            out[False]["iterations"],
            out[True]["iterations"],
            min(cpu[False]),
            np.median(cpu[False]),
            min(cpu[True]),
            np.median(cpu[True]),
            diff,
            change_,
        )
        rows_out.append(r)
        print(
            f"{name:22s} iterations {r[1]:4d} -> {r[2]:4d}; CPU min {r[3]:.3f} -> {r[5]:.3f} s, median "
            f"{r[4]:.3f} -> {r[6]:.3f} s; |dMz| with/without reference {diff:.1e} N m (change against the "
            f"reference {change_:.2g} N m)"
        )

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11.5, 3.8))
    x = np.arange(len(rows_out))
    names = [r[0] for r in rows_out]
    axes[0].bar(x - 0.2, [r[1] for r in rows_out], 0.4, color="0.6", label="tangent predictor")
    axes[0].bar(x + 0.2, [r[2] for r in rows_out], 0.4, color="C0", label="reference run")
    axes[0].set_ylabel("Newton iterations per run (49 increments)")
    axes[1].bar(x - 0.2, [1e3 * r[3] for r in rows_out], 0.4, color="0.6", label="tangent predictor")
    axes[1].bar(x + 0.2, [1e3 * r[5] for r in rows_out], 0.4, color="C0", label="reference run")
    axes[1].set_ylabel(f"CPU per run, min of {args.repeat} (ms)")
    for ax in axes:
        ax.set_xticks(x, names, rotation=25, ha="right", fontsize=8)
        ax.grid(axis="y", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("bay-torsion FE runs started from a reference run's converged increments")
    fig.tight_layout()
    out = ROOT / "benchmarks" / "out"
    out.mkdir(exist_ok=True)
    fig.savefig(out / "fe_reference_runs.png", dpi=120)
    print(f"figure: {out / 'fe_reference_runs.png'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
