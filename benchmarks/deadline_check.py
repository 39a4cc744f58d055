"""Cost of the wall-clock deadline check that every Newton iteration makes (femast/analysis/deadline.py,
``Study(timeout_s=)``): per call without a deadline and inside one, against the time of one Newton
iteration of a small model.

    python benchmarks/deadline_check.py [--calls 200000]
"""

import argparse
import time

import femast as fm
from femast.analysis.deadline import check, deadline


def per_call(n):
    t0 = time.process_time()
    for _ in range(n):
        check()
    return (time.process_time() - t0) / n


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--calls", type=int, default=200_000)
    args = ap.parse_args()
    without = min(per_call(args.calls) for _ in range(3))
    with deadline(3600.0):
        inside = min(per_call(args.calls) for _ in range(3))
    m = fm.Model("cantilever")
    a, b = m.node(0, 0, 0), m.node(1.0, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=2)
    m.fix(a)
    m.step("load", initial_increment=0.01, max_increment=0.01).load(b, fz=-100.0)
    an = fm.Analysis(m, None, progress=False, on_frame=lambda fr: None)
    an.run()  # warm
    an = fm.Analysis(m, None, progress=False, on_frame=lambda fr: None)
    t0 = time.process_time()
    an.run()
    iteration = (time.process_time() - t0) / an.summary.iterations
    print(f"deadline check, CPU per call: {1e6 * without:.2f} us without a deadline, {1e6 * inside:.2f} us inside one")
    print(
        f"one Newton iteration of a 2-beam cantilever: {1e6 * iteration:.0f} us CPU (the check: {inside / iteration:.1e} of it)"
    )


if __name__ == "__main__":
    main()
