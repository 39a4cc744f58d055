"""Time of the short FE runs behind compare, diagnose and the guyed-mast identification.

    python benchmarks/experiment_runs.py [--repeat 20]

Times, in this process with a warm numba cache:

* one bay-torsion FE run (``femast.rigs.bay_torsion.run_bay``: the ADAM bay driven along the
  49 rows of ``femast/examples/bay_torsion_example.csv``), as the experiment runs it (no files,
  ``Analysis(out=None)``) and with its frames written to a temporary results folder (what it did
  before), alternating;
* ``MastFE.run_wrenches`` of the guyed mast (pretension step + 3 top wrenches);
* one evaluation of each element family of the ADAM bay (the glue of a small constrained model).

It prints medians and the spread (min-max); both variants of the bay run must give the same
moments bit for bit (checked). Figures in docs/performance.md ("Fourth round").
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "femast" / "examples" / "bay_torsion_example.csv"


def _times(fn, repeat):
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t0)
    return np.array(ts), out


def _fmt(ts, unit=1.0, name="s"):
    return f"median {np.median(ts) * unit:.3g} {name} (min {ts.min() * unit:.3g}, max {ts.max() * unit:.3g})"


def bay_runs(repeat):
    import femast.analysis as fa
    import femast.rigs.bay_torsion as bt
    from femast.analysis import Analysis
    from femast.experiments import get_experiment, read_data

    exp = get_experiment("bay-torsion")
    prep = bt._prepare(read_data(exp, DATA), exp.options)
    drive = np.column_stack([prep["theta"], prep["ux"], prep["uy"]])[prep["rows"]]
    inputs = bt.bay_inputs({"latch_k": 1.08e5, "latch_mu": 0.065}, exp.options)

    class WithFiles(Analysis):  # the experiment as it was: every frame written to a temporary folder
        def __init__(self, model, out=None, **kw):
            self._tmp = tempfile.TemporaryDirectory(prefix="femast_bay_")  # removed with the analysis
            super().__init__(model, self._tmp.name, **kw)

    def run(files):
        fa.Analysis = WithFiles if files else Analysis  # run_bay imports it from femast.analysis when called
        try:
            return bt.run_bay(inputs, drive)
        finally:
            fa.Analysis = Analysis

    run(False), run(True)  # numba cache loads
    res = {False: [], True: []}
    outs = {}
    for _ in range(repeat):
        for files in (False, True):
            ts, outs[files] = _times(lambda: run(files), 1)
            res[files].append(ts[0])
    same = np.array_equal(outs[False]["Mz"], outs[True]["Mz"])
    o = outs[False]
    print(f"bay-torsion FE run ({len(drive)} rows, {o['increments']} increments, {o['iterations']} iterations):")
    print(f"  no files (out=None)        {_fmt(np.array(res[False]))}")
    print(f"  frames to a temp folder    {_fmt(np.array(res[True]))}")
    print(f"  same moments bit for bit: {same}")
    return same


def guyed(repeat):
    from femast.guyed.fe_mast import MastFE

    fe = MastFE(1200.0)
    fe.equilibrate()
    W = np.array([[10.0, 0, 0, 0, 0, 0], [20.0, 5.0, 0, 0, 0, 1.0], [0, 0, 0, 0, 0, 0]])  # N, N m
    fe.run_wrenches(W)
    ts, _ = _times(lambda: fe.run_wrenches(W), repeat)
    print(f"guyed mast run_wrenches (pretension + 3 wrenches): {_fmt(ts, 1e3, 'ms')}")


def families(repeat):
    from femast.adam import build_bay
    from femast.adam.parameters import BayParameters
    from femast.adam.steps import add_initial_steps
    from femast.analysis import Analysis
    from femast.elements.base import IncrementContext

    am = build_bay(BayParameters())
    add_initial_steps(am, hold_control=("ux", "uy", "rz"))
    an = Analysis(am.model, None, progress=False, on_frame=lambda fr: None)
    an.run()
    ctx = IncrementContext(x_committed=an.x.copy(), R_committed=an.R.copy())
    print("ADAM bay, one evaluation per element family (no output read):")
    for f, s in zip(an.families, an.states):
        f.evaluate(an.x, an.R, s, ctx)
        ts, _ = _times(lambda: f.evaluate(an.x, an.R, s, ctx), 100 * repeat)
        print(f"  {f.name:<20} {_fmt(ts, 1e6, 'us')}")
    c = an.constraints
    f_net = np.zeros(an.dofmap.n_active)
    ts, _ = _times(lambda: c.update_slaves(an.x, an.R, an.spin), 100 * repeat)
    print(f"  constraints: slave update {_fmt(ts, 1e6, 'us')}")
    ts, _ = _times(lambda: c.geometric_values(an.x, f_net), 100 * repeat)
    print(f"  constraints: geometric values {_fmt(ts, 1e6, 'us')}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=20)
    args = ap.parse_args(argv)
    same = bay_runs(args.repeat)
    guyed(args.repeat)
    families(args.repeat)
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
