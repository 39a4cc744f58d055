"""Speed of ``diagnose`` (targets): a 500-sample mast-top data set with every applicable
effect as a candidate (every form of those that gain) and the pair stage, under 15 s on 2 cores;
the bay-torsion example diagnose under 20 s.

    python benchmarks/diagnose_speed.py [--workers N] [--repeat R] [--no-bay]

Each diagnosis runs in a fresh process (``femast diagnose`` through ``femast.cli.main``: imports,
numba cache loads and worker start-up included), wall time and the CPU time of the process and its
children (``resource.getrusage``; contention on a shared machine stretches wall time, CPU time much
less); the load average is printed beside. The mast-top data hide a clearance and a friction (the
pair stage runs); the bay-torsion data are ``femast/examples/bay_torsion_example.csv``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BAY = ROOT / "femast" / "examples" / "bay_torsion_example.csv"


def _load() -> str:
    return "load average " + " ".join(f"{v:.2f}" for v in os.getloadavg()) + f" on {os.cpu_count()} CPUs"


def _cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def timed(args) -> tuple:
    """(wall s, CPU s of the child and its workers, JSON report) of ``femast ARGS --json``."""
    cmd = [
        sys.executable,
        "-c",
        "import sys; from femast.cli import main; sys.exit(main(sys.argv[1:]))",
        *args,
        "--json",
    ]
    c0, t0 = _cpu(), time.perf_counter()
    env = {k: v for k, v in os.environ.items() if k != "FEMAST_FE_CACHE"}  # cold: no disk cache of FE runs
    p = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, env=env)
    wall, cpu = time.perf_counter() - t0, _cpu() - c0
    if p.returncode != 0:
        raise SystemExit(f"femast {' '.join(args)} failed:\n{p.stdout}\n{p.stderr}")
    return wall, cpu, json.loads(p.stdout)


def mast_top_file(folder: Path) -> Path:
    from femast.experiments import get_experiment, write_data
    from femast.rigs.synthetic import mast_top_data, mast_top_path

    exp = get_experiment("mast-top")
    data, _ = mast_top_data(
        effects={"joint_clearance": {"c": 1.5e-4}, "friction_hysteresis": {"M_f": 12.0}},
        path=mast_top_path(n=500, kind="cycles", amplitude_N=150.0, seed=3),
        seed=3,
    )
    f = folder / "mast_top_500.csv"
    write_data(f, data, exp)
    return f


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--no-bay", action="store_true", help="skip the bay-torsion diagnose")
    args = ap.parse_args(argv)
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        f = mast_top_file(Path(tmp))
        print(f"mast-top, 500 samples, every effect and the pair stage, --workers {args.workers}; {_load()}")
        runs = []
        for _ in range(args.repeat):
            wall, cpu, rep = timed(
                ["diagnose", "mast-top", str(f), "--out", str(Path(tmp) / "mt"), "--workers", str(args.workers)]
            )
            fits = sum(len(e.get("forms", [])) for e in rep["ranking"]) + len(rep["pairs"]) + len(rep["form_check"])
            runs.append((wall, cpu))
            print(
                f"  wall {wall:.2f} s, CPU {cpu:.2f} s ({fits} refits, {len(rep['pairs'])} pairs; "
                f"{rep['executor']}) -> {rep['verdict']['kind']} {rep['verdict']['missing_effects']}; {_load()}"
            )
        out["mast_top"] = {"wall_s": min(w for w, _ in runs), "cpu_s": min(c for _, c in runs)}
        print(
            f"  best: wall {out['mast_top']['wall_s']:.2f} s, CPU {out['mast_top']['cpu_s']:.2f} s "
            "(target: under 15 s on 2 cores)"
        )
        if not args.no_bay:
            print(f"bay-torsion example ({BAY.name}), --workers {args.workers}; {_load()}")
            wall, cpu, rep = timed(
                ["diagnose", "bay-torsion", str(BAY), "--out", str(Path(tmp) / "bay"), "--workers", str(args.workers)]
            )
            out["bay_torsion"] = {"wall_s": wall, "cpu_s": cpu}
            print(
                f"  wall {wall:.2f} s, CPU {cpu:.2f} s ({len(rep['ranking'])} candidates, {len(rep['pairs'])} "
                f"pairs; {rep['executor']}) -> {rep['verdict']['kind']} {rep['verdict']['missing_effects']}; "
                f"{_load()} (target: under 20 s)"
            )
    return out


if __name__ == "__main__":
    main()
