"""Speed of the prestressed modal analysis: the first 10 modes of the 40-bay ADAM mast
after its pretension step (target: under 1 s), and a 400-bay mast reported.

    python benchmarks/modal_speed.py [--bays 40 400] [--out benchmarks/out/modal_speed]

Prints, per mast: free DOFs, elements, the static state's time, and the modal analysis' wall
and process CPU time (median of 3 runs: its first run includes the mass kernels' JIT load from
numba's cache), with ``uptime``'s load (the machine is shared).  Writes the first mode shapes
of each mast as a figure.
"""

import argparse
import os
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import femast as fm
from femast.adam.build import build_mast
from femast.adam.mass import add_mass
from femast.adam.steps import CONVERGENCE, add_initial_steps
from femast.modal import modal_analysis


def run(n_bays, n_modes=10, repeats=3):
    am = add_mass(build_mast(n_bays))
    add_initial_steps(am)
    an = fm.Analysis(am.model, None, progress=n_bays > 100, on_frame=lambda d: None, convergence=CONVERGENCE)
    t = time.perf_counter()
    an.run()
    t_static = time.perf_counter() - t
    walls, cpus = [], []
    for _ in range(repeats):
        w, c = time.perf_counter(), time.process_time()
        modes = modal_analysis(an, n_modes, label=f"{n_bays}-bay mast after the pretension step")
        walls.append(time.perf_counter() - w)
        cpus.append(time.process_time() - c)
    n_el = sum(f.n_elements for f in an.families)
    n_struct = sum(f.n_elements for f in an.families if f.name in ("adam_batten", "adam_longeron", "adam_latch"))
    return am, modes, an.dofmap.n_free, n_el, n_struct, t_static, walls, cpus


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--bays", type=int, nargs="+", default=[40, 400])
    ap.add_argument("--out", default="benchmarks/out/modal_speed")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, len(args.bays), figsize=(5 * len(args.bays), 6), squeeze=False)
    for ax, nb in zip(axes[0], args.bays):
        am, modes, nf, n_el, n_struct, ts, walls, cpus = run(nb)
        load = os.getloadavg()
        print(
            f"{nb}-bay mast: {nf} free DOFs, {n_el} elements ({n_struct} beams and latch cables); static "
            f"pretension state {ts:.2f} s"
        )
        print(
            f"  10 modes: wall {np.median(walls):.3f} s (runs {', '.join(f'{w:.3f}' for w in walls)}), "
            f"CPU {np.median(cpus):.3f} s; load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}"
        )
        print("  f (Hz): " + ", ".join(f"{f:.3f}" for f in modes.frequencies))
        x = modes.x
        z = x[:, 2]
        scale = 0.1 * am.height / max(np.abs(modes.shapes[:, :, :3]).max(), 1e-300)
        for k in (0, 2, 3):
            if k < len(modes):
                d = modes.shapes[k, :, :3] * scale
                ax.plot(
                    x[:, 0] + d[:, 0] + x[:, 1] + d[:, 1],
                    z + d[:, 2],
                    ".",
                    ms=1.5,
                    label=f"mode {k + 1}: {modes.frequencies[k]:.2f} Hz",
                )
        ax.set_title(f"{nb}-bay ADAM mast, prestressed modes")
        ax.set_xlabel("x + y (m)")
        ax.set_ylabel("z (m)")
        ax.legend(fontsize=8, markerscale=6)
    fig.tight_layout()
    fig.savefig(out / "modal_speed.png", dpi=100)
    print(f"figure {out / 'modal_speed.png'}")


if __name__ == "__main__":
    main()
