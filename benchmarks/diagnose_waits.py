"""How long a user waits for ``femast diagnose`` on the shipped examples, warm and on an empty
compile cache, against the targets: platform-pose < 30 s, tip-cycle < 20 s, bay-torsion < 5 s warm,
and the first run on an empty compile cache at most 2x the warm time.

    python -m femast.benchmarks.diagnose_waits [--cases bay-torsion tip-cycle platform-pose]
                                               [--repeat 2] [--no-cold] [--warm] [--workers N [N ...]]
                                               [--other CHECKOUT]

Each run is the command a user types, ``femast diagnose EXPERIMENT example``, in a fresh process
(imports, numba cache loads and worker start-up included) from an empty folder.  Warm: numba's
compile cache filled by a first run; cold: ``NUMBA_CACHE_DIR`` an empty folder (every kernel
compiled on the way; ``--warm``: the cache is known to be filled, no filling run).  No disk cache of
FE runs (``FEMAST_FE_CACHE`` unset).  ``--workers``: one or more settings of ``femast diagnose
--workers`` (``default``: none given, the command's own choice -- one worker process per CPU for
the FE experiments), each timed.  Printed per case and setting:
wall time (the best of ``--repeat`` runs), the CPU time of the process and its workers, the model
runs computed by all of them (``$FEMAST_FE_RUN_LOG``: the FE runs of bay-torsion and tip-cycle; 0
for a model that is not an FE run), the processes started (the most alive at once), the load average
when it ended (the machine may be shared: wall time grows with load, CPU time much less), the target
and the verdict, so that a faster run can be checked to conclude the same.

``--other CHECKOUT`` times the femast of another source tree (e.g. ``git worktree add /tmp/main
main``) in the same minutes: every run of this tree is followed by the same run of that one
(``PYTHONPATH``), and both are printed, A/B.
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

TARGETS = {"bay-torsion": 5.0, "tip-cycle": 20.0, "platform-pose": 30.0}


def _cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _descendants(pid: int) -> int:
    """Number of live processes below ``pid`` (from /proc; 0 where /proc is missing)."""
    try:
        children = {}
        for d in os.listdir("/proc"):
            if d.isdigit():
                try:
                    with open(f"/proc/{d}/stat") as fh:
                        ppid = int(fh.read().rsplit(")", 1)[1].split()[1])
                except (OSError, IndexError, ValueError):
                    continue
                children.setdefault(ppid, []).append(int(d))
    except OSError:
        return 0
    stack, n = [pid], 0
    while stack:
        for c in children.get(stack.pop(), ()):
            n += 1
            stack.append(c)
    return n


def run(case: str, env: dict, workers=None, tree=None) -> dict:
    """One ``femast diagnose CASE example --json`` in a fresh process and an empty folder (``tree``: the
    femast of that source tree, on ``PYTHONPATH``)."""
    cmd = [sys.executable, "-m", "femast.cli", "diagnose", case, "example", "--json", "--out", "out"]
    if workers is not None:
        cmd += ["--workers", str(workers)]
    with tempfile.TemporaryDirectory() as folder:
        env = dict(env, FEMAST_FE_RUN_LOG=os.path.join(folder, "runs.log"))
        if tree is not None:
            env["PYTHONPATH"] = os.path.abspath(tree)
        c0, t0 = _cpu(), time.perf_counter()
        p = subprocess.Popen(cmd, cwd=folder, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        most = [0]

        def watch():
            while p.poll() is None:
                most[0] = max(most[0], _descendants(p.pid))
                time.sleep(0.2)

        t = threading.Thread(target=watch, daemon=True)
        t.start()
        out, err = p.communicate()
        wall, cpu = time.perf_counter() - t0, _cpu() - c0
        t.join()
        try:
            with open(env["FEMAST_FE_RUN_LOG"]) as fh:
                runs = sum(1 for _ in fh)
        except OSError:
            runs = 0
    if p.returncode != 0:
        raise SystemExit(f"femast diagnose {case} example failed:\n{err[-2000:]}")
    report = json.loads(out)
    return {
        "wall": wall,
        "cpu": cpu,
        "runs": runs,
        "processes": most[0],
        "load": os.getloadavg()[0],
        "verdict": report["verdict"]["conclusion"],
    }


def _row(case: str, label: str, r: dict, target: str, judged: str) -> str:
    return (
        f"{case:<14s} {label:<15s} {r['wall']:>7.1f} {r['cpu']:>7.1f} {r['runs']:>5d} {r['processes']:>5d} "
        f"{r['load']:>5.1f} {target:>8s}  [{judged}]  {r['verdict']}"
    )


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", nargs="+", default=list(TARGETS), choices=list(TARGETS))
    ap.add_argument("--repeat", type=int, default=2, help="warm runs per case (the best is shown)")
    ap.add_argument("--no-cold", action="store_true", help="skip the runs on an empty compile cache")
    ap.add_argument(
        "--workers",
        nargs="+",
        default=["default"],
        help="settings of femast diagnose --workers to time: numbers, or 'default' (none given)",
    )
    ap.add_argument("--warm", action="store_true", help="numba's cache is filled already: no filling run")
    ap.add_argument("--other", default=None, metavar="CHECKOUT", help="also time this source tree, interleaved (A/B)")
    args = ap.parse_args(argv)
    env = {k: v for k, v in os.environ.items() if k not in ("FEMAST_FE_CACHE", "NUMBA_CACHE_DIR", "PYTHONPATH")}
    env["FEMAST_QUIET"] = "1"
    trees = [("this", None)] + ([("other", args.other)] if args.other else [])
    print(f"load average {' '.join(f'{v:.2f}' for v in os.getloadavg())} on {os.cpu_count()} CPUs")
    print(
        f"{'case':<14s} {'run':<15s} {'wall s':>7s} {'CPU s':>7s} {'runs':>5s} {'procs':>5s} {'load':>5s} {'target':>8s}  [judged]  verdict"
    )
    settings = [None if w == "default" else int(w) for w in args.workers]
    for case in args.cases:
        if not args.warm:
            for _, tree in trees:
                run(case, env, settings[0], tree)  # fills numba's cache (and the OS file cache)
        for workers in settings:
            label = "w=" + ("default" if workers is None else str(workers))
            warm = {name: [] for name, _ in trees}
            for _ in range(args.repeat):
                for name, tree in trees:  # interleaved: A, B, A, B
                    warm[name].append(run(case, env, workers, tree))
            best = {name: min(w, key=lambda r: r["wall"]) for name, w in warm.items()}
            for name, _ in trees:
                b = best[name]
                ok = "met" if b["wall"] < TARGETS[case] else "MISSED"
                print(_row(case, f"warm {label}" + (f" {name}" if args.other else ""), b, f"< {TARGETS[case]:g} s", ok))
            if not args.no_cold:
                for name, tree in trees:
                    with tempfile.TemporaryDirectory() as cache:
                        cold = run(case, dict(env, NUMBA_CACHE_DIR=cache), workers, tree)
                    ratio = cold["wall"] / best[name]["wall"]
                    judged = f"{ratio:.1f}x warm: {'met' if ratio <= 2.0 else 'MISSED'}"
                    print(_row(case, f"cold {label}" + (f" {name}" if args.other else ""), cold, "<= 2x", judged))
            sys.stdout.flush()
    print(f"load average {' '.join(f'{v:.2f}' for v in os.getloadavg())} on {os.cpu_count()} CPUs")


if __name__ == "__main__":
    main()
