"""Worker processes: the one executor of every parallel path of femast.

femast computes in the caller's process unless the user asks for workers (``workers=``,
``--workers``, a dask scheduler).  When they do, the work goes to a :class:`Pool` of worker
processes that

* are started fresh (``spawn``: a new interpreter that imports femast; never a bare ``fork`` of
  a process that may hold threads, locks or OpenMP state);
* end with their parent however the parent ends, SIGKILL included: on Linux the kernel kills a
  worker when the thread of the parent that started it ends (``PR_SET_PDEATHSIG``; the pool's own
  manager thread starts them), which needs no Python in the worker, so a worker busy in a compiled
  loop dies too; everywhere, a worker waiting for a task ends when its pipe from the parent
  closes, and a watchdog thread ends it when the parent's sentinel fires (on other systems a
  worker inside a compiled loop that holds the GIL ends when the loop returns);
* can be killed one by one: a task that runs over its time-out (``timeout_s``) has its worker
  killed and replaced, so a task stuck inside a compiled loop, which no signal interrupts, still
  ends; a worker that dies (out of memory, a crash in compiled code) fails its task with
  :class:`~femast.errors.WorkerDied` and is replaced, the other tasks go on;
* are never more than the CPUs femast may use unless the caller asks for more
  (:func:`worker_count`).

API (a :class:`concurrent.futures.Executor`)::

    from femast import workers

    n = workers.worker_count(None, tasks=len(jobs))        # CPUs, at most one per task
    with workers.Pool(n, initializer=setup, initargs=(payload,), timeout_s=600.0) as pool:
        futures = [pool.submit(run_one, job) for job in jobs]   # concurrent.futures.Future
        for fut in concurrent.futures.as_completed(futures):
            value = fut.result()    # the task's value, or its exception (TaskTimeout, WorkerDied)
    values = pool.map(fn, items)    # (inside the with) ordered, like Executor.map

* ``fn``, its arguments and ``initargs`` are pickled (``cloudpickle`` when the standard pickle
  cannot: functions of a script).  Send large read-only things once, through ``initializer``
  (which runs in every worker as it starts, replacements included) and keep them in a module
  global of the worker, rather than with every task.
* ``timeout_s`` (s, per task, from the moment a worker takes it; ``submit(..., timeout_s=...)``
  overrides it for one task).  ``None``: no limit.  ``start_timeout_s`` (s) bounds a worker's
  start (import and ``initializer``); workers that die or hang as they start, three in a row,
  end the pool: every task then fails with :class:`~femast.errors.WorkerDied`.
* Leaving the ``with`` block normally waits for the submitted tasks; leaving it by an exception
  (Ctrl-C included) kills the workers at once.  :meth:`Pool.kill` does that explicitly.
* A worker ignores SIGINT (Ctrl-C is its parent's to handle), and prints no first-run compile
  notice of its own unless it is the first process of the tree to compile
  (:mod:`femast.jit`).
* Scripts that start workers and are run with ``python script.py`` must keep their top-level
  work under ``if __name__ == "__main__":`` (Python's rule for ``spawn``/``forkserver``: a worker
  imports the main script); ``femast study`` scripts need not.

A study's samples (:mod:`femast.studies`) and diagnose's refits run on this pool.
"""

from __future__ import annotations

import atexit
import collections
import concurrent.futures
import itertools
import multiprocessing
import os
import pickle
import threading
import time
import weakref
from multiprocessing.connection import wait as _wait_ready

from .errors import FemastError, TaskTimeout, WorkerDied
from .worker_main import COMPILING, dumps, worker_main

STOP_WAIT_S = 5.0  # a worker asked to stop gets this long before it is killed (s)
_START_FAILURES_MAX = 3  # workers in a row dying before their first task: the pool is broken
_POOLS: weakref.WeakSet = weakref.WeakSet()  # live pools, killed at interpreter exit


def cpu_count() -> int:
    """CPUs this process may run on (its affinity mask where the platform has one)."""
    if hasattr(os, "process_cpu_count"):  # Python >= 3.13
        return max(1, os.process_cpu_count() or 1)
    if hasattr(os, "sched_getaffinity"):
        try:
            return max(1, len(os.sched_getaffinity(0)))
        except OSError:  # pragma: no cover
            pass
    return max(1, os.cpu_count() or 1)


def worker_count(requested=None, tasks: int | None = None) -> int:
    """Worker processes to start: ``requested`` when the user gave a number (more than the CPUs
    only then), else the CPUs; never more than ``tasks`` (when given) nor fewer than 1."""
    if requested is None:
        n = cpu_count()
    else:
        if isinstance(requested, bool) or int(requested) != requested or requested < 1:
            raise FemastError(f"workers = {requested!r} must be a whole number >= 1")
        n = int(requested)
    if tasks is not None:
        n = min(n, max(1, int(tasks)))
    return max(1, n)


def start_method() -> str:
    """``spawn``: a fresh interpreter per worker, on every platform.  (Not ``forkserver``: a worker
    of the fork server holds the fork server's liveness pipe open, so after a SIGKILL of the parent
    the fork server waits for the workers while they wait for it.)"""
    return "spawn"


# --------------------------------------------------------------------------- the parent side
class _Slot:
    """One worker process and the task it runs."""

    def __init__(self, process, conn):
        self.process, self.conn = process, conn
        self.task = None  # (task id, future, deadline or None)
        self.ready = False  # set up (initializer run): takes tasks
        self.start_deadline = None  # monotonic s by which it must be set up (None: no limit)
        self.done = 0  # tasks finished


class Pool(concurrent.futures.Executor):
    """``workers`` worker processes (see the module docstring).

    workers : number of processes (:func:`worker_count` chooses one).
    initializer, initargs : ``initializer(*initargs)`` runs in each worker as it starts.
    timeout_s : s, default time-out of a task, counted from when a worker takes it; a task over
        it fails with :class:`~femast.errors.TaskTimeout` and its worker is killed and replaced.
    name : shown in error messages ("study workers", "diagnose refits").
    start_timeout_s : s, a worker not set up this long after it was started (importing, running
        ``initializer``) is killed and counts as a worker that died as it started; ``None``: no
        limit.
    """

    def __init__(
        self,
        workers: int,
        initializer=None,
        initargs=(),
        timeout_s: float | None = None,
        name="femast",
        start_timeout_s: float | None = None,
    ):
        workers = worker_count(workers)
        if timeout_s is not None and not (timeout_s > 0):
            raise FemastError(f"timeout_s = {timeout_s!r} must be > 0 s (or None: no limit)")
        self.name = name
        self.timeout_s = timeout_s
        self.start_timeout_s = start_timeout_s
        self._ctx = multiprocessing.get_context(start_method())
        self._initializer = initializer
        self._initargs = dumps(tuple(initargs))
        self._ids = itertools.count()
        self._queue = collections.deque()  # (task id, future, payload, timeout_s)
        self._lock = threading.Lock()
        self._wake_r, self._wake_w = multiprocessing.Pipe(duplex=False)
        self._n = workers
        self._slots = []  # started by the manager thread (Linux: a worker dies with the thread that started it)
        self._started = threading.Event()
        self._closing = False  # no more submissions; stop when the queue is empty
        self._broken = None  # the reason the pool cannot run tasks
        self._start_failures = 0
        self._thread = threading.Thread(target=self._manage, daemon=True, name=f"femast-pool-{name}")
        self._thread.start()
        self._started.wait()
        _POOLS.add(self)
        if self._broken is not None:
            self._thread.join(STOP_WAIT_S)
            raise WorkerDied(self._broken)

    @property
    def workers(self) -> int:
        return self._n

    def pids(self) -> list[int]:
        """Process ids of the live workers."""
        return [s.process.pid for s in self._slots if s.process.is_alive()]

    # ---------------------------------------------------------------- Executor API
    def submit(self, fn, /, *args, timeout_s: float | None = ..., **kwargs) -> concurrent.futures.Future:
        """Run ``fn(*args, **kwargs)`` in a worker; ``timeout_s`` (s) overrides the pool's."""
        fut = concurrent.futures.Future()
        task_id = next(self._ids)
        payload = dumps((task_id, fn, args, kwargs))  # (here: a task that cannot be pickled fails in the caller)
        with self._lock:
            if self._closing:
                raise RuntimeError(f"{self.name}: cannot submit to a pool that is shut down")
            if self._broken is not None:
                raise WorkerDied(self._broken)
            self._queue.append((task_id, fut, payload, self.timeout_s if timeout_s is ... else timeout_s))
        self._wake()
        return fut

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        """No more tasks; ``wait``: until the submitted ones are done and the workers have ended."""
        with self._lock:
            self._closing = True
            if cancel_futures:
                while self._queue:
                    self._queue.popleft()[1].cancel()
        self._wake()
        if wait:
            self._thread.join()

    def kill(self) -> None:
        """End every worker now; unfinished tasks fail with :class:`~femast.errors.WorkerDied`."""
        with self._lock:
            self._closing = True
            self._broken = self._broken or f"{self.name}: the pool was stopped"
            while self._queue:
                self._queue.popleft()[1].cancel()
        for s in self._slots:
            _kill(s.process)
        self._wake()
        self._thread.join(timeout=STOP_WAIT_S)

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self.shutdown(wait=True)
        else:
            self.kill()
        return False

    # ---------------------------------------------------------------- the manager thread
    def _start(self) -> _Slot:
        mine, theirs = self._ctx.Pipe(duplex=True)
        p = self._ctx.Process(
            target=worker_main,
            args=(theirs, self._initializer, self._initargs),
            name=f"femast-worker ({self.name})",
            daemon=True,
        )
        p.start()
        theirs.close()  # only the worker holds its end: its reads see EOF when this process ends
        slot = _Slot(p, mine)
        if self.start_timeout_s is not None:
            slot.start_deadline = time.monotonic() + float(self.start_timeout_s)
        return slot

    def _wake(self) -> None:
        try:
            self._wake_w.send_bytes(b"!")
        except OSError:  # the manager has ended
            pass

    def _manage(self) -> None:
        try:
            try:
                self._slots.extend(self._start() for _ in range(self._n))
            except BaseException as exc:  # e.g. Python refusing to start a process while a worker imports
                with self._lock:
                    self._broken = f"{self.name}: cannot start worker processes ({type(exc).__name__}: {exc})"
                raise
            finally:
                self._started.set()
            self._loop()
        except BaseException as exc:  # a bug here must not hang the caller
            with self._lock:
                self._broken = self._broken or f"{self.name}: the pool's manager failed ({type(exc).__name__}: {exc})"
            self._fail_all(self._broken)
        finally:
            _stop_all(self._slots)
            self._wake_r.close()
            self._wake_w.close()

    def _loop(self) -> None:
        while True:
            with self._lock:
                if self._broken is not None:
                    break
                if self._closing and not self._queue and all(s.task is None for s in self._slots):
                    break
                self._dispatch()
            now = time.monotonic()
            deadlines = [s.task[2] for s in self._slots if s.task is not None and s.task[2] is not None]
            deadlines += [s.start_deadline for s in self._slots if not s.ready and s.start_deadline is not None]
            timeout = None if not deadlines else max(0.0, min(deadlines) - now)
            waitables = [self._wake_r] + [s.conn for s in self._slots] + [s.process.sentinel for s in self._slots]
            ready = _wait_ready(waitables, timeout)
            if self._wake_r in ready:
                while self._wake_r.poll():
                    self._wake_r.recv_bytes()
            for s in list(self._slots):
                if s.conn in ready or s.process.sentinel in ready:
                    self._collect(s)
            now = time.monotonic()
            for s in list(self._slots):
                if s.task is not None and s.task[2] is not None and now >= s.task[2]:
                    self._time_out(s)
                elif not s.ready and s.start_deadline is not None and now >= s.start_deadline:
                    s.start_deadline = None
                    _kill(s.process)  # its sentinel fires: collected as a worker that died as it started
        if self._broken is not None:
            self._fail_all(self._broken)

    def _dispatch(self) -> None:
        """Give queued tasks to idle workers (under the lock)."""
        for s in self._slots:
            if not self._queue:
                return
            if s.task is not None or not s.ready:
                continue
            task_id, fut, payload, timeout_s = self._queue.popleft()
            if not fut.running() and not fut.set_running_or_notify_cancel():
                continue  # cancelled
            try:
                s.conn.send_bytes(payload)
            except OSError:  # the worker died meanwhile (its sentinel is ready): the next one takes the task
                self._queue.appendleft((task_id, fut, payload, timeout_s))
                continue
            deadline = None if timeout_s is None else time.monotonic() + float(timeout_s)
            s.task = (task_id, fut, deadline)

    def _collect(self, s: _Slot) -> None:
        """A worker answered or died."""
        try:
            while s.conn.poll():
                data = s.conn.recv_bytes()
                if data == COMPILING:
                    from . import jit

                    jit.announce()  # (once per process: the tree's notice)
                    continue
                reply = pickle.loads(data)
                if reply is None:
                    s.ready = True
                    return
                task_id, ok, value = reply
                fut = s.task[1]
                s.task = None
                s.done += 1
                self._start_failures = 0
                if ok:
                    fut.set_result(value)
                else:
                    fut.set_exception(value)
                return
        except (EOFError, OSError):
            pass
        if s.process.is_alive():
            return
        # the worker is gone
        code = s.process.exitcode
        _stop(s)
        if s.task is not None:
            fut = s.task[1]
            s.task = None
            fut.set_exception(
                WorkerDied(
                    f"{self.name}: a worker process died running a task (exit code {code}: killed, out of "
                    "memory, or a crash in compiled code)"
                )
            )
        elif not s.ready:
            self._start_failures += 1
            if self._start_failures >= _START_FAILURES_MAX:
                with self._lock:
                    self._broken = (
                        f"{self.name}: worker processes die (or hang) as they start (exit code {code}); if the script "
                        'that starts them is run with `python script.py`, put its work under `if __name__ == "__main__":`'
                    )
                return
        self._replace(s)

    def _replace(self, s: _Slot) -> None:
        """A new worker in the place of the ended ``s`` (none once closing with nothing queued)."""
        i = self._slots.index(s)
        if not self._closing or self._queue:
            self._slots[i] = self._start()
        else:
            del self._slots[i]

    def _time_out(self, s: _Slot) -> None:
        """A task ran over its time-out: its worker is killed and replaced."""
        task_id, fut, deadline = s.task
        s.task = None
        _kill(s.process)
        _stop(s)
        fut.set_exception(TaskTimeout(f"{self.name}: a task ran over its time-out; its worker process was killed"))
        self._replace(s)

    def _fail_all(self, reason: str) -> None:
        with self._lock:
            queued = list(self._queue)
            self._queue.clear()
        for s in self._slots:
            if s.task is not None:
                fut, s.task = s.task[1], None
                if not fut.done():
                    fut.set_exception(WorkerDied(reason))
            _kill(s.process)
        for _, fut, _, _ in queued:
            if fut.running() or fut.set_running_or_notify_cancel():
                fut.set_exception(WorkerDied(reason))


def _kill(process) -> None:
    try:
        if process.is_alive():
            process.kill()
    except (OSError, ValueError, AttributeError):  # already reaped / closed
        pass


def _stop(s: _Slot) -> None:
    _stop_all([s])


def _stop_all(slots) -> None:
    """Ask workers to end (an empty message), wait up to :data:`STOP_WAIT_S` in all, then kill the
    ones still running."""
    for s in slots:
        try:
            s.conn.send_bytes(b"")
        except (OSError, ValueError):  # gone, or its pipe closed
            pass
    end = time.monotonic() + STOP_WAIT_S
    for s in slots:
        try:
            s.process.join(max(0.0, end - time.monotonic()))
            if s.process.is_alive():
                s.process.kill()
                s.process.join(STOP_WAIT_S)
        except (ValueError, AssertionError):  # already closed
            pass
        try:
            s.conn.close()
        except OSError:  # pragma: no cover
            pass


def _kill_all_at_exit() -> None:
    for pool in list(_POOLS):
        for s in pool._slots:
            _kill(s.process)


atexit.register(_kill_all_at_exit)
