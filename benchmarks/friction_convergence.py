"""Convergence of the friction paths: the 40-bay ADAM mast's Table 1 (Stohlman & Pellegrino,
Sec. VII) against the number of increments per load step.

    python -m femast.benchmarks.friction_convergence [--cycles 1 3] [--seat seated|tied]
                                                     [--increments 1 2 4 8 16 32] [--bays 40]

For each number n of increments per step (fixed: ``initial_increment = max_increment = 1/n``;
the default settings, ``add_table1_steps`` as a user calls it, are n = TABLE1_INCREMENTS), runs the
pretensioned mast through the Table 1 load sequence and prints every Table 1 quantity (x, y in um;
theta_x, theta_y, theta_z in arcsec; every row) beside its Richardson-extrapolated value (first
order, from the two finest runs; the observed order is printed) and each run's error: percent of
the extrapolated value, or um / arcsec where the value is below 10 um / 10 arcsec (the goal: 1 %,
or 0.1 um / 0.1 arcsec; "!" marks a miss).  Ends with each run's count of misses.
"""

from __future__ import annotations

import argparse
import tempfile
import time

import numpy as np

import femast as fm
from femast.adam import BayParameters, build_mast
from femast.adam.post import tip_table
from femast.adam.steps import CONVERGENCE, TABLE1_INCREMENTS, add_initial_steps, add_table1_steps

COLUMNS = {"x": (0, "um"), "y": (1, "um"), "thx": (3, "asec"), "thy": (4, "asec"), "thz": (5, "asec")}
GOAL_REL, GOAL_ABS, SMALL = 0.01, 0.1, 10.0


def run(n_bays, seat, cycles, increments):
    """(labels, values (rows, 6: um, um, um, asec, asec, asec), summary, wall s) of one run."""
    am = build_mast(n_bays, BayParameters(seat=seat))
    add_initial_steps(am)
    add_table1_steps(am, cycles=cycles, increments=increments)
    with tempfile.TemporaryDirectory() as out:
        an = fm.Analysis(am.model, out, progress=False, convergence=CONVERGENCE)
        t0 = time.perf_counter()
        res = an.run()
        wall = time.perf_counter() - t0
        labels, values = tip_table(res, am)
    return labels, np.asarray(values), an.summary, wall


def error(v, ref):
    """(error shown, "%" or "abs", within the goal): the error in percent of |ref|, or absolute
    (um, arcsec) where |ref| is below 10; within the goal if either is (1 %, or 0.1 um / arcsec)."""
    ok = abs(v - ref) <= GOAL_ABS or abs(v - ref) <= GOAL_REL * abs(ref)
    if abs(ref) < SMALL:
        return abs(v - ref), "abs", ok
    return 100 * abs(v - ref) / abs(ref), "%", ok


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bays", type=int, default=40)
    ap.add_argument("--cycles", type=int, nargs="+", default=[1, 3])
    ap.add_argument("--seat", choices=("seated", "tied"), default="seated")
    ap.add_argument("--increments", type=int, nargs="+", default=[1, 2, 4, 8, 16, 32])
    args = ap.parse_args(argv)
    ns = sorted(set(args.increments))
    if len(ns) < 2:
        ap.error("--increments: give at least two numbers of increments per step (the extrapolation needs two)")
    for cycles in args.cycles:
        print(f"\n{args.bays}-bay ADAM mast, {args.seat} joints, Table 1 x {cycles}: tip relative to the deployed mast")
        runs = {}
        for n in ns:
            labels, vals, summary, wall = run(args.bays, args.seat, cycles, n)
            runs[n] = (vals, summary, wall)
            name = f"{n}/step" + (" (default)" if n == TABLE1_INCREMENTS else "")
            print(
                f"  {name:>8s}: {summary.increments} increments, {summary.iterations} iterations, "
                f"{summary.cutbacks} cutbacks, {wall:.1f} s",
                flush=True,
            )
        f1, f2 = ns[-2], ns[-1]
        ref = 2 * runs[f2][0] - runs[f1][0]  # Richardson, first order (h halves)
        head = "  ".join(f"{'n=' + str(n) + ('*' if n == TABLE1_INCREMENTS else ''):>9s}" for n in runs)
        print(f"\n  {'row':>6s} {'qty':>4s} {'extrap.':>11s}  {head}   (error: % of extrap., or um/asec below 10)")
        fails = dict.fromkeys(runs, 0)
        orders = []
        for i, lab in enumerate(labels):
            if i == 0:
                continue
            for q, (c, unit) in COLUMNS.items():
                r = ref[i, c]
                cells = []
                for n, (vals, _, _) in runs.items():
                    e, kind, ok = error(vals[i, c], r)
                    fails[n] += not ok
                    cells.append(f"{e:8.2f}{'%' if kind == '%' else unit[0]}{' ' if ok else '!'}")
                if len(ns) >= 3:
                    d1 = runs[ns[-3]][0][i, c] - runs[f1][0][i, c]
                    d2 = runs[f1][0][i, c] - runs[f2][0][i, c]
                    if abs(d2) > 1e-12 and d1 / d2 > 0:
                        orders.append(np.log2(d1 / d2))
                print(f"  {lab:>6s} {q:>4s} {r:11.4g}  {'  '.join(cells)}")
        print(
            f"\n  * the default ({TABLE1_INCREMENTS} increments per step); quantities outside the goal (1 %, or 0.1 um / 0.1 arcsec):"
        )
        for n in runs:
            print(f"    {'n=' + str(n):>8s}: {fails[n]} of {5 * (len(labels) - 1)}")
        if orders:
            print(f"  observed order (from n = {ns[-3]}, {f1}, {f2}): median {np.median(orders):.2f}")


if __name__ == "__main__":
    main()
