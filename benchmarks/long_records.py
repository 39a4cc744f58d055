"""compare and diagnose on a long record (2 million rows by default): how long a user waits, how
often the progress moves, how many rows are used, and what the statistics lose by using them.

    python -m femast.benchmarks.long_records [--rows 2000000] [--max-rows 10000] [--workers N]
                                              [--reference-rows 100000] [--no-reference]

The record: a mast top (the ``mast-top`` experiment) cycled ``--rows / 12500`` times, as a logger at
a few hundred hertz writes it over hours of quasi-static cycling, with a hidden joint clearance of
0.15 mrad and 50 um of white noise on every displacement (the synthetic generator of
:mod:`femast.rigs.synthetic`), written as a CSV file.

Each run is the command a user types (``femast compare mast-top FILE --fit``, ``femast diagnose
mast-top FILE``) in a fresh process with plain-text progress (``FEMAST_PROGRESS=plain``: a line
every 5 s while something long runs).  Printed per command: wall and CPU time (the process and its
children), the rows used of the rows read, the longest time without a line on stderr (the user's
longest wait without news), and the result.

What the statistics lose: ``femast compare --effects joint_clearance --fit`` on the thinned record
and on ``--reference-rows`` rows (default 100 000, ten times more; ``--no-reference`` to skip it);
printed: the noise floor, the parameters and their standard errors against the truth, and the ratio
of the standard errors beside sqrt(ratio of the rows) (white noise); the rows of the whole record
would shrink them by sqrt(rows read / rows used) in all.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

NOISE_M = 5e-5  # m, white noise of every displacement channel
CLEARANCE_RAD = 1.5e-4  # rad, the hidden joint clearance (half play)
TRUTH = {"k_theta1": 2.7e5, "k_theta2": 2.3e5}  # N m/rad


def write_record(path: Path, rows: int, seed: int = 3) -> float:
    """The long mast-top record as CSV at ``path``; returns the seconds it took."""
    from femast.experiments import get_experiment, write_data
    from femast.rigs.synthetic import mast_top_data, mast_top_path

    t0 = time.perf_counter()
    route = mast_top_path(n=rows, kind="cycles", cycles=rows / 12_500, amplitude_N=150.0, moment_Nm=20.0, seed=seed)
    data, _ = mast_top_data(TRUTH, {"joint_clearance": {"c": CLEARANCE_RAD}}, path=route, noise_m=NOISE_M, seed=seed)
    write_data(path, data, get_experiment("mast-top"))
    return time.perf_counter() - t0


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_command(args: list, folder: Path) -> dict:
    """``femast ARGS --json`` in a fresh process: wall, CPU, longest silence on stderr, report."""
    env = dict(os.environ, FEMAST_PROGRESS="plain")
    cmd = [sys.executable, "-m", "femast.cli", *args, "--json"]
    c0, t0 = _children_cpu(), time.perf_counter()
    p = subprocess.Popen(cmd, cwd=folder, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    stamps, lines = [t0], []

    def read_stderr():
        for line in p.stderr:
            stamps.append(time.perf_counter())
            lines.append(line.rstrip())

    reader = threading.Thread(target=read_stderr, daemon=True)
    reader.start()
    out = p.stdout.read()
    p.wait()
    reader.join()
    wall, cpu = time.perf_counter() - t0, _children_cpu() - c0
    stamps.append(t0 + wall)
    if p.returncode != 0:
        raise SystemExit(f"femast {' '.join(args)} failed:\n" + "\n".join(lines[-20:]))
    return {
        "wall": wall,
        "cpu": cpu,
        "silence": float(np.max(np.diff(stamps))),
        "progress_lines": len(lines),
        "stderr": lines,
        "report": json.loads(out),
    }


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rows", type=int, default=2_000_000, help="rows of the generated record (default 2000000)")
    ap.add_argument("--max-rows", type=int, default=None, help="passed to compare and diagnose (default: theirs)")
    ap.add_argument("--workers", default=None, help="passed to diagnose --workers (default: its own choice)")
    ap.add_argument("--reference-rows", type=int, default=100_000, help="rows of the reference fit (default 100000)")
    ap.add_argument("--no-reference", action="store_true", help="skip the reference fit")
    ap.add_argument("--keep", type=Path, default=None, help="folder to keep the record and the outputs in")
    args = ap.parse_args(argv)
    folder = args.keep or Path(tempfile.mkdtemp(prefix="femast-long-records-"))
    folder.mkdir(parents=True, exist_ok=True)
    csv = folder / f"mast_top_{args.rows}_rows.csv"
    print(f"load average {' '.join(f'{v:.2f}' for v in os.getloadavg())} on {os.cpu_count()} CPUs")
    if not csv.is_file() or args.keep is None:
        s = write_record(csv, args.rows)
        print(f"record: {args.rows} rows of mast-top, {csv.stat().st_size / 1e6:.0f} MB, written in {s:.0f} s")
    limit = [] if args.max_rows is None else ["--max-rows", str(args.max_rows)]
    more = ["--max-rows", str(args.reference_rows)]
    clearance = ["--effects", "joint_clearance"]
    runs = {  # name: (command, its own output folder, options)
        "compare --fit": ("compare", "compare", ["--fit", *limit]),
        "diagnose": ("diagnose", "diagnose", [*limit, *([] if args.workers is None else ["--workers", args.workers])]),
    }
    if not args.no_reference:
        runs["compare clearance --fit"] = ("compare", "clearance", ["--fit", *clearance, *limit])
        runs[f"compare clearance --fit, {args.reference_rows} rows"] = (
            "compare",
            "clearance_more",
            ["--fit", *clearance, *more],
        )
    results = {}
    print(f"{'command':<36s} {'wall s':>7s} {'CPU s':>7s} {'rows used':>17s} {'longest silence s':>18s}")
    for name, (command, out, options) in runs.items():
        r = results[name] = run_command([command, "mast-top", str(csv), "--out", out, *options], folder)
        rep = r["report"]
        used = f"{rep['n_samples']}/{args.rows}"
        print(f"{name:<36s} {r['wall']:>7.1f} {r['cpu']:>7.1f} {used:>17s} {r['silence']:>18.1f}", flush=True)
    d = results["diagnose"]["report"]
    print(f"diagnose: {d['verdict']['conclusion']}")
    thinning = [line for line in results["diagnose"]["stderr"] if "uses one row in" in line]
    print(f"diagnose says: {thinning[0].split(': ', 1)[-1] if thinning else '(nothing about thinning)'}")
    if args.no_reference:
        return
    a = results["compare clearance --fit"]["report"]
    b = results[f"compare clearance --fit, {args.reference_rows} rows"]["report"]
    print(f"what the statistics lose: {a['n_samples']} rows against {b['n_samples']} (truth in brackets):")
    print(f"  noise floor: {a['noise_rms'] * 1e6:.2f} um against {b['noise_rms'] * 1e6:.2f} um [{NOISE_M * 1e6:g} um]")
    truth = {**TRUTH, "joint_clearance.c": CLEARANCE_RAD}
    expected = np.sqrt(b["n_samples"] / a["n_samples"])
    for key, pa in a["params"].items():
        pb = b["params"][key]
        print(
            f"  {key}: {pa['value']:.5g} +- {pa['stderr']:.2g} against {pb['value']:.5g} +- {pb['stderr']:.2g} "
            f"[{truth[key]:.5g}]; standard error x{pa['stderr'] / pb['stderr']:.2f} (white noise: x{expected:.2f})"
        )
    whole = np.sqrt(args.rows / a["n_samples"])
    print(f"  every row of the record would shrink the standard errors of the thinned fit by ~{whole:.0f}x")
    print(f"load average {' '.join(f'{v:.2f}' for v in os.getloadavg())} on {os.cpu_count()} CPUs")


if __name__ == "__main__":
    main()
