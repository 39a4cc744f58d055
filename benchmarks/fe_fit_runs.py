"""How many FE runs (and how much time) the FE experiments' fits take.

    python benchmarks/fe_fit_runs.py [--cases bay-compare bay-diagnose tip-diagnose] [--workers N]
                                     [--save FILE.json] [--before FILE.json] [--other CHECKOUT --repeat K]

Each case runs in a fresh process (``femast ... --json`` through ``femast.cli.main``: imports, numba
cache loads and worker start-up included, no disk cache of FE runs) with ``$FEMAST_FE_RUN_LOG``
set, so that every FE run any process computes is counted (femast/experiments/fe_cache.py):

* ``bay-compare``: ``femast compare bay-torsion example --fit``;
* ``bay-diagnose``: ``femast diagnose bay-torsion example --workers W``;
* ``tip-diagnose``: ``femast diagnose tip-cycle example --workers W`` (the 40-bay mast of Stohlman & Pellegrino
  Table 1).

Printed per case: FE runs, the seconds spent in them (summed over the processes), wall time, CPU
time of the child and its workers (``resource.getrusage``; contention on the shared machine
stretches wall time, CPU time much less), the load average, the verdict and the fitted baseline
parameters with their standard errors.  ``--before`` prints the change against an earlier
``--save`` (``--other CHECKOUT``: against the same cases run alternately with the femast of another
checkout, e.g. ``git archive`` of an older commit unpacked in /tmp) and checks the targets:
bay-torsion diagnose under 5 s, tip-cycle diagnose under 60 s
(2 cores), same verdicts, parameters within their standard errors.  Writes
``benchmarks/out/fe_fit_runs.png`` (``--docs``: docs/figures/performance_fe_fits.png).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASES = {
    "bay-compare": ["compare", "bay-torsion", "example", "--fit"],
    "bay-diagnose": ["diagnose", "bay-torsion", "example"],
    "tip-diagnose": ["diagnose", "tip-cycle", "example"],
}
TARGET_S = {"bay-diagnose": 5.0, "tip-diagnose": 60.0}


def _cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_case(name: str, workers: int, tmp: Path, code: Path | None = None) -> dict:
    """One case in a fresh process; ``workers`` 0: the command's default; ``code``: run the femast of
    that checkout (PYTHONPATH) instead of this one."""
    args = list(CASES[name]) + ["--out", str(tmp / name), "--json", "--quiet"]
    if args[0] == "diagnose" and workers:
        args += ["--workers", str(workers)]
    log = tmp / f"{name}.log"
    log.unlink(missing_ok=True)
    env = {k: v for k, v in os.environ.items() if k != "FEMAST_FE_CACHE"}  # cold: no disk cache
    env["FEMAST_FE_RUN_LOG"] = str(log)
    env["PYTHONPATH"] = str(code or ROOT)
    cmd = [sys.executable, "-c", "import sys; from femast.cli import main; sys.exit(main(sys.argv[1:]))", *args]
    load0 = os.getloadavg()[0]
    c0, t0 = _cpu(), time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp, env=env)
    wall, cpu = time.perf_counter() - t0, _cpu() - c0
    if p.returncode != 0:
        raise SystemExit(f"femast {' '.join(args)} failed:\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    rep = json.loads(p.stdout)
    lines = log.read_text().split("\n") if log.exists() else []
    runs = [ln.split() for ln in lines if ln.strip()]
    if args[0] == "diagnose":
        params = rep["baseline"]["params"]
        verdict = f"{rep['verdict']['kind']} {rep['verdict'].get('missing_effects')}"
    else:
        params = rep["params"]
        verdict = f"rms {rep['rms']:.4g} {rep['error_unit']}, {rep['ratio']:.3g} x noise"
    return {
        "case": name,
        "wall_s": wall,
        "cpu_s": cpu,
        "fe_runs": len(runs),
        "fe_seconds": sum(float(r[3]) for r in runs),
        "processes": len({r[0] for r in runs}),
        "load": [load0, os.getloadavg()[0]],
        "verdict": verdict,
        "params": params,
    }


def _param_text(params: dict) -> str:
    out = []
    for k, v in params.items():
        if isinstance(v, dict):
            e = v.get("stderr")
            out.append(f"{k} = {v['value']:.5g}" + (f" +- {e:.2g}" if e is not None else ""))
        else:
            out.append(f"{k} = {v}")
    return ", ".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    ap.add_argument("--workers", type=int, default=0, help="diagnose --workers (0: the command's default)")
    ap.add_argument(
        "--other",
        help="another femast checkout (e.g. `git worktree add /tmp/old COMMIT`): each case "
        "runs alternately there and here, --repeat times (interleaved A/B)",
    )
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--save", help="write the figures of this run to a JSON file")
    ap.add_argument("--before", help="a JSON file of an earlier --save to compare with")
    ap.add_argument("--docs", action="store_true")
    args = ap.parse_args(argv)
    before = json.loads(Path(args.before).read_text()) if args.before else {}
    results = {}
    with tempfile.TemporaryDirectory() as t:
        for name in args.cases:
            for k in range(args.repeat):
                if args.other:
                    o = run_case(name, args.workers, Path(t), Path(args.other))
                    print(
                        f"{name} [other {args.other}]: {o['fe_runs']} FE runs, wall {o['wall_s']:.1f} s, CPU "
                        f"{o['cpu_s']:.1f} s; load {o['load'][0]:.1f}; verdict {o['verdict']}; "
                        f"{_param_text(o['params'])}"
                    )
                    before.setdefault(name, o)
                r = run_case(name, args.workers, Path(t))
                if k + 1 < args.repeat:
                    print(
                        f"{name}: {r['fe_runs']} FE runs, wall {r['wall_s']:.1f} s, CPU {r['cpu_s']:.1f} s; load "
                        f"{r['load'][0]:.1f}"
                    )
            results[name] = r
            print(
                f"{name}: {r['fe_runs']} FE runs ({r['fe_seconds']:.1f} s in them, {r['processes']} processes), "
                f"wall {r['wall_s']:.1f} s, CPU {r['cpu_s']:.1f} s; load {r['load'][0]:.1f} -> {r['load'][1]:.1f}"
                f" (2 cores)\n  verdict: {r['verdict']}\n  baseline: {_param_text(r['params'])}"
            )
            b = before.get(name)
            if b:
                print(
                    f"  before: {b['fe_runs']} FE runs, wall {b['wall_s']:.1f} s, CPU {b['cpu_s']:.1f} s; "
                    f"verdict {b['verdict']}; {_param_text(b['params'])}"
                )
                same = b["verdict"] == r["verdict"] if name.endswith("diagnose") else True
                within = []
                for k, v in r["params"].items():
                    if isinstance(v, dict) and k in b["params"]:
                        e = max(v.get("stderr") or 0.0, b["params"][k].get("stderr") or 0.0)
                        within.append(abs(v["value"] - b["params"][k]["value"]) <= e)
                print(f"  same verdict: {same}; parameters within their standard errors: {all(within)}")
            if name in TARGET_S:
                print(
                    f"  target: under {TARGET_S[name]:.0f} s on 2 cores: wall {r['wall_s']:.1f} s, CPU "
                    f"{r['cpu_s']:.1f} s -> {'MET' if r['wall_s'] < TARGET_S[name] else 'NOT MET (wall)'}"
                )
    if args.save:
        Path(args.save).write_text(json.dumps(results, indent=2))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    names = list(results)
    fig, axes = plt.subplots(1, 3, figsize=(12.0, 3.8))
    x = np.arange(len(names))
    for ax, key, label in (
        (axes[0], "fe_runs", "FE runs"),
        (axes[1], "cpu_s", "CPU time, all processes (s)"),
        (axes[2], "wall_s", "wall time (s)"),
    ):
        if before:
            ax.bar(x - 0.2, [before.get(n, {}).get(key, np.nan) for n in names], 0.4, label="before", color="0.6")
        ax.bar(x + (0.2 if before else 0.0), [results[n][key] for n in names], 0.4, label="now", color="C0")
        ax.set_xticks(x, names)
        ax.set_ylabel(label)
        ax.grid(axis="y", alpha=0.3)
    for n, i in zip(names, x):
        if n in TARGET_S:
            axes[2].plot([i - 0.45, i + 0.45], [TARGET_S[n]] * 2, "C3--", lw=1)
    axes[0].legend()
    axes[1].set_yscale("log")
    axes[2].set_yscale("log")
    fig.suptitle(
        f"FE fits: runs, CPU and wall time (--workers {args.workers or 'default'}; wall target dashed; load "
        f"{os.getloadavg()[0]:.1f} on 2 cores)"
    )
    fig.tight_layout()
    out = ROOT / "benchmarks" / "out"
    out.mkdir(exist_ok=True)
    fig.savefig(out / "fe_fit_runs.png", dpi=120)
    print(f"figure: {out / 'fe_fit_runs.png'}")
    if args.docs:
        shutil.copy(out / "fe_fit_runs.png", ROOT / "docs" / "figures" / "performance_fe_fits.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
