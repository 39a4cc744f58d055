"""Speed of ``diagnose``: a 500-sample mast-top data set, every applicable effect as a candidate.

    python benchmarks/diagnose_speed.py [--workers N] [--repeat R]

Target (issue 7): under 30 s on 2 cores.  Prints the wall time of the diagnosis with N local
worker processes (default 2) and in one process, and of a fit with every effect switched on at
once, and with the default workers (serial when the refits are cheaper than starting
processes).  The bay-torsion diagnose time is reported once that experiment has its FE model.
"""

from __future__ import annotations

import argparse
import os
import time

from femast.effects import applicable_effects
from femast.experiments import diagnose, fit, get_experiment
from femast.experiments.synthetic import mast_top_data, mast_top_path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    exp = get_experiment("mast-top")
    data, _ = mast_top_data(effects={"joint_clearance": {"c": 1.5e-4}, "friction_hysteresis": {"M_f": 12.0}},
                            path=mast_top_path(n=500, kind="cycles", moment_Nm=150.0, seed=3), seed=3)
    cands = [e.name for e in applicable_effects(exp)]
    print(f"mast-top, {data.n} samples, {len(cands)} candidate effects: {', '.join(cands)}; "
          f"{os.cpu_count()} CPUs on this machine")
    diagnose(exp, data, workers=1)  # warm up (numba caches, imports)
    for workers in (args.workers, 1, None):
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            d = diagnose(exp, data, workers=workers)
            times.append(time.perf_counter() - t0)
        print(f"  diagnose, workers={workers}, {d.executor[:40]:>40s}: best of {args.repeat} {min(times):.2f} s (mean "
              f"{sum(times) / len(times):.2f} s) -> {d.verdict['conclusion'][:60]}...")
    t0 = time.perf_counter()
    r = fit(exp, data, cands)
    print(f"  fit with all {len(cands)} effects at once ({len(r.x)} parameters, {r.nfev} evaluations): "
          f"{time.perf_counter() - t0:.2f} s, {r.ratio:.2f}x noise")
    bay = get_experiment("bay-torsion")
    print(f"  bay-torsion diagnose: {'pending a model (not measured)' if bay.pending else 'see its benchmark'}")
    print("target: under 30 s on 2 cores")


if __name__ == "__main__":
    main()
