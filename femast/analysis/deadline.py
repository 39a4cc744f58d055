"""A wall-clock deadline for the analyses run by this thread (``Study(timeout_s=)`` on
dask workers, whose samples run in threads where a SIGALRM timer cannot reach).

``with deadline(60.0):`` gives every analysis this thread runs inside the block
until 60 s of wall clock from now: the Newton loop checks it at each iteration
(:func:`check`) and raises :class:`~femast.errors.SampleTimeout` past it.  The analysis writes its
summary as for any error and the study records the sample as failed with that reason.  Nested
deadlines keep the earlier one.  Unused, :func:`check` is one attribute read per iteration
(0.1-0.2 us of CPU, measured, against 0.3 ms or more for an iteration's assembly and solve).
"""

from __future__ import annotations

import threading
import time
from contextlib import contextmanager

from ..errors import ModelError, SampleTimeout


class _Local(threading.local):
    until = None  # (monotonic time, message) or None; a class default: no AttributeError to catch


_LOCAL = _Local()


@contextmanager
def deadline(seconds: float | None, message: str | None = None):
    """Analyses run by this thread inside the block stop (SampleTimeout, with ``message``) after
    ``seconds`` of wall clock (None: no limit)."""
    if seconds is None:
        yield
        return
    try:
        seconds = float(seconds)
    except (TypeError, ValueError):
        raise ModelError(f"deadline: {seconds!r} is not a number of seconds") from None
    if not seconds > 0.0:
        raise ModelError(f"deadline: {seconds!r} s must be > 0 (None: no limit)")
    old = _LOCAL.until
    until = time.monotonic() + seconds
    if old is not None and old[0] <= until:
        until, label = old
    else:
        label = message or f"the computation ran over its deadline of {seconds:g} s (wall clock); it is stopped"
    _LOCAL.until = (until, label)
    try:
        yield
    finally:
        _LOCAL.until = old


def check() -> None:
    """Raise SampleTimeout if this thread's deadline has passed (a no-op without one)."""
    d = _LOCAL.until
    if d is not None and time.monotonic() > d[0]:
        raise SampleTimeout(d[1])


def remaining() -> float | None:
    """Seconds left before this thread's deadline (None: no deadline)."""
    d = _LOCAL.until
    return None if d is None else d[0] - time.monotonic()
