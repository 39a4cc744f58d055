"""femast.workers.Pool, the one executor of femast's parallel paths: results and errors come back
as from a call in this process, a task over its time-out or a dying worker fails that task alone,
the first-run compile notice is printed once for the process tree, and a SIGKILL of the parent
leaves no worker behind even when the workers are inside a compiled loop."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest
from process_tree import assert_session_ends, session_processes

from femast import jit, workers
from femast.errors import FemastError, TaskTimeout, WorkerDied


def _square(x):
    return x * x


def _fails(text):
    raise KeyError(text)


def _sleeps(seconds):
    time.sleep(seconds)
    return "woke"


def _dies():
    os._exit(7)


def _announces():
    jit.announce()  # (what numba's first compile of a femast kernel does in a worker)
    return os.getpid()


def test_pool_results_errors_timeouts_and_dead_workers(monkeypatch, capsys):
    from femast import progress

    monkeypatch.setattr(jit, "_announced", False)
    monkeypatch.setattr(progress, "_QUIET", False)  # (whatever an earlier test left)
    monkeypatch.delenv("FEMAST_QUIET", raising=False)
    with workers.Pool(2, timeout_s=60.0, name="test") as pool:
        assert list(pool.map(_square, range(7))) == [x * x for x in range(7)]
        with pytest.raises(KeyError, match="no such thing"):
            pool.submit(_fails, "no such thing").result()
        with pytest.raises(TaskTimeout):
            pool.submit(_sleeps, 600.0, timeout_s=1.0).result()
        with pytest.raises(WorkerDied, match="exit code 7"):
            pool.submit(_dies).result()
        # the pool goes on with replaced workers
        assert pool.submit(_sleeps, 0.0).result() == "woke"
        pids = {pool.submit(_announces).result() for _ in range(4)}
        assert len(pool.pids()) == 2
    err = capsys.readouterr().err
    assert len(pids) >= 1 and err.count("compiling femast's numba kernels") == 1
    assert pool.pids() == []


def test_worker_count():
    n = workers.cpu_count()
    assert workers.worker_count() == n
    assert workers.worker_count(None, tasks=1) == 1
    assert workers.worker_count(3 * n) == 3 * n  # more than the CPUs only when asked
    assert workers.worker_count(4, tasks=2) == 2
    for bad in (0, -1, 1.5, True):
        with pytest.raises(FemastError, match="workers"):
            workers.worker_count(bad)


PARENT = textwrap.dedent(
    """
    import os, signal, sys, time
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
        spin(10)  # compiled
        open(mark, "w").close()  # (the test waits for both marks)
        return spin(10**18)  # with the GIL held: no Python runs in the worker until it returns

    if __name__ == "__main__":
        pool = workers.Pool(2)
        futures = [pool.submit(stuck, f"inside-{i}") for i in range(2)]
        print("started", flush=True)
        time.sleep(3600)
    """
)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc to find the processes")
def test_sigkill_of_the_parent_ends_workers_inside_compiled_code(tmp_path):
    script = tmp_path / "parent.py"
    script.write_text(PARENT)
    p = subprocess.Popen(
        [sys.executable, str(script)], cwd=tmp_path, start_new_session=True, stdout=subprocess.PIPE, text=True
    )
    try:
        assert p.stdout.readline().strip() == "started"
        deadline = time.monotonic() + 300.0
        while not all((tmp_path / f"inside-{i}").exists() for i in range(2)):  # both workers in the loop
            assert time.monotonic() < deadline, "the workers did not start"
            time.sleep(0.2)
        time.sleep(0.5)
        os.kill(p.pid, signal.SIGKILL)
        p.wait(timeout=30)
        assert_session_ends(p.pid, within_s=30.0)
    finally:
        for pid in session_processes(p.pid):
            os.kill(pid, signal.SIGKILL)


def test_the_docs_example_runs_as_a_script(tmp_path):
    """docs/workers.md's example, run as `python script.py` (its main block starts the workers)."""
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "workers.md").read_text()
    (block,) = re.findall(r"```python\n(.*?)```", text, re.S)
    (quoted,) = re.findall(r"prints `([^`]+)`", text)
    (tmp_path / "example.py").write_text(block)
    p = subprocess.run(
        [sys.executable, "example.py"], cwd=tmp_path, capture_output=True, text=True, timeout=300, check=True
    )
    assert eval(p.stdout.strip()) == [1.0 / (1.0 / k + 1.0 / 2.0e6) for k in (1.0e6, 2.0e6, 4.0e6, 8.0e6)]
    assert eval(quoted) == eval(p.stdout.strip())


UNGUARDED = textwrap.dedent(
    """
    from femast import workers

    def square(x):
        return x * x

    with workers.Pool(2) as pool:  # not under `if __name__ == "__main__":`
        print(list(pool.map(square, range(4))))
    """
)


def test_a_script_without_a_main_guard_gets_a_clear_error_not_a_hang(tmp_path):
    """Each worker imports the script and would start workers of its own: Python refuses that, the
    workers die as they start, and the script ends with an error that says what to change."""
    (tmp_path / "unguarded.py").write_text(UNGUARDED)
    p = subprocess.run([sys.executable, "unguarded.py"], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert p.returncode != 0
    last = p.stderr.strip().splitlines()[-1]
    assert last.startswith("femast.errors.WorkerDied") and 'if __name__ == "__main__":' in last


def _never_returns():
    time.sleep(3600)


def test_workers_that_never_get_set_up_end_the_pool_with_an_error():
    with workers.Pool(2, initializer=_never_returns, start_timeout_s=5.0, name="test") as pool:
        with pytest.raises(WorkerDied, match="as they start"):
            pool.submit(_square, 3).result(timeout=600)


BAR_IN_A_WORKER = textwrap.dedent(
    """
    from tqdm import tqdm

    from femast import workers

    def with_a_bar(n):
        return sum(1 for _ in tqdm(range(n), disable=False))

    if __name__ == "__main__":
        with workers.Pool(2) as pool:
            print(list(pool.map(with_a_bar, [3, 4])))
    """
)


def test_progress_bars_in_workers_leave_no_semaphore_behind(tmp_path):
    """A task that draws a tqdm bar (an FE run inside a refit does) must not leave a named semaphore
    for the resource tracker to warn about when the user's command ends."""
    (tmp_path / "bars.py").write_text(BAR_IN_A_WORKER)
    p = subprocess.run(
        [sys.executable, "bars.py"], cwd=tmp_path, capture_output=True, text=True, timeout=300, check=True
    )
    assert p.stdout.strip().splitlines()[-1] == "[3, 4]"
    assert "leaked semaphore" not in p.stderr
