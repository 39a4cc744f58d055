"""A SIGKILL of ``femast compare`` or ``femast diagnose`` at any moment -- while it starts, while its
fits run, while its refits run on worker processes -- leaves no process behind: every process it
started (worker processes, anything they started) is gone within 30 s."""

import os
import signal
import subprocess
import sys
import time

import pytest
from process_tree import assert_session_ends, session_processes

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc to find the processes")


def _kill_after(tmp_path, args, seconds, workers_seen=0):
    """Start ``femast ARGS`` in its own session; SIGKILL it ``seconds`` after it started (or, with
    ``workers_seen``, that long after it first had that many processes besides itself); then no
    process of the session may be alive 30 s later.  Returns the most processes seen."""
    p = subprocess.Popen(
        [sys.executable, "-m", "femast.cli", *args, "--out", str(tmp_path / "out")],
        cwd=tmp_path,
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    most = 1
    try:
        start = time.monotonic()
        if workers_seen:
            while len(session_processes(p.pid)) < 1 + workers_seen:
                if p.poll() is not None or time.monotonic() - start > 600.0:
                    pytest.fail(f"femast {' '.join(args)} never had {workers_seen} worker processes")
                time.sleep(0.1)
            start = time.monotonic()
        while time.monotonic() - start < seconds:
            most = max(most, len(session_processes(p.pid)))
            time.sleep(0.1)
        if p.poll() is None:  # (a fast machine may have finished: then nothing may be left either)
            os.kill(p.pid, signal.SIGKILL)
        p.wait(timeout=30)
        assert_session_ends(p.pid, within_s=30.0)
    finally:
        for pid in session_processes(p.pid):
            os.kill(pid, signal.SIGKILL)  # (only when the test failed: what it started)
    return most


def test_diagnose_on_two_workers_killed_while_its_refits_run(tmp_path):
    most = _kill_after(tmp_path, ["diagnose", "bay-torsion", "example", "--workers", "2"], 2.0, workers_seen=2)
    assert most <= 1 + 2 + 2  # never more workers than asked (a resource tracker and such aside)


@pytest.mark.parametrize("seconds", [1.0, 4.0])
def test_compare_with_a_fit_killed_early_or_during_its_fit(tmp_path, seconds):
    _kill_after(tmp_path, ["compare", "tip-cycle", "example", "--fit"], seconds)


@pytest.mark.slow
@pytest.mark.parametrize("example", ["platform-pose", "mast-top", "tip-cycle"])
@pytest.mark.parametrize("seconds", [1.0, 5.0, 15.0])
def test_diagnose_killed_at_any_moment(tmp_path, example, seconds):
    _kill_after(tmp_path, ["diagnose", example, "example", "--workers", "2"], seconds)
