"""What one FE run of the ADAM experiments costs, and what their first run compiles.

    python -m femast.benchmarks.fe_run_cost [--runs 5] [--no-compile]

The run: ``tip-cycle``'s FE model on its shipped example (the 40-bay mast on seated ball joints,
pretensioned, then one load step per row of Table 1), as every refit of ``femast diagnose
tip-cycle example`` runs it, in this process after a first run: CPU time of the whole run (model
building, analysis set-up, Newton), best and median of ``--runs``, with its increments, Newton
iterations and factorisations, and the CPU of its set-up.

The compile: a fresh process with an empty numba cache (``NUMBA_CACHE_DIR`` a new folder) runs
one ``bay-torsion`` model run (one ADAM bay) and then one ``tip-cycle`` run; numba's compile
events give the CPU time spent compiling each kernel (the outermost ones, their helpers included)
and the total, beside the CPU of the two runs.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time


def _tip_cycle():
    """(inputs, loads) of the tip-cycle example's FE run at the default parameters."""
    import femast.examples
    from femast.experiments.core import prepared
    from femast.experiments.data import read_data
    from femast.experiments.registry import get_experiment
    from femast.rigs import tip_cycle

    exp = get_experiment("tip-cycle")
    options = dict(exp.options)
    data = read_data(exp, femast.examples.path("tip_cycle_table1.csv"))
    prep = prepared(data, exp.prepare, options)
    return tip_cycle.mast_inputs({}, options), prep["loads"][prep["rows"]], options


def run_cost(runs: int) -> None:
    from femast.adam import build_mast
    from femast.adam.steps import CONVERGENCE, add_initial_steps
    from femast.analysis import Analysis
    from femast.rigs.bay_torsion import bay_parameters
    from femast.rigs.tip_cycle import run_mast

    inputs, loads, options = _tip_cycle()
    run_mast(inputs, loads, options["n_bays"])  # kernels loaded or compiled
    cpu, setup = [], []
    for _ in range(runs):
        t0 = time.process_time()
        out = run_mast(inputs, loads, options["n_bays"])
        cpu.append(time.process_time() - t0)
        t0 = time.process_time()
        am = build_mast(options["n_bays"], bay_parameters(inputs))
        add_initial_steps(am)
        an = Analysis(am.model, None, progress=False, convergence=CONVERGENCE, on_frame=lambda frame: None)
        setup.append(time.process_time() - t0)
    cpu.sort()
    setup.sort()
    dofs = an.system.n_free
    print(f"tip-cycle FE run (40-bay ADAM mast, seated ball joints, {len(loads)} rows, {dofs} free DOFs):")
    print(
        f"  CPU {cpu[0]:.2f} s best, {cpu[len(cpu) // 2]:.2f} s median of {runs}; {out['increments']} increments, "
        f"{out['iterations']} Newton iterations; set-up (model + analysis) {setup[0]:.2f} s of it"
    )


_COMPILE_CHILD = """
import sys, time
from collections import defaultdict
from numba.core import event
t_compile = defaultdict(float)
stack = []
class Timer(event.Listener):
    def on_start(self, e):
        stack.append(time.process_time())
    def on_end(self, e):
        t0 = stack.pop()
        if not stack:
            f = e.data["dispatcher"].py_func
            t_compile[f.__module__ + "." + f.__qualname__] += time.process_time() - t0
event.register("numba:compile", Timer())
import femast.examples
from femast.experiments.data import read_data
from femast.experiments.registry import get_experiment
for name, csv in (("bay-torsion", "bay_torsion_example.csv"), ("tip-cycle", "tip_cycle_table1.csv")):
    exp = get_experiment(name)
    data = read_data(exp, femast.examples.path(csv))
    before = sum(t_compile.values())
    t0 = time.process_time()
    exp.model({}, data, None, dict(exp.options))
    dt = time.process_time() - t0
    spent = sum(t_compile.values()) - before
    print(f"first {name} model run: {dt:.1f} s CPU, {spent:.1f} s of it compiling")
print(f"compiling, in all: {sum(t_compile.values()):.1f} s CPU; the largest kernels:")
for k, v in sorted(t_compile.items(), key=lambda kv: -kv[1])[:8]:
    print(f"  {v:6.1f} s  {k}")
"""


def compile_cost() -> None:
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, FEMAST_QUIET="1")
        subprocess.run([sys.executable, "-c", _COMPILE_CHILD], env=env, check=True)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=5, help="timed tip-cycle runs (best and median printed)")
    ap.add_argument("--no-compile", action="store_true", help="skip the run on an empty compile cache")
    args = ap.parse_args(argv)
    print(f"load average {' '.join(f'{v:.2f}' for v in os.getloadavg())} on {os.cpu_count()} CPUs")
    run_cost(args.runs)
    if not args.no_compile:
        compile_cost()


if __name__ == "__main__":
    main()
