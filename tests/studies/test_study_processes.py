"""A study's worker processes: a sample stuck inside a compiled loop (which no signal interrupts)
is ended at the study's time-out and recorded as failed, serial or on two workers; a kill -9
of ``femast study --workers 2`` leaves no process behind; a kill (SIGTERM) of the shape-accuracy
benchmark on dask closes its cluster."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import numba
import numpy as np
import pytest
from process_tree import assert_session_ends, session_processes

import femast.studies as st

STUCK_AT = 0.8  # samples with x above this never return


@numba.njit(cache=False)
def _spin(n):
    s = 0.0
    for i in range(n):
        s += (i % 7) * 1e-12
        if s < -1.0:  # never: keeps the loop from being folded away
            break
    return s


def _stuck_in_compiled_code(x):
    n = 10**18 if x > STUCK_AT else 1000  # 1e18 iterations: centuries, with the GIL held
    return {"y": x + _spin(n)}


@pytest.mark.parametrize("workers", [1, 2])
def test_a_sample_stuck_in_compiled_code_ends_at_the_timeout(tmp_path, workers):
    study = st.Study(
        run=_stuck_in_compiled_code,
        inputs=[st.Uniform("x", 0.0, 1.0)],
        outputs=["y"],
        sampler="mc",
        seed=5,
        timeout_s=10.0,  # (generous: the ok samples take milliseconds, also on a loaded machine)
    )
    s = st.run(study, tmp_path / "s", samples=4, workers=workers)
    t = st.load(tmp_path / "s").table(["x", "y", "status"])
    stuck = t["x"] > STUCK_AT
    assert 0 < stuck.sum() < 4  # (seed 5: some samples of each kind)
    assert s.failed == stuck.sum() and s.ok == 4 - stuck.sum() and s.complete
    assert np.all(t["status"][stuck] == "failed") and np.all(t["status"][~stuck] == "ok")
    assert np.array_equal(t["y"][~stuck], t["x"][~stuck] + _spin(1000))  # the ok samples, as computed here
    reasons = [r for _, r in st.load(tmp_path / "s").failures()]
    assert all(r.startswith("SampleTimeout") and "timeout_s = 10 s" in r for r in reasons)


SLOW_STUDY = textwrap.dedent(
    """
    import time
    import femast.studies as st

    def slow(x):
        time.sleep(0.5)
        return {"y": x}

    study = st.Study(run=slow, inputs=[st.Uniform("x", 0.0, 1.0)], outputs=["y"], sampler="mc", seed=1)
    """
)


def _kill_once_running(p, running, what, within_s, settle_s, sig=signal.SIGKILL):
    """Signal ``sig`` (SIGKILL unless told) to process ``p`` (the leader of its own session)
    ``settle_s`` seconds after ``running()`` first holds (at most ``within_s`` seconds); then no process
    of its session may be alive 30 s later.  Whatever happens, the session's processes are killed at
    the end."""
    try:
        deadline = time.monotonic() + within_s
        while not running():
            assert p.poll() is None, f"it ended before {what} started"
            assert time.monotonic() < deadline, f"{what} did not start"
            time.sleep(0.2)
        time.sleep(settle_s)
        os.kill(p.pid, sig)
        p.wait(timeout=60)
        assert_session_ends(p.pid, within_s=30.0)
    finally:
        for pid in session_processes(p.pid):
            os.kill(pid, signal.SIGKILL)  # (only if the test failed: the processes it started)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc to find the processes")
def test_kill_9_of_a_study_on_two_workers_leaves_no_process(tmp_path):
    script = tmp_path / "slow_study.py"
    script.write_text(SLOW_STUDY)
    p = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "femast.cli",
            "study",
            str(script),
            "--samples",
            "400",
            "--workers",
            "2",
            "--out",
            str(tmp_path / "out"),
        ],
        cwd=tmp_path,
        start_new_session=True,  # its own session: every process it starts is found by the session id
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    # the study and its two workers; then 2 s while the workers run samples
    _kill_once_running(p, lambda: len(session_processes(p.pid)) >= 3, "the workers", 300.0, 2.0)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc to find the processes")
def test_kill_9_of_the_shape_accuracy_benchmark_on_a_local_dask_cluster_leaves_no_process(tmp_path):
    """``--dask`` runs the long mast on a dask LocalCluster the benchmark starts: its worker
    processes end with it (dask watches its parent through a pipe) when it is killed mid-study."""
    pytest.importorskip("distributed")
    args = ["--bays", "--plain-bays", "--big", "2", "--big-samples", "64", "--dask", "--workers", "1"]
    p = subprocess.Popen(
        [sys.executable, "-m", "femast.benchmarks.shape_accuracy", *args, "--out", str(tmp_path / "out")],
        cwd=tmp_path,
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    runs = tmp_path / "out" / "bays2_plain"
    # the benchmark and its dask worker, writing runs; then 3 s while the worker runs samples
    _kill_once_running(p, lambda: len(session_processes(p.pid)) >= 2 and runs.is_dir(), "the dask worker", 600.0, 3.0)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc to find the processes")
def test_kill_of_the_shape_accuracy_benchmark_closes_its_dask_cluster(tmp_path):
    """``kill PID`` (SIGTERM) of the benchmark mid-study stops it as Ctrl-C does: it closes its dask
    cluster, so the worker ends with it and (a run of two bays) no semaphore is left for the resource tracker to report
    (SIGTERM's default action killed the process with the worker still sending heartbeats, and the
    tracker warned of leaked semaphores); the study's folder reads back."""
    pytest.importorskip("distributed")
    args = ["--bays", "--plain-bays", "--big", "2", "--big-samples", "64", "--dask", "--workers", "1"]
    runs = tmp_path / "out" / "bays2_plain"
    with open(tmp_path / "stderr.txt", "w") as err:
        p = subprocess.Popen(
            [sys.executable, "-m", "femast.benchmarks.shape_accuracy", *args, "--out", str(tmp_path / "out")],
            cwd=tmp_path,
            start_new_session=True,
            stdout=subprocess.DEVNULL,
            stderr=err,
        )
        running = lambda: len(session_processes(p.pid)) >= 2 and runs.is_dir()  # noqa: E731
        _kill_once_running(p, running, "the dask worker", 600.0, 3.0, sig=signal.SIGTERM)
    text = (tmp_path / "stderr.txt").read_text()
    assert "KeyboardInterrupt: stopped by signal 15" in text
    assert "leaked semaphore" not in text
    assert st.load(runs).counts()["expected"] == 64  # the folder reads back: the study of 64 samples
