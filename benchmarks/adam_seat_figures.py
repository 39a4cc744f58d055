"""The ADAM paper's own figures (Stohlman & Pellegrino) on tied against seated ball joints: the
single bay's idealised torsion (Fig. 16: peak resisting moment, twist at which the latches let go,
rotation at zero moment after the cycle) and the 40-bay mast's Table 1 (theta_z and x at every row).

    python -m femast.benchmarks.adam_seat_figures [--max-increment 0.0025] [--cycles 3] [--bays 40]

--max-increment: the bay's increments as a fraction of each torsion step (0.01 is the figure of
docs/adam_bay.md; 0.0025 its converged value); Table 1 runs one increment per step, as
docs/adam_mast.md's table.
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time

import numpy as np

import femast as fm
from femast.adam import BayParameters, build_bay, build_mast
from femast.adam.post import bay_curve, release_angles, tip_table
from femast.adam.steps import CONVERGENCE, add_idealised_torsion, add_initial_steps, add_table1_steps

SEATS = ("tied", "seated")


def bay_figures(seat: str, max_increment: float) -> str:
    t = time.process_time()
    am = build_bay(seat=seat)
    add_initial_steps(am, hold_control=("ux", "uy"))
    add_idealised_torsion(am, math.radians(3.5), max_increment=max_increment)
    with tempfile.TemporaryDirectory() as out:
        an = fm.Analysis(am.model, out, progress=False, convergence=CONVERGENCE)
        c = bay_curve(an.run(), am)
    i = int(np.argmin(c["M"]))
    free = ", ".join(f"{math.degrees(x):.3f}" for x in release_angles(c))
    return (
        f"  {seat:6s}: peak {c['M'][i]:.2f} N m at {math.degrees(c['theta'][i]):.3f} deg; latches free at {free} deg; "
        f"rotation at zero moment {math.degrees(c['theta'][-1]):.5f} deg "
        f"({an.summary.iterations} iterations, {time.process_time() - t:.0f} s CPU)"
    )


def table1(seat: str, n_bays: int, cycles: int):
    am = build_mast(n_bays, BayParameters(seat=seat))
    add_initial_steps(am)
    add_table1_steps(am, cycles=cycles, increments=1)  # one increment per step, as docs/adam_mast.md's table
    with tempfile.TemporaryDirectory() as out:
        an = fm.Analysis(am.model, out, progress=False, convergence=CONVERGENCE)
        labels, values = tip_table(an.run(), am)
    return labels, np.asarray(values)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max-increment", type=float, default=0.0025, help="bay torsion increments (fraction of a step)")
    ap.add_argument("--cycles", type=int, default=3, help="Table 1 cycles")
    ap.add_argument("--bays", type=int, default=40)
    args = ap.parse_args(argv)
    print(f"Single bay, idealised torsion to 3.5 deg and back (increments {args.max_increment:g} of a step):")
    for seat in SEATS:
        print(bay_figures(seat, args.max_increment), flush=True)
    print(
        f"{args.bays}-bay mast, Table 1 x {args.cycles} (x in um, theta_z in arcsec; the paper: 1740 and 3030 under M + F):"
    )
    runs = {seat: table1(seat, args.bays, args.cycles) for seat in SEATS}
    labels = runs[SEATS[0]][0]
    print("  row      " + "".join(f"{seat + ' x':>12s}{seat + ' theta_z':>16s}" for seat in SEATS))
    for k, lab in enumerate(labels):
        print(f"  {lab:8s} " + "".join(f"{runs[s][1][k, 0]:12.1f}{runs[s][1][k, 5]:16.1f}" for s in SEATS))


if __name__ == "__main__":
    main()
