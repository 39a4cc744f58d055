"""Model building: a Python call per element against one call from arrays.

    python benchmarks/model_building.py [--bays 40 200 400 1000] [--repeat 5] [--docs]

Builds the truss mast of ``benchmarks/peers/mast.py`` (4 (n + 1) nodes, 12 n beams) in femast two
ways, interleaved, --repeat times each: ``model.node`` / ``model.beam`` per node and element, and
``model.nodes(X)`` + one ``model.beams(pairs, sections, up=...)``.  Prints the best and median wall
time and the CPU time of each, the analysis set-up (``Analysis(model)``: element families, DOF
numbering, assembly pattern, ordering) of the array-built model, and checks that the two models
are the same element for element.  Target: the 1000-bay mast builds in under 0.1 s.
Writes ``benchmarks/out/model_building.png`` (``--docs``: docs/figures/performance_model_building.png).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "peers"))

from mast import E_AL, G_AL, SECTIONS, build_mast  # noqa: E402

import femast as fm  # noqa: E402
from femast.analysis import Analysis  # noqa: E402

HERE = Path(__file__).resolve().parent


def per_element(mast, secs):
    m = fm.Model("per element")
    labels = [m.node(*x) for x in mast.X]
    for e, (a, b) in enumerate(mast.conn):
        m.beam(labels[a], labels[b], secs[mast.kind[e]], up=tuple(mast.up[e]))
    return m


def from_arrays(mast, secs):
    m = fm.Model("arrays")
    labels = np.asarray(m.nodes(mast.X))
    m.beams(labels[mast.conn], [secs[k] for k in mast.kind], up=mast.up)
    return m


def timed(fn, *args):
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn(*args)
    return out, time.perf_counter() - t0, time.process_time() - c0


def same(a, b):
    if len(a.beams) != len(b.beams) or not np.array_equal(a.coordinates, b.coordinates):
        return False
    return all(
        p.label == q.label and p.nodes == q.nodes and p.section is q.section and np.array_equal(p.up, q.up)
        for p, q in zip(a.beams, b.beams)
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bays", type=int, nargs="+", default=[40, 200, 400, 1000])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--docs", action="store_true", help="copy the figure to docs/figures")
    args = ap.parse_args(argv)
    secs = {k: fm.Section(E=E_AL, G=G_AL, **v) for k, v in SECTIONS.items()}
    print(f"load average at start: {os.getloadavg()[0]:.2f} (2 cores shared; wall times are noisy, CPU times less so)")
    rows = []
    for nb in args.bays:
        mast = build_mast(nb)
        t = {"per element": [], "arrays": []}
        c = {"per element": [], "arrays": []}
        for _ in range(args.repeat):  # interleaved A/B
            a, ta, ca = timed(per_element, mast, secs)
            b, tb, cb = timed(from_arrays, mast, secs)
            t["per element"].append(ta)
            c["per element"].append(ca)
            t["arrays"].append(tb)
            c["arrays"].append(cb)
        b.step("load")
        _, t_an, c_an = timed(lambda: Analysis(b, None, progress=False, on_frame=lambda f: None))
        ok = same(a, b)
        rows.append((nb, min(t["per element"]), min(t["arrays"]), t_an))
        print(f"\n{nb} bays: {len(mast.X)} nodes, {len(mast.conn)} beams; models identical: {ok}")
        for k in t:
            print(
                f"  {k:12s}: best {min(t[k]):.4f} s, median {statistics.median(t[k]):.4f} s wall; "
                f"CPU best {min(c[k]):.4f} s"
            )
        print(
            f"  speed-up (best/best): {min(t['per element']) / min(t['arrays']):.0f}x; analysis set-up of the "
            f"array-built model: {t_an:.3f} s wall, {c_an:.3f} s CPU"
        )
        if nb == 1000:
            best = min(t["arrays"])
            print(
                f"  target: 1000-bay mast built in < 0.1 s: {best:.4f} s best, "
                f"{statistics.median(t['arrays']):.4f} s median -> {'MET' if best < 0.1 else 'NOT MET'}"
            )
    print(f"load average at end: {os.getloadavg()[0]:.2f}")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    nb, tp, ta, tan = (np.array(v, float) for v in zip(*rows))
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.loglog(nb, tp, "o-", label="model.node / model.beam per element")
    ax.loglog(nb, ta, "s-", label="model.nodes + model.beams (arrays)")
    ax.loglog(nb, tan, "^--", color="0.5", label="Analysis set-up (array-built model)")
    ax.axhline(0.1, color="C3", lw=0.8, ls=":", label="target at 1000 bays: 0.1 s")
    ax.set_xlabel("bays (12 beams per bay)")
    ax.set_ylabel(f"wall time, best of {args.repeat} (s)")
    ax.set_title("Building the truss mast of benchmarks/peers")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    out = HERE / "out"
    out.mkdir(exist_ok=True)
    fig.savefig(out / "model_building.png", dpi=120)
    print(f"figure: {out / 'model_building.png'}")
    if args.docs:
        shutil.copy(out / "model_building.png", HERE.parent / "docs" / "figures" / "performance_model_building.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
