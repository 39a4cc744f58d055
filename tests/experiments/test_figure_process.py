"""A figure drawn by a child forked at the start of a command (femast.experiments.figure_process):
it writes what the function writes; an argument that does not pickle or a failing
function returns False (the caller then draws); the child is always reaped."""

import os
import sys

import pytest

from femast.experiments import fe_jacobian as fj
from femast.experiments.figure_process import FigureProcess

pytestmark = pytest.mark.skipif(
    not sys.platform.startswith("linux") or (os.cpu_count() or 1) < 2, reason="needs Linux (fork) and two CPUs"
)


@pytest.fixture(autouse=True)
def _fork_possible_in_this_process():
    """The fork path needs a process without GNU OpenMP threads; an earlier test (in any order) may
    have run a parallel numba kernel on them, and they cannot be stopped."""
    import numba

    try:
        layer = numba.threading_layer()
    except ValueError:  # no parallel kernel has run
        return
    if layer == "omp":
        pytest.skip("an earlier test started GNU OpenMP threads in this process: no fork here")


@pytest.fixture
def forking(monkeypatch):
    monkeypatch.setattr(fj, "_only_thread", lambda: True)  # (earlier tests may have left threads behind)


def _plot(png, title):
    from femast.post.plotstyle import pyplot, save

    plt = pyplot()
    fig, ax = plt.subplots()
    ax.plot([0, 1], [1, 0])
    ax.set_title(title)
    save(fig, png)
    return png


def _fails(png):
    raise RuntimeError("no figure")


def _reaped(pid):
    with pytest.raises(ChildProcessError):
        os.waitpid(pid, os.WNOHANG)
    return True


def test_the_child_writes_the_figure(tmp_path, forking):
    fp = FigureProcess.start()
    assert fp is not None and fp.pid != os.getpid()
    pid = fp.pid
    png = tmp_path / "a.png"
    assert fp.draw(_plot, png, "drawn in the child")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert _reaped(pid)


def test_what_does_not_pickle_or_fails_is_left_to_the_caller(tmp_path, forking):
    fp = FigureProcess.start()
    pid = fp.pid
    assert not fp.draw(lambda png: _plot(png, "x"), tmp_path / "b.png")  # a lambda does not pickle
    assert not (tmp_path / "b.png").exists() and _reaped(pid)
    fp = FigureProcess.start()
    pid = fp.pid
    assert not fp.draw(_fails, tmp_path / "c.png")
    assert _reaped(pid)


def test_closed_without_a_request(forking):
    fp = FigureProcess.start()
    pid = fp.pid
    fp.close()
    fp.close()  # twice: nothing left to do
    assert _reaped(pid)


def test_no_child_where_forking_is_unsafe(monkeypatch):
    monkeypatch.setattr(fj, "_only_thread", lambda: False)
    assert FigureProcess.start() is None


def _stuck(png):
    import time

    time.sleep(60.0)


def test_a_stuck_child_is_killed_and_the_caller_draws(tmp_path, forking, monkeypatch):
    import time

    from femast.experiments import figure_process

    monkeypatch.setattr(figure_process, "FIGURE_WAIT_S", 1.0)
    fp = FigureProcess.start()
    pid = fp.pid
    t0 = time.monotonic()
    assert not fp.draw(_stuck, tmp_path / "d.png")
    assert time.monotonic() - t0 < 30.0  # not the child's 60 s
    assert _reaped(pid)
