"""Time to first result on a fresh install: the getting_started script and the main job
(``benchmarks/verification.py``) with an empty numba cache, then again with the cache written.

    python benchmarks/cold_start.py [--only getting_started|verification] [--warm]

femast is copied (without any ``__pycache__``) into a temporary folder that comes first on
``PYTHONPATH``, and ``NUMBA_CACHE_DIR`` is unset, so numba writes its cache beside that copy as it
would beside a fresh ``pip install``; the repository's own cache is neither read nor touched.  Each
case gets its own fresh copy.  Every run is a child process started from a temporary working
folder; its wall time and its CPU time (user + sys of the child and everything it waited for,
``resource.getrusage(RUSAGE_CHILDREN)``) are printed with the machine's load average, because
on a shared machine the wall time grows with the load while the CPU time hardly does.

numba compiles the kernels in the script's own process, in the foreground (its CPU time is the
child's).

Targets: getting_started < 8 s and the main job < 15 s, cold.
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGETS = {"getting_started": 8.0, "verification": 15.0}


def _fresh_copy(tmp: Path) -> Path:
    src = tmp / "src"
    shutil.copytree(
        ROOT / "femast", src / "femast", ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc", "*.pyc")
    )
    return src


def _getting_started_script(folder: Path) -> Path:
    text = (ROOT / "docs" / "getting_started.md").read_text()
    block = re.findall(r"```python\n(.*?)```", text, re.S)[0]
    script = folder / "getting_started.py"
    script.write_text(block)
    return script


def _run(cmd, env, cwd):
    """(wall s, cpu s, exit code, stderr tail) of one child process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, p.returncode, (p.stderr or "")[-2000:]


def measure(case: str, warm: bool) -> list[tuple]:
    tmp = Path(tempfile.mkdtemp(prefix=f"femast_cold_{case}_"))
    try:
        src = _fresh_copy(tmp)
        run = tmp / "run"
        run.mkdir()
        env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CACHE_DIR")}
        env["PYTHONPATH"] = str(src)
        env["MPLBACKEND"] = "Agg"
        if case == "getting_started":
            cmd = [sys.executable, str(_getting_started_script(run))]
        else:
            cmd = [sys.executable, str(ROOT / "benchmarks" / "verification.py"), "--out", str(run / "verification")]
        rows = []
        for label in ("cold", "warm")[: 2 if warm else 1]:
            load = os.getloadavg()[0]
            wall, cpu, rc, err = _run(cmd, env, run)
            if rc not in (0,):
                raise SystemExit(f"{case} ({label}) failed with exit code {rc}:\n{err}")
            rows.append((label, wall, cpu, load))
        n_index = sum(f.endswith(".nbi") for _, _, fs in os.walk(src) for f in fs)
        print(f"{case} (target < {TARGETS[case]:.0f} s cold; {n_index} numba index files written):")
        for label, wall, cpu, load in rows:
            print(f"  {label:4s}: wall {wall:5.1f} s, CPU {cpu:5.1f} s (load {load:.1f})")
        return rows
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", choices=sorted(TARGETS), default=None, help="run one case (default: both)")
    ap.add_argument("--warm", action="store_true", help="also run each case a second time, cache written")
    args = ap.parse_args(argv)
    print(
        f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.1f}; femast from {ROOT / 'femast'} "
        "(copied, empty cache)"
    )
    verdict = []
    for case in [args.only] if args.only else ["getting_started", "verification"]:
        (label, wall, cpu, load), *_ = measure(case, args.warm)
        verdict.append(
            f"{case}: cold {wall:.1f} s wall / {cpu:.1f} s CPU (load {load:.1f}), target < "
            f"{TARGETS[case]:.0f} s: "
            f"{'met' if wall < TARGETS[case] else ('met in CPU time' if cpu < TARGETS[case] else 'NOT MET')}"
        )
    print("\n".join(verdict))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
