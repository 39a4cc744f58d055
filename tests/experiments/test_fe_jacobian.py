"""Finite-difference columns of the expensive fits split with a forked child
(femast.experiments.fe_jacobian.evaluate_many): the same values as computing them here,
bit for bit; a child that fails is replaced by this process; serial where forking is unsafe."""

import os
import sys
import threading

import numpy as np
import pytest

from femast.experiments import fe_jacobian as fj

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
    """Forking allowed although earlier tests may have left threads behind (the functions forked here
    take no locks); the thread rule itself is tested below."""
    monkeypatch.setattr(fj, "_only_thread", lambda: True)


def _fun(u):
    # a smooth vector function with values whose bits a round trip through text would change
    x = np.linspace(0.0, 1.0, 7)
    return np.sin(u[0] * x) / 3.0 + np.exp(-u[1] * x) + np.pi * u[0] * u[1]


def test_forked_columns_equal_serial_ones_bit_for_bit(forking):
    pts = [np.array([0.1 * k, 1.0 + 0.3 * k]) for k in range(5)]
    assert fj._fork_ok(len(pts))
    got = fj.evaluate_many(_fun, pts, 7)
    want = [_fun(p) for p in pts]
    assert len(got) == 5
    for g, w in zip(got, want):
        assert g.dtype == np.float64 and np.array_equal(g, w)


def test_the_child_runs_the_second_half(forking):
    parent = os.getpid()
    pids = {}

    def fun(u):
        pids[float(u[0])] = os.getpid()
        return np.full(3, float(os.getpid() == parent))

    got = fj.evaluate_many(fun, [np.array([1.0]), np.array([2.0]), np.array([3.0])], 3)
    # ceil(3 / 2) = 2 points here (seen in this process's dict), the last one in the child (1.0 -> 0)
    assert [g[0] for g in got] == [1.0, 1.0, 0.0]
    assert set(pids) == {1.0, 2.0}


def test_a_failing_child_is_replaced_by_this_process(forking):
    parent = os.getpid()

    def fun(u):
        if os.getpid() != parent:
            raise RuntimeError("child fails")
        return np.full(4, u[0])

    got = fj.evaluate_many(fun, [np.array([1.0]), np.array([2.0])], 4)
    assert np.array_equal(got[1], np.full(4, 2.0))


def test_serial_outside_the_main_thread_and_when_switched_off(forking, monkeypatch):
    out = {}

    def run():
        out["ok"] = fj._fork_ok(4)

    t = threading.Thread(target=run)
    t.start()
    t.join()
    assert out["ok"] is False
    assert fj._fork_ok(1) is False  # one point: nothing to split
    monkeypatch.setattr(fj, "FORK_COLUMNS", False)
    assert fj._fork_ok(4) is False


def test_jacobian_with_forked_columns_equals_the_serial_one(forking, monkeypatch):
    lo, hi = np.full(2, -10.0), np.full(2, 10.0)
    u = np.array([0.4, 0.7])
    jac = {}
    for fork in (True, False):
        monkeypatch.setattr(fj, "FORK_COLUMNS", fork)
        j = fj._FEJacobian(_fun, 1e-3, lo, hi)
        jac[fork] = j.jac(u)
        assert j.runs == 3  # the point itself and two columns
    assert np.array_equal(jac[True], jac[False])


def test_serial_while_another_thread_runs():
    stop = threading.Event()
    t = threading.Thread(target=stop.wait, daemon=True)
    t.start()
    try:
        assert fj._only_thread() is False and fj._fork_ok(4) is False
    finally:
        stop.set()
        t.join()


def test_the_heap_is_unfrozen_after_the_children(forking):
    import gc

    from femast.experiments.refits import frozen_heap

    fj.evaluate_many(_fun, [np.array([0.1, 0.2]), np.array([0.3, 0.4])], 7)
    assert gc.get_freeze_count() == 0
    with frozen_heap():
        assert gc.get_freeze_count() > 0
    assert gc.get_freeze_count() == 0


def _gone(pid):
    """The process ``pid`` has ended and was reaped (no zombie, no orphan)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    return False


def test_an_error_here_ends_the_child_at_once(forking, tmp_path):
    """An error (or Ctrl-C) in this process's share: the child's points are not waited for; it is
    killed and reaped before the error goes on."""
    import time

    parent = os.getpid()
    pid_file = tmp_path / "child.pid"

    def fun(u):
        if os.getpid() != parent:
            pid_file.write_text(str(os.getpid()))
            time.sleep(60.0)  # a long FE run
            return np.zeros(2)
        time.sleep(0.5)  # (the child has started its run)
        raise KeyboardInterrupt

    t0 = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        fj.evaluate_many(fun, [np.array([1.0]), np.array([2.0])], 2)
    assert time.monotonic() - t0 < 30.0  # not the child's 60 s
    assert _gone(int(pid_file.read_text()))


def test_a_stuck_child_is_killed_and_its_points_computed_here(forking, tmp_path, monkeypatch):
    import time

    monkeypatch.setattr(fj, "CHILD_WAIT", 1.0)
    monkeypatch.setattr(fj, "CHILD_WAIT_MIN_S", 0.5)
    parent = os.getpid()
    pid_file = tmp_path / "child.pid"

    def fun(u):
        if os.getpid() != parent:
            pid_file.write_text(str(os.getpid()))
            time.sleep(60.0)  # stuck (e.g. on a lock that fork copied)
        return np.full(3, u[0])

    t0 = time.monotonic()
    got = fj.evaluate_many(fun, [np.array([1.0]), np.array([2.0]), np.array([3.0])], 3)
    assert time.monotonic() - t0 < 30.0
    assert [g[0] for g in got] == [1.0, 2.0, 3.0]
    assert _gone(int(pid_file.read_text()))


def test_serial_off_linux(monkeypatch):
    """fork is used on Linux only (macOS: not safe with its system libraries; Windows: none)."""
    monkeypatch.setattr(fj, "_only_thread", lambda: True)
    monkeypatch.setattr(sys, "platform", "darwin")
    assert fj._fork_ok(4) is False
    calls = []
    got = fj.evaluate_many(lambda u: calls.append(os.getpid()) or np.zeros(1), [np.zeros(1)] * 3, 1)
    assert len(got) == 3 and set(calls) == {os.getpid()}


def test_the_wait_works_on_descriptors_above_select_s_limit():
    """The pipe of a process with many open files may be numbered above 1024, where select() fails."""
    import resource

    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if hard != resource.RLIM_INFINITY and hard <= 1500:
        pytest.skip("cannot open a descriptor above 1500 here")
    r, w = os.pipe()
    try:
        if soft != resource.RLIM_INFINITY and soft <= 1500:
            resource.setrlimit(
                resource.RLIMIT_NOFILE, (2048 if hard == resource.RLIM_INFINITY else min(hard, 2048), hard)
            )
        hi = os.dup2(r, 1500)
        assert not fj.readable(hi, 0.01)  # nothing written yet
        os.write(w, b"x")
        assert fj.readable(hi, 1.0)
        os.close(hi)
    finally:
        os.close(r)
        os.close(w)
        resource.setrlimit(resource.RLIMIT_NOFILE, (soft, hard))
