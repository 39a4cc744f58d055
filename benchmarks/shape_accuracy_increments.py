"""How the shape-accuracy study's load-cycle residuals depend on the increments per Table 1 step:
the nominal mast and scattered samples (the stated scatter), 1, 2, 4, 8, 16 increments per step.

    python -m femast.benchmarks.shape_accuracy_increments [--bays 10] [--samples 0 1 2] [--seat seated]

Sample 0 is the nominal mast; sample k >= 1 draws the stated scatter from numpy's
default_rng(k).  Prints the tip's response under M + F and the residual twist and lateral error
after one cycle, with each run's difference from the 16-increment run.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from femast.adam import BayParameters
from femast.adam.post import ARCSEC
from femast.adam.shape_study import n_uniforms, sample_scatter, tip_history

INCREMENTS = (1, 2, 4, 8, 16)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bays", type=int, default=10)
    ap.add_argument("--samples", type=int, nargs="+", default=[0, 1, 2], help="0: nominal; k: default_rng(k)")
    ap.add_argument("--seat", choices=("seated", "tied"), default="seated")
    args = ap.parse_args(argv)
    n, p = args.bays, BayParameters(seat=args.seat)
    for k in args.samples:
        rng = np.random.default_rng(k)
        values = None if k == 0 else sample_scatter({g: rng.random(m) for g, m in n_uniforms(n).items()}, n)
        rows = {}
        for inc in INCREMENTS:
            t = time.process_time()
            h = tip_history(n, values, cycles=1, params=p, increments=inc)
            u, th = h["u"], h["theta"]
            twist = (th[-1, 2] - th[0, 2]) * ARCSEC
            lateral = np.hypot(*(u[-1, :2] - u[0, :2])) * 1e6
            rows[inc] = (twist, lateral, h["iterations"], time.process_time() - t)
        ref_t, ref_l = rows[INCREMENTS[-1]][:2]
        print(f"{n} bays, {args.seat} joints, {'nominal mast' if k == 0 else f'sample {k}'}:")
        for inc, (tw, lat, its, cpu) in rows.items():
            print(
                f"  {inc:2d} increments/step: residual twist {tw:9.2f} arcsec ({100 * (tw / ref_t - 1):+.2f} %), "
                f"lateral {lat:8.2f} um ({100 * (lat / ref_l - 1):+.2f} %); {its} iterations, {cpu:.1f} s CPU"
            )


if __name__ == "__main__":
    main()
