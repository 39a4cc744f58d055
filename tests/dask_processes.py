"""A real dask cluster for tests of the ``--scheduler`` paths: a ``dask scheduler`` and a ``dask worker``
started as separate processes (not an in-process client), each in a session of its own, and ended by
their process groups (SIGKILL) when the block ends, however it ends.

Backstops for a test process that is itself killed (its ``finally`` never runs): the scheduler
shuts down after ``idle_s`` seconds without work, and the worker ``death_s`` seconds after it lost
its scheduler."""

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path


def _start(args, cwd, log):
    return subprocess.Popen(
        [sys.executable, "-m", "dask", *args],
        cwd=cwd,
        stdout=log,
        stderr=subprocess.STDOUT,
        start_new_session=True,  # its own process group: ended as a whole below
    )


def _group_members(pgid: int) -> list[int]:
    """The live processes (not zombies) of process group ``pgid``."""
    members = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue  # ended meanwhile
        fields = stat[stat.rindex(")") + 2 :].split()  # state, ppid, pgrp, ...
        if int(fields[2]) == pgid and fields[0] != "Z":
            members.append(int(entry.name))
    return members


def end_group(p: subprocess.Popen, timeout_s: float = 30.0) -> list[int]:
    """SIGKILL process ``p``'s whole group (it leads it), reap ``p``; returns the group's processes
    still alive ``timeout_s`` seconds later (none, unless something escaped)."""
    with contextlib.suppress(ProcessLookupError):
        os.killpg(p.pid, signal.SIGKILL)
    p.wait(timeout=timeout_s)
    deadline = time.monotonic() + timeout_s
    while (left := _group_members(p.pid)) and time.monotonic() < deadline:
        time.sleep(0.1)
    return left


@contextlib.contextmanager
def dask_cluster(folder: Path, idle_s: int = 600, death_s: int = 60):
    """Yields the address (tcp://127.0.0.1:PORT) of a scheduler with one single-threaded worker,
    both separate processes writing to ``folder/dask.log``.  At the end, every process they
    started is gone (asserted), whether the block passed or failed."""
    folder = Path(folder)
    info = folder / "scheduler.json"
    log_path = folder / "dask.log"
    procs = []
    with open(log_path, "wb") as log:
        try:
            scheduler = _start(
                [
                    "scheduler",
                    "--host",
                    "127.0.0.1",
                    "--port",
                    "0",
                    "--no-dashboard",
                    "--scheduler-file",
                    str(info),
                    "--idle-timeout",
                    f"{idle_s}s",
                ],
                folder,
                log,
            )
            procs.append(scheduler)
            deadline = time.monotonic() + 120.0
            while not (info.is_file() and info.stat().st_size > 0):
                assert scheduler.poll() is None, log_path.read_text()
                assert time.monotonic() < deadline, "no scheduler after 120 s:\n" + log_path.read_text()
                time.sleep(0.2)
            address = json.loads(info.read_text())["address"]
            worker_args = ["worker", address, "--nthreads", "1", "--nworkers", "1", "--no-nanny", "--no-dashboard"]
            procs.append(_start([*worker_args, "--death-timeout", f"{death_s}s"], folder, log))
            yield address
        finally:
            left = {p.pid: end_group(p) for p in reversed(procs)}
    assert not any(left.values()), f"dask processes left alive: {left}"
