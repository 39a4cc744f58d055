"""``femast study S --scheduler tcp://...`` against a real ``dask scheduler`` and ``dask worker``
started as separate processes (not an in-process client): the same results as a serial run."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import femast.studies as st

pytest.importorskip("distributed")

STUDY = textwrap.dedent(
    """
    import numpy as np
    import femast.studies as st

    def ishigami(x1, x2, x3):
        return {"y": np.sin(x1) + 7 * np.sin(x2) ** 2 + 0.1 * x3 ** 4 * np.sin(x1)}

    study = st.Study(run=ishigami, inputs=[st.Uniform(n, -np.pi, np.pi) for n in ("x1", "x2", "x3")],
                     outputs=["y"], sensitivity=True, name="ishigami", seed=7)
    """
)


def _start(args, cwd, log):
    return subprocess.Popen(
        [sys.executable, "-m", "dask", *args],
        cwd=cwd,
        stdout=log,
        stderr=subprocess.STDOUT,
        start_new_session=True,  # (ended with its whole session below)
    )


def _end(p):
    try:
        os.killpg(p.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    p.wait(timeout=30)


def test_cli_study_on_a_separate_dask_scheduler_and_worker(tmp_path):
    script = tmp_path / "ishigami_study.py"
    script.write_text(STUDY)
    info = tmp_path / "scheduler.json"
    log = open(tmp_path / "dask.log", "wb")
    scheduler = _start(
        ["scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard", "--scheduler-file", str(info)],
        tmp_path,
        log,
    )
    worker = None
    try:
        deadline = time.monotonic() + 120.0
        while not (info.is_file() and info.stat().st_size > 0):
            assert scheduler.poll() is None and time.monotonic() < deadline, (tmp_path / "dask.log").read_text()
            time.sleep(0.2)
        address = json.loads(info.read_text())["address"]
        worker = _start(
            ["worker", address, "--nthreads", "1", "--nworkers", "1", "--no-nanny", "--no-dashboard"], tmp_path, log
        )
        p = subprocess.run(
            [
                sys.executable,
                "-m",
                "femast.cli",
                "study",
                str(script),
                "--samples",
                "16",
                "--scheduler",
                address,
                "--out",
                str(tmp_path / "dask"),
                "--no-report",
            ],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=600,
        )
        assert p.returncode == 0, p.stderr + (tmp_path / "dask.log").read_text()
        assert "dask worker(s)" in p.stdout and "complete" in p.stdout
    finally:
        for proc in (worker, scheduler):
            if proc is not None:
                _end(proc)
        log.close()
    ns = {}
    exec(STUDY, ns)
    st.run(ns["study"], tmp_path / "serial", samples=16)
    a = st.load(tmp_path / "serial").table(["y", "x1", "x2", "x3", "block"])
    b = st.load(tmp_path / "dask").table(["y", "x1", "x2", "x3", "block"])
    for k in a:
        assert np.array_equal(a[k], b[k]), k
