"""numba kernels in the user's process: the first-run compile notice and the set-up kernels' plain-Python path.

numba compiles each kernel the first time it is called and keeps it in its on-disk cache (see
:mod:`femast.numba_cache` for where); only kernels a model calls are compiled.  On a fresh install
(or after an update) the first analysis therefore meets the compiler, in the user's process, in
the foreground.  The first time numba starts compiling a femast kernel, one notice goes to stderr
for the whole process tree (a worker of :mod:`femast.workers` passes it on to its parent, which
prints it once)::

    femast: compiling femast's numba kernels, once after an install or an update (about 30 s of
    CPU for a small model, 1-3 min for every element family); later runs load them from the
    cache. `femast warmup` does it ahead.

and, on a terminal, a bar counts the kernels compiled, naming the current one.  ``femast --quiet``
or ``FEMAST_QUIET=1`` silences both.  ``femast warmup`` (:mod:`femast.warmup`) compiles every
kernel ahead.
"""

from __future__ import annotations

import sys
import threading

NOTICE = (
    "femast: compiling femast's numba kernels, once after an install or an update (about 30 s of CPU for a "
    "small model, 1-3 min for every element family); later runs load them from the cache. "
    "`femast warmup` does it ahead."
)

_announced = False  # this process has claimed (or given up) the notice
_installed = False
_delegate = None  # in a worker process: passes the notice on to the parent
_bar = None
_depth = 0
_compiled = 0


# Set-up kernels (run once per analysis: assembly pattern, orderings, position maps) run as plain
# Python on inputs up to this many items: a small model then never compiles them (nor queues them
# for the background compile, which would delay the element kernels' compile), at a few ms of
# Python; larger inputs call the compiled kernel.
SETUP_PYTHON_MAX = 20_000  # inner-loop iterations (~10 ms of Python)


# Set-up kernels that return new arrays computed from their arguments alone and write none of them
# (qualified names): on the plain-Python path their results are remembered by a digest of the
# arguments, so a process that builds the same small model again and again (the FE fits of
# femast.experiments: 50-60 runs of one bay in a diagnosis) computes its pattern once
# (the bay's assembly pattern is 12 ms of its 82 ms per run in Python).
MEMO_KERNELS = frozenset({"femast.analysis.assembly._pattern_kernel", "femast.analysis.linalg.ordering._permuted_csc"})
MEMO_ENTRIES = 16
_MEMO: dict = {}
_MEMO_LOCK = threading.Lock()  # (models built in threads: a Study on dask threads)


def _memo_key(kernel, args):
    import hashlib

    import numpy as np

    h = hashlib.sha1(f"{kernel.py_func.__module__}.{kernel.py_func.__name__}".encode())
    for a in args:
        if isinstance(a, np.ndarray):
            a = np.ascontiguousarray(a)
            h.update(f"|{a.dtype.str}{a.shape}|".encode())
            h.update(a.tobytes())
        else:
            h.update(f"|{type(a).__name__}:{a!r}".encode())
    return h.digest()


def _copy_result(result):
    import numpy as np

    if isinstance(result, tuple):
        return tuple(r.copy() if isinstance(r, np.ndarray) else r for r in result)
    return result.copy() if isinstance(result, np.ndarray) else result


def setup_call(kernel, n_items: int, *args):
    """``kernel(*args)`` for a set-up kernel: its plain-Python function when ``n_items`` (about the
    number of its inner-loop iterations) is at most :data:`SETUP_PYTHON_MAX` (integer results, or
    sums in the same order: the same bits).  The plain-Python results of the kernels named in
    :data:`MEMO_KERNELS` are remembered (the last :data:`MEMO_ENTRIES`, keyed by a SHA-1 of the
    arguments' bytes, dtypes and shapes) and returned as copies."""
    if n_items > SETUP_PYTHON_MAX:
        return kernel(*args)
    if f"{kernel.py_func.__module__}.{kernel.py_func.__name__}" not in MEMO_KERNELS:
        return kernel.py_func(*args)
    key = _memo_key(kernel, args)
    hit = _MEMO.get(key)
    if hit is None:
        hit = kernel.py_func(*args)
        kept = _copy_result(hit)
        with _MEMO_LOCK:
            while _MEMO and len(_MEMO) >= MEMO_ENTRIES:
                _MEMO.pop(next(iter(_MEMO)))  # the oldest entry
            _MEMO[key] = kept
        return hit
    return _copy_result(hit)


def notice_to(send) -> None:
    """In a worker process: instead of printing the notice, call ``send()`` once (the worker's pool
    then has its parent print it, once for the whole process tree)."""
    global _delegate
    _delegate = send


def _claim() -> bool:
    """True the first time in this process (this process prints, or passes on, the notice)."""
    global _announced
    if _announced:
        return False
    _announced = True
    return True


def announce(bar: bool = False) -> None:
    """Print the compile notice (once per process, unless quiet) and, with ``bar``, open the bar of
    the kernels this process compiles; in a worker, pass the notice on to the parent instead."""
    global _bar
    from . import progress

    if not _claim():
        return
    if _delegate is not None:
        _delegate()
        return
    if progress.quiet():
        return
    print(NOTICE, file=sys.stderr, flush=True)
    if bar and progress.enabled():
        _bar = progress.counter(None, "compiling femast kernels", unit="kernels")


def _femast_kernel(event):
    try:
        func = event.data["dispatcher"].py_func
    except (KeyError, AttributeError):
        return None
    return func.__name__ if func.__module__.startswith("femast") else None


def _on_start(event) -> None:
    global _depth
    name = _femast_kernel(event)
    if name is None:
        return
    if not _announced:
        announce(bar=True)
    _depth += 1
    if _bar is not None and _depth == 1:
        _bar.set_postfix_str(name, refresh=True)


def _on_end(event) -> None:
    global _depth, _compiled
    if _femast_kernel(event) is None:
        return
    _depth = max(0, _depth - 1)
    _compiled += 1
    if _bar is not None:
        _bar.update(1)
        if _depth == 0:
            _bar.set_postfix_str("", refresh=True)


def prepare() -> None:
    """Before an analysis: the compile notice is armed (:func:`watch`); an open kernel bar of an
    earlier analysis is closed."""
    global _bar
    watch()
    if _bar is not None and _depth == 0:
        _bar.close()
        _bar = None


def watch() -> None:
    """Print the compile notice the first time numba compiles a femast kernel in this process
    (numba's compile events)."""
    global _installed
    if _installed:
        return
    _installed = True
    try:
        from numba.core import event
    except ImportError:  # pragma: no cover
        return

    class _Listener(event.Listener):
        def on_start(self, ev):
            _on_start(ev)

        def on_end(self, ev):
            _on_end(ev)

    event.register("numba:compile", _Listener())
