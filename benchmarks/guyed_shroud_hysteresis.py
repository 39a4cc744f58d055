"""The Rocaspect mast with the shrouds' loading/unloading law: a hysteresis loop of the mast top.

    python -m femast.benchmarks.guyed_shroud_hysteresis [--eta 0.05 0.1] [--force 400] [--out DIR] [--docs]

The Rocaspect paper (Sec. IV-A, Fig. 4a) finds "a significant difference between loading and
unloading the shroud" and fits its polynomial to the average.  ``MastFE(shroud_hysteresis=eta)``
puts that difference in the FE shroud (``femast.elements.shroud_hysteresis``: a friction tension in
parallel with the rope law, at most eta times the law's tension).  Mast 1 with 1200 N of shroud
pretension takes a horizontal top force cycled 0 -> +F -> -F -> +F (N) in small steps.  Prints, per
eta, the top's x under +F and -F, the residual x and the shroud tensions after unloading from +F
(the pretension the loop costs); draws DIR/guyed_shroud_hysteresis.png.
"""

from __future__ import annotations

import argparse
import shutil
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from femast.guyed.fe_mast import MastFE

ROOT = Path(__file__).resolve().parents[1]


def force_path(F: float, n: int = 12) -> np.ndarray:
    up = np.linspace(0.0, F, n + 1)[1:]
    down = np.linspace(F, -F, 2 * n + 1)[1:]
    back = np.linspace(-F, F, 2 * n + 1)[1:]
    return np.r_[up, down, back]


def run(eta: float, F: float):
    mf = MastFE(1200.0, shroud_hysteresis=eta)
    mf.equilibrate()
    fx = force_path(F)
    W = np.zeros((len(fx), 6))
    W[:, 0] = fx
    r = mf.run_wrenches(W)
    x = (r["u"][:, 0] - r["u0"][0]) * 1e3
    return fx, x, r


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--eta", type=float, nargs="+", default=[0.05, 0.1])
    ap.add_argument("--force", type=float, default=400.0, help="top force amplitude, N")
    ap.add_argument("--out", default="results/guyed_shroud_hysteresis")
    ap.add_argument("--docs", action="store_true", help="copy the figure to docs/figures/")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    F = args.force
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    print(f"Rocaspect mast 1, shrouds pretensioned to 1200 N, top force fx cycled 0 -> {F:g} -> {-F:g} -> {F:g} N")
    print(f"{'eta':>6} {'x(+F) mm':>10} {'x(-F) mm':>10} {'x(0, unloaded from +F) mm':>26} {'tensions there (N)':>28}")
    for eta in [0.0] + list(args.eta):
        t0 = time.perf_counter()
        fx, x, r = run(eta, F)
        n = len(fx) // 5
        i_plus, i_zero, i_minus = n - 1, 2 * n - 1, 3 * n - 1
        print(
            f"{eta:6.3g} {x[i_plus]:10.4f} {x[i_minus]:10.4f} {x[i_zero]:26.4f} "
            f"{np.array2string(r['tension'][i_zero], precision=1):>28}   ({time.perf_counter() - t0:.1f} s)"
        )
        ax.plot(x, fx, "-" if eta else "k--", label=f"eta = {eta:g}" if eta else "eta = 0 (the paper's law)")
    ax.set_xlabel("mast top x displacement (mm)")
    ax.set_ylabel("top force fx (N)")
    ax.set_title("Rocaspect mast 1: shroud loading/unloading in the FE")
    ax.axhline(0.0, color="0.8", lw=0.8)
    ax.axvline(0.0, color="0.8", lw=0.8)
    ax.legend()
    fig.tight_layout()
    png = out / "guyed_shroud_hysteresis.png"
    fig.savefig(png, dpi=110)
    print(f"figure: {png}")
    if args.docs:
        shutil.copy(png, ROOT / "docs" / "figures" / "guyed_shroud_hysteresis.png")


if __name__ == "__main__":
    main()
