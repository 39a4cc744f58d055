"""CPU time of femast alone on the peer mast: for interleaved before/after runs.

    python benchmarks/peers/femast_cpu.py [--bays 40 400 1000] [--repeat 3] [--strict]

Solves the mast of ``mast.py`` (10 load increments, tolerance 1e-6, as in compare_opensees.py)
``--repeat`` times per size after a warm-up and prints the best and median CPU time of the process
(build + solve, and the solve alone), the Newton iterations and the factorisations.  To compare two
checkouts, alternate them: ``PYTHONPATH=<A> python .../femast_cpu.py``, then ``<B>``, then ``<A>``...
(each run in a fresh process), and give ``uptime``'s load with the figures.  ``--strict``: the strict
correction test alone (``Convergence(predicted=False)``), to compare the two rules in one checkout.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import femast_mast  # noqa: E402
from mast import build_mast  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bays", type=int, nargs="+", default=[40, 400, 1000])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--strict", action="store_true", help="the strict correction test only")
    args = ap.parse_args(argv)
    femast_mast.warm_up()
    print(f"load average {os.getloadavg()[0]:.1f}; CPU s of this process")
    for nb in args.bays:
        mast = build_mast(nb)
        tot, run = [], []
        for _ in range(args.repeat):
            c0 = time.process_time()
            r = femast_mast.solve(mast, 10, predicted=not args.strict)
            tot.append(time.process_time() - c0)
            run.append(r["cpu_analyze"])
        an = r["analysis"]
        print(
            f"{nb:5d} bays: build + solve best {min(tot):.3f} median {statistics.median(tot):.3f}; solve best "
            f"{min(run):.3f} median {statistics.median(run):.3f}; {r['iterations']} iterations, "
            f"{an.solver.factorizations} factorisations"
        )


if __name__ == "__main__":
    sys.exit(main())
