"""What runs inside a worker process of :class:`femast.workers.Pool`: it asks to die with the
thread that started it (Linux), watches its parent, sets up, then runs tasks from its pipe.

Messages on the pipe (pickled; ``cloudpickle`` when the standard pickle cannot): to the worker,
``(task id, fn, args, kwargs)`` or an empty message (stop); from it, ``None`` once set up,
``(task id, True, value)`` or ``(task id, False, exception)`` per task, and :data:`COMPILING` when
numba begins compiling a femast kernel there (the parent prints the one notice of the tree).
"""

from __future__ import annotations

import multiprocessing
import os
import pickle
import sys
import threading
import traceback

from .errors import FemastError

COMPILING = b"compiling"  # a worker's message: numba has begun compiling a femast kernel


def dumps(obj) -> bytes:
    """``obj`` pickled: the standard pickle, else cloudpickle (functions of a script)."""
    try:
        return pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
    except (pickle.PicklingError, AttributeError, TypeError):
        try:
            import cloudpickle
        except ImportError:
            raise
        return cloudpickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)


def _die_with_parent() -> None:
    """Linux: the kernel sends SIGKILL to this process when the thread of the parent that started
    it ends (the pool's manager thread; with the whole parent on a SIGKILL).  No Python is needed
    for that: a worker busy in a compiled loop that holds the GIL dies too."""
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes
        import signal

        libc = ctypes.CDLL(None, use_errno=True)
        pr_set_pdeathsig = 1
        libc.prctl(pr_set_pdeathsig, int(signal.SIGKILL), 0, 0, 0)
    except (OSError, AttributeError):  # pragma: no cover - no prctl: the watchdog thread remains
        pass


def _watchdog() -> None:
    """Portable fallback: end this worker as soon as its parent is gone (its sentinel fires)."""
    parent = multiprocessing.parent_process()
    if parent is None:  # pragma: no cover
        return
    parent.join()  # returns when the parent process has ended
    os._exit(1)


class _RemoteError(FemastError):
    """An exception of a worker that could not be sent back as itself."""


def worker_main(conn, initializer, initargs) -> None:
    """A worker: set up, then run tasks from ``conn`` until told to stop or the parent is gone."""
    import signal

    _die_with_parent()
    parent = multiprocessing.parent_process()
    if parent is not None and not parent.is_alive():  # the parent died before prctl took effect
        os._exit(1)
    threading.Thread(target=_watchdog, daemon=True, name="femast-watchdog").start()
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    except (ValueError, OSError):  # pragma: no cover
        pass
    from . import jit

    jit.notice_to(lambda: conn.send_bytes(COMPILING))  # (from the task's thread, between its replies)
    _thread_lock_for_progress_bars()
    if initializer is not None:
        initializer(*pickle.loads(initargs))
    conn.send_bytes(dumps(None))  # ready: a task's time-out counts from now on
    while True:
        try:
            msg = conn.recv_bytes()
        except (EOFError, OSError):  # the parent is gone
            break
        if not msg:
            break
        task_id, fn, args, kwargs = pickle.loads(msg)
        try:
            reply = (task_id, True, fn(*args, **kwargs))
        except BaseException as exc:  # sent back to the caller, who decides
            reply = (task_id, False, _portable(exc))
        try:
            data = dumps(reply)
        except Exception as exc:
            data = dumps((task_id, False, _RemoteError(f"the task's result could not be sent back: {exc}")))
        try:
            conn.send_bytes(data)
        except (EOFError, OSError):
            break
    os._exit(0)  # no exit handlers of the task code (thread pools of numba, tqdm monitors)


def _thread_lock_for_progress_bars() -> None:
    """tqdm guards its bars with a multiprocessing lock (a named semaphore) by default; a worker
    ends with ``os._exit``, which never releases it, and the resource tracker then warns of "leaked
    semaphore objects" when the user's command ends.  A worker's bars are its own, so a thread lock
    is enough (tqdm's public ``set_lock``)."""
    import tqdm

    tqdm.tqdm.set_lock(threading.RLock())


def _portable(exc: BaseException) -> BaseException:
    """``exc`` if it survives pickling, else a :class:`_RemoteError` with its type and text; the
    worker's traceback goes along as a note."""
    tb = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
    try:
        pickle.loads(dumps(exc))
    except Exception:
        exc = _RemoteError(f"{type(exc).__name__}: {exc}")
    if hasattr(exc, "add_note"):
        exc.add_note(f"(in a worker process)\n{tb}")
    return exc
