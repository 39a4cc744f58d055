"""A figure drawn by a process forked when the command starts, which imports matplotlib meanwhile.

``diagnose`` of an FE experiment keeps both CPUs busy while its refits run, but only one while it
fits the baseline; matplotlib's import (0.45-0.6 s of CPU) used to run in a thread during the refits.
:meth:`FigureProcess.start` forks a child at the start instead: it imports pyplot on the idle CPU
and waits; :meth:`FigureProcess.draw` sends it a plotting function and its arguments (pickled, through
a pipe) and waits until the child has written the figure.  When forking is not safe (see
:func:`femast.experiments.fe_jacobian._fork_ok`), or anything goes wrong on the way (an argument that
does not pickle, a failed draw), the caller draws the figure itself.
"""

from __future__ import annotations

import os
import pickle
import signal
import struct


class FigureProcess:
    """A forked child holding an imported pyplot, drawing one figure on request."""

    def __init__(self, pid: int, to_child: int, from_child: int):
        self.pid, self.to_child, self.from_child = pid, to_child, from_child

    @classmethod
    def start(cls):
        """Fork the child (it imports pyplot, then waits); None when forking is not safe here."""
        import gc

        from .fe_jacobian import _fork_ok

        if not _fork_ok(2):
            return None
        r1, w1 = os.pipe()  # requests: 8-byte length, pickled (function, args)
        r2, w2 = os.pipe()  # answer: one byte, 1 if the figure was written
        gc.freeze()  # (the child's collections skip the inherited heap: fewer copied pages)
        try:
            pid = os.fork()
        except OSError:
            gc.unfreeze()
            for fd in (r1, w1, r2, w2):
                os.close(fd)
            return None
        if pid == 0:
            _child(r1, w1, r2, w2)  # never returns
        gc.unfreeze()
        os.close(r1)
        os.close(w2)
        return cls(pid, w1, r2)

    def draw(self, fn, *args) -> bool:
        """``fn(*args)`` in the child; True once it has returned there, False if it could not be sent
        or failed (then nothing may have been written: draw it here)."""
        try:
            payload = pickle.dumps((fn, args), protocol=pickle.HIGHEST_PROTOCOL)
        except Exception:  # an argument that does not pickle (an experiment defined in memory)
            self.close()
            return False
        try:
            with os.fdopen(self.to_child, "wb") as fh:
                self.to_child = None
                fh.write(struct.pack("<Q", len(payload)))
                fh.write(payload)
            ok = _answer(self.from_child, FIGURE_WAIT_S) == b"1"
        except OSError:
            ok = False
        self.close()
        return ok

    def close(self) -> None:
        """End the child (if it is still waiting) and reap it."""
        for name in ("to_child", "from_child"):
            fd = getattr(self, name)
            if fd is not None:
                try:
                    os.close(fd)
                except OSError:
                    pass
                setattr(self, name, None)
        if self.pid:
            try:
                _, status = os.waitpid(self.pid, os.WNOHANG)
                if _ == 0:  # still importing, waiting or drawing (stuck): it has nothing left to do
                    os.kill(self.pid, signal.SIGKILL)
                    os.waitpid(self.pid, 0)
            except (ChildProcessError, ProcessLookupError, OSError):
                pass
            self.pid = 0


FIGURE_WAIT_S = 300.0  # s: a child that has not answered by then is taken for stuck (the caller draws;
#                        matplotlib's first import builds its font cache: tens of seconds)


def _answer(fd: int, wait_s: float) -> bytes:
    """The child's one-byte answer on ``fd``, or b"" if it closed the pipe or did not answer within
    ``wait_s`` seconds."""
    from .fe_jacobian import readable

    if not readable(fd, wait_s):
        return b""
    return os.read(fd, 1)


def _read_exactly(fh, n: int) -> bytes:
    data = fh.read(n)
    return data if data is not None and len(data) == n else b""


def _child(r1: int, w1: int, r2: int, w2: int) -> None:
    """The child: import pyplot, wait for one request, run it, answer, exit (without the parent's exit
    handlers)."""
    ok = b"0"
    try:
        os.close(w1)
        os.close(r2)
        os.environ["FEMAST_BACKGROUND_COMPILE"] = "0"  # (no requests to the parent's compile worker)
        from .. import progress
        from ..post.plotstyle import pyplot

        progress.set_quiet(True)
        pyplot()
        with os.fdopen(r1, "rb") as fh:
            head = _read_exactly(fh, 8)
            if head:
                payload = _read_exactly(fh, struct.unpack("<Q", head)[0])
                if payload:
                    fn, args = pickle.loads(payload)  # (from our own parent process)
                    fn(*args)
                    ok = b"1"
    except BaseException:  # the parent draws the figure itself
        ok = b"0"
    finally:
        try:
            os.write(w2, ok)
        except OSError:
            pass
        os._exit(0)
