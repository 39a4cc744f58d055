"""Throughput of femast.studies: runs per second per core for the 10- and
40-bay ADAM masts (benchmarks/study_adam.py: pretension + one Table 1 cycle), the speed-up from 1
to 2 local worker processes, the overhead per sample of the dask path against local processes,
and the 1000-sample 10-bay study against its target (under 10 minutes on 2 cores).

    python benchmarks/study_throughput.py            # measurements + the 1000-sample projection
    python benchmarks/study_throughput.py --full     # also runs the 1000-sample study (~2-10 min)

The machine is shared: every line reports the load average and the CPU time of the study
(this process and its workers), which contention disturbs less than wall time.  Throughput per
core = samples / CPU seconds.  Figure: benchmarks/out/study_throughput/throughput.png.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from study_adam import adam_study  # noqa: E402

import femast.studies as st  # noqa: E402
from femast.post import plotstyle  # noqa: E402

OUT = Path(__file__).resolve().parent / "out" / "study_throughput"
TARGET_S = 600.0  # the issue: 1000 samples of the 10-bay mast in 10 minutes on 2 cores


def load():
    return os.getloadavg()[0]


def timed(study, samples, **kw):
    """Run ``samples`` of ``study`` in a fresh folder; the RunSummary and the load before it."""
    folder = tempfile.mkdtemp(prefix="femast_study_")
    try:
        ld = load()
        s = st.run(study, folder, samples=samples, **kw)
        if s.failed:
            print(f"  note: {s.failed} failed samples: {s.failures[:3]}")
        return s, ld
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def per_sample(s):
    """Wall and CPU seconds per sample, the warm-up sample left out."""
    return (s.wall_time - s.warmup_time) / s.ran, (s.cpu_time - s.warmup_cpu) / s.ran


def trivial(x):
    return {"y": x}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true", help="also run the 1000-sample 10-bay study on 2 workers")
    ap.add_argument("--samples", type=int, default=16, help="samples per 10-bay measurement")
    args = ap.parse_args(argv)
    OUT.mkdir(parents=True, exist_ok=True)
    rows = {}

    # -- runs per second per core (serial, in this process, warmed up first)
    for bays, n in ((10, args.samples), (40, max(2, args.samples // 4))):
        s, ld = timed(adam_study(bays), n, workers=1)
        w, c = per_sample(s)
        rows[bays] = (w, c)
        print(
            f"{bays:>3} bays, 1 worker, {n} samples: {w:.2f} s wall / sample, {c:.2f} s CPU / sample -> "
            f"{1 / c:.2f} runs/s per core (CPU), {1 / w:.2f} runs/s wall (load {ld:.1f}; warm-up "
            f"{s.warmup_time:.1f} s not counted)",
            flush=True,
        )

    # -- speed-up 1 -> 2 local workers (10 bays), interleaved A B A B
    sp = {1: [], 2: []}
    for _rep in range(2):
        for w_ in (1, 2):
            s, ld = timed(adam_study(10), args.samples, workers=w_)
            sp[w_].append((s.wall_time - s.warmup_time, s.cpu_time - s.warmup_cpu, ld))
            print(
                f"  10 bays, {w_} worker(s), {args.samples} samples: {s.wall_time - s.warmup_time:.1f} s wall "
                f"(after warm-up), CPU {s.cpu_time - s.warmup_cpu:.1f} s, load {ld:.1f}",
                flush=True,
            )
    w1 = np.median([x[0] for x in sp[1]])
    w2 = np.median([x[0] for x in sp[2]])
    c1 = np.median([x[1] for x in sp[1]])
    c2 = np.median([x[1] for x in sp[2]])
    print(
        f"speed-up 1 -> 2 local workers: {w1 / w2:.2f} (median wall {w1:.1f} s vs {w2:.1f} s; "
        f"ideal 2 on an idle 2-core machine, load now {load():.1f}); CPU of the samples {c1:.1f} s vs {c2:.1f} s: "
        f"the work does not grow with the workers, so on 2 idle cores the speed-up is at most "
        f"2 x {c1:.1f} / {c2:.1f} = {2 * c1 / c2:.2f}",
        flush=True,
    )

    # -- dask overhead per sample vs local processes: a trivial sample (pure engine cost), then 10 bays
    trivial_study = st.Study(run=trivial, inputs=[st.Uniform("x", 0.0, 1.0)], outputs=["y"], name="trivial")
    n_triv = 400
    sl, ld1 = timed(trivial_study, n_triv, workers=2)
    ov = {"local": sl.wall_time / n_triv}
    dask_rows = None
    try:
        import distributed
    except ImportError:
        print("dask.distributed not installed: no dask measurement (pip install 'dask[distributed]')")
    else:
        with (
            distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl,
            distributed.Client(cl) as client,
        ):
            sd, ld2 = timed(trivial_study, n_triv, scheduler=client)
            ov["dask"] = sd.wall_time / n_triv
            print(
                f"engine cost per sample (trivial sample, {n_triv} samples, 2 workers): local processes "
                f"{ov['local'] * 1e3:.2f} ms, dask {ov['dask'] * 1e3:.2f} ms -> dask overhead "
                f"{(ov['dask'] - ov['local']) * 1e3:.2f} ms per sample (load {ld1:.1f} / {ld2:.1f})",
                flush=True,
            )
            sdm, ld3 = timed(adam_study(10), args.samples, scheduler=client)
        slm, ld4 = timed(adam_study(10), args.samples, workers=2)
        dask_rows = (sdm.wall_time - sdm.warmup_time, slm.wall_time - slm.warmup_time)
        print(
            f"10 bays, {args.samples} samples, 2 workers: dask {dask_rows[0]:.1f} s, local {dask_rows[1]:.1f} s "
            f"wall after warm-up ({(dask_rows[0] - dask_rows[1]) / args.samples * 1e3:+.0f} ms per sample; "
            f"load {ld3:.1f} / {ld4:.1f})",
            flush=True,
        )

    # -- the 1000-sample target
    c10 = rows[10][1]
    proj = 1000 * c10 / 2
    print(
        f"1000-sample 10-bay study on 2 idle cores (projected from {c10:.2f} s CPU / sample): {proj:.0f} s "
        f"({proj / 60:.1f} min; target < {TARGET_S / 60:.0f} min: {'met' if proj < TARGET_S else 'NOT met'})"
    )
    full = None
    if args.full:
        ld = load()
        s, _ = timed(adam_study(10), 1000, workers=2)
        full = s
        print(
            f"1000-sample 10-bay study, 2 local workers: wall {s.wall_time:.0f} s ({s.wall_time / 60:.1f} min), "
            f"CPU {s.cpu_time:.0f} s, {s.ok} ok, {s.failed} failed, load {ld:.1f} before / {load():.1f} after; "
            f"target < {TARGET_S / 60:.0f} min wall: {'met' if s.wall_time < TARGET_S else 'NOT met'} "
            f"(CPU / 2 = {s.cpu_time / 2:.0f} s)"
        )

    # -- figure
    plt = plotstyle.pyplot()
    fig, ax = plt.subplots(1, 3, figsize=(12, 3.6))
    b = list(rows)
    ax[0].bar([f"{k} bays" for k in b], [1 / rows[k][1] for k in b], color="C0", label="per CPU second")
    ax[0].bar([f"{k} bays" for k in b], [1 / rows[k][0] for k in b], color="C1", width=0.4, label="per wall second")
    ax[0].set_ylabel(plotstyle.axis_label("runs per second per core", "1/s"))
    for i, k in enumerate(b):
        ax[0].annotate(f"{1 / rows[k][1]:.2f}", (i, 1 / rows[k][1]), ha="center", va="bottom")
    ax[0].set_title("throughput, 1 worker")
    ax[0].legend()
    ax[1].bar([0, 1], [w1, w2], 0.4, color="C0", label="wall")
    ax[1].bar([0.4, 1.4], [c1, c2], 0.4, color="C2", label="CPU (all processes)")
    ax[1].set_xticks([0.2, 1.2], ["1 worker", "2 workers"])
    ax[1].set_ylabel(plotstyle.axis_label(f"time of {args.samples} samples", "s"))
    ax[1].set_title(f"10 bays: wall speed-up {w1 / w2:.2f} under load")
    ax[1].legend()
    if "dask" in ov:
        ax[2].bar(["local", "dask"], [ov["local"] * 1e3, ov["dask"] * 1e3], color=["C0", "C3"])
    else:
        ax[2].bar(["local"], [ov["local"] * 1e3], color=["C0"])
    ax[2].set_ylabel(plotstyle.axis_label("engine cost per trivial sample", "ms"))
    ax[2].set_title("dask vs local processes")
    fig.suptitle(f"femast.studies throughput (shared 2-core machine, load {load():.1f})")
    fig.tight_layout()
    png = plotstyle.save(fig, OUT / "throughput.png")
    print(f"figure: {png}")
    return full


if __name__ == "__main__":
    main()
