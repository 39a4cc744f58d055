"""What femast's worker processes cost, and how fast they end after a kill -9 of their parent.

    python benchmarks/workers.py [--workers 2] [--tasks 200]

Prints: the time from ``Pool(n)`` to the first answer of every worker (a fresh interpreter that
imports femast), the cost per task of a task that does nothing (pickling, the pipe, the manager
thread), the time to replace a worker killed at a task's time-out, and the time from a SIGKILL of
a parent whose workers are inside a compiled loop to the last of its processes gone (Linux).
Wall and CPU time with the load average: on a shared machine the wall time grows with the load.
"""

from __future__ import annotations

import argparse
import os
import resource
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

from femast import workers
from femast.errors import TaskTimeout


def _nothing(x):
    return x


def _pid(_):
    time.sleep(0.2)  # (long enough for every worker to take one)
    return os.getpid()


def _sleep(s):
    time.sleep(s)


def _cpu():
    a, b = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return a.ru_utime + a.ru_stime + b.ru_utime + b.ru_stime


PARENT = textwrap.dedent(
    """
    import os, time
    import numba
    from femast import workers

    @numba.njit(cache=False)
    def spin(n):
        s = 0.0
        for i in range(n):
            s += (i % 7) * 1e-12
            if s < -1.0:
                break
        return s

    def stuck(mark):
        spin(10)
        open(mark, "w").close()
        return spin(10**18)

    if __name__ == "__main__":
        n = int(os.environ["N_WORKERS"])
        pool = workers.Pool(n)
        futures = [pool.submit(stuck, f"inside-{i}") for i in range(n)]
        time.sleep(3600)
    """
)


def _session(sid):
    out = []
    for name in os.listdir("/proc"):
        if name.isdigit():
            try:
                stat = Path(f"/proc/{name}/stat").read_text()
            except OSError:
                continue
            fields = stat[stat.rindex(")") + 2 :].split()
            if int(fields[3]) == sid and fields[0] not in ("Z", "X"):
                out.append(int(name))
    return out


def kill_to_gone(n: int) -> float:
    """s from the SIGKILL of a parent (its ``n`` workers inside a compiled loop) to no process left."""
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "parent.py").write_text(PARENT)
        p = subprocess.Popen(
            [sys.executable, "parent.py"], cwd=tmp, start_new_session=True, env={**os.environ, "N_WORKERS": str(n)}
        )
        while not all((Path(tmp) / f"inside-{i}").exists() for i in range(n)):
            time.sleep(0.05)
        t0 = time.perf_counter()
        os.kill(p.pid, signal.SIGKILL)
        p.wait()
        while _session(p.pid):
            time.sleep(0.01)
        return time.perf_counter() - t0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--tasks", type=int, default=200)
    args = ap.parse_args(argv)
    n = args.workers
    print(f"{workers.cpu_count()} CPUs, load average {os.getloadavg()[0]:.1f}; {n} workers ({workers.start_method()})")
    t0, c0 = time.perf_counter(), _cpu()
    with workers.Pool(n, timeout_s=1.0) as pool:
        pids = set(pool.map(_pid, range(2 * n)))
        t_start = time.perf_counter() - t0
        print(f"  start: {t_start:.2f} s wall to the first answer of {len(pids)} workers")
        t1 = time.perf_counter()
        list(pool.map(_nothing, range(args.tasks)))
        per = (time.perf_counter() - t1) / args.tasks
        print(f"  a task that does nothing: {1e3 * per:.2f} ms wall each ({args.tasks} tasks)")
        t2 = time.perf_counter()
        try:
            pool.submit(_sleep, 60.0).result()
        except TaskTimeout:
            pass
        pool.submit(_nothing, 0).result()
        pool.submit(_nothing, 0).result()
        print(
            f"  a task killed at its 1 s time-out, until the pool answers again: {time.perf_counter() - t2:.2f} s wall"
        )
    print(f"  pool of {n}: {time.perf_counter() - t0:.2f} s wall, {_cpu() - c0:.2f} s CPU (this process + workers)")
    if sys.platform.startswith("linux"):
        gone = [kill_to_gone(n) for _ in range(3)]
        print(
            f"  kill -9 of the parent (workers inside a compiled loop) to no process left: "
            f"{', '.join(f'{g:.2f}' for g in gone)} s"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
