"""A results folder that defends itself: femast's own files, written and read only inside it.

Everything femast writes into a results folder (the summary, the mesh, the frame log, the status
file, the restart point) goes through this module, which keeps four promises:

* **Only regular files femast created, only inside the folder.**  A sub-folder femast uses
  (``frames``, ``restart``) must be a real folder, not a symbolic link (a link could lead the
  writes, and the clean-up of an earlier run's files, anywhere on the disk); a file is opened with
  ``O_NOFOLLOW`` and must be a regular file; a temporary name is created afresh (``O_EXCL``).
* **Never deleting what femast did not write.**  :func:`remove_own` removes a regular file of one
  of femast's names; a symbolic link, a folder or a device of that name is refused with an error,
  not removed or followed.
* **One writer per folder.**  :class:`FolderLock` takes an exclusive lock (``flock``) on the
  folder's ``.femast.lock`` for as long as a run writes there; a second run into the same folder,
  or a restart of a run that is still going, is refused with :class:`~femast.errors.FolderInUseError`
  naming the folder and the process that holds it.  The operating system drops the lock when that
  process ends, however it ends (a kill -9 too): a stale lock file never blocks a later run.
* **Read back only from regular files, with bounds.**  :func:`open_regular` refuses a FIFO, a
  device or a symbolic link before reading a byte from it (a FIFO planted as ``summary.json``
  would otherwise block the reader forever), and :func:`read_json` parses at most
  :data:`MAX_JSON_BYTES`, with a FemastError for anything that is not JSON.

A write error (a full disk) is left to the caller, which turns it into a
:class:`~femast.errors.ResultsWriteError`.
"""

from __future__ import annotations

import errno
import json
import os
import socket
import stat
import time
from pathlib import Path

from ..errors import FemastError, FolderInUseError

LOCK_NAME = ".femast.lock"
MAX_JSON_BYTES = 16 * 2**20  # a summary, restart point or history line beyond this is not femast's
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_NONBLOCK = getattr(os, "O_NONBLOCK", 0)
_BINARY = getattr(os, "O_BINARY", 0)

try:  # advisory locks (POSIX); elsewhere a folder is not locked
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None


def _kind(mode: int) -> str:
    """What a file of mode ``mode`` is, in words."""
    if stat.S_ISLNK(mode):
        return "a symbolic link"
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    return "not a regular file"


def refusal(path, mode: int, doing: str, thing: str = "file") -> FemastError:
    """The FemastError refusing ``path`` (of ``os.lstat`` mode ``mode``): what it is, where a link points."""
    try:
        where = f" to {os.readlink(path)}" if stat.S_ISLNK(mode) else ""
    except OSError:
        where = ""
    own = "regular files" if thing == "file" else "folders"
    return FemastError(
        f"{path} is {_kind(mode)}{where}, not a {thing} femast made; femast {doing} only its own {own} "
        "inside the results folder: remove it, or give the run another folder"
    )


def own_dir(folder, name: str) -> Path:
    """The sub-folder ``name`` of ``folder`` (created if missing): a real folder, never a symbolic
    link, else a FemastError naming it."""
    path = Path(folder) / name
    try:
        os.mkdir(path)
    except FileExistsError:
        pass
    mode = os.lstat(path).st_mode
    if not stat.S_ISDIR(mode):  # a link (to a folder or not), a file, a FIFO...
        raise refusal(path, mode, "uses", "folder")
    return path


def lstat_or_none(path):
    """``os.lstat(path)`` or None if there is nothing at ``path``."""
    try:
        return os.lstat(path)
    except FileNotFoundError:
        return None


def remove_own(path) -> bool:
    """Remove ``path`` if it is a regular file (one of femast's, by its name); nothing there: False;
    a link, folder, FIFO or device of that name: a FemastError (neither removed nor followed)."""
    st = lstat_or_none(path)
    if st is None:
        return False
    if not stat.S_ISREG(st.st_mode):
        raise refusal(path, st.st_mode, "removes")
    try:
        os.unlink(path)
    except FileNotFoundError:
        return False
    return True


def open_write(path, append: bool = False, truncate: bool = False, read: bool = False) -> int:
    """A file descriptor of regular file ``path`` opened for writing (created if missing; appended to
    with ``append``; emptied with ``truncate``; readable too with ``read``), never through a symbolic
    link, never a FIFO or device."""
    st = lstat_or_none(path)
    if st is not None and not stat.S_ISREG(st.st_mode):
        raise refusal(path, st.st_mode, "writes")
    flags = (os.O_RDWR if read else os.O_WRONLY) | os.O_CREAT | _NOFOLLOW | _NONBLOCK | _BINARY
    flags |= (os.O_APPEND if append else 0) | (os.O_TRUNC if truncate else 0)
    fd = _open(path, flags, "writes")
    _regular_or_close(fd, path, "writes")
    return fd


def create_new(path) -> int:
    """A file descriptor of a new regular file ``path`` (a temporary name): a file of that name left by
    a killed run is removed first (if it is a regular file; anything else is refused)."""
    remove_own(path)
    return _open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW | _BINARY, "writes")


def _open(path, flags, doing, mode=0o666) -> int:
    try:
        return os.open(path, flags, mode)
    except OSError as exc:
        if exc.errno in (errno.ELOOP, errno.EMLINK, errno.ENXIO):  # a link under O_NOFOLLOW; a FIFO without reader
            st = lstat_or_none(path)
            if st is not None:
                raise refusal(path, st.st_mode, doing) from None
        raise


def _regular_or_close(fd: int, path, doing: str) -> None:
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        os.close(fd)
        raise refusal(path, mode, doing)
    if _NONBLOCK:
        os.set_blocking(fd, True)


def write_all(fd: int, data) -> None:
    """Write all of ``data`` to ``fd`` (looped over short writes)."""
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]


def write_atomic(path, data: bytes, sync: bool = False) -> None:
    """``data`` to ``path`` through the temporary ``<path>.tmp``, renamed into place (a reader sees
    the whole file or the previous one).  On an error the temporary file is removed and the error
    goes on (a full disk: an OSError the caller names)."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    st = lstat_or_none(path)
    if st is not None and not stat.S_ISREG(st.st_mode):  # (the rename would replace a link or FIFO)
        raise refusal(path, st.st_mode, "writes")
    fd = create_new(tmp)
    try:
        try:
            write_all(fd, data)
            if sync:
                os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def open_regular(path, doing: str = "reads"):
    """``path`` opened for reading in binary mode, if it is a regular file: a FIFO, a device or a
    symbolic link is refused (a FemastError) before anything is read; FileNotFoundError if missing."""
    st = os.lstat(path)
    if not stat.S_ISREG(st.st_mode):
        raise refusal(path, st.st_mode, doing)
    fd = _open(path, os.O_RDONLY | _NOFOLLOW | _NONBLOCK | _BINARY, doing)
    _regular_or_close(fd, path, doing)
    return os.fdopen(fd, "rb")


def is_regular(path) -> bool:
    """True if ``path`` is a regular file (not a link, folder, FIFO or device)."""
    st = lstat_or_none(path)
    return st is not None and stat.S_ISREG(st.st_mode)


def read_json(path, what: str = "file"):
    """The JSON value of regular file ``path``, or a FemastError naming it: not a regular file,
    larger than :data:`MAX_JSON_BYTES`, not JSON (nested beyond Python's recursion limit too)."""
    with open_regular(path) as fh:
        text = fh.read(MAX_JSON_BYTES + 1)
    if len(text) > MAX_JSON_BYTES:
        raise FemastError(f"{path}: the {what} is larger than {MAX_JSON_BYTES // 2**20} MB; it is not femast's")
    return parse_json(text, f"{path}", what)


def parse_json(text, where: str, what: str):
    """:func:`json.loads` of ``text``, or a FemastError naming ``where`` for a malformed value or one
    nested too deeply for the parser (a RecursionError)."""
    try:
        return json.loads(text)
    except (ValueError, RecursionError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise FemastError(f"{where}: the {what} is not valid JSON ({msg}); it is damaged or not femast's") from None


class FolderLock:
    """An exclusive lock on folder ``folder`` while a run writes there (see the module docstring):
    :meth:`acquire` or FolderInUseError naming the folder and the pid that holds it; :meth:`release`.
    ``what`` names the folder in the message ("results folder", "history folder")."""

    def __init__(self, folder, what: str = "results folder", name: str = LOCK_NAME):
        self.folder = Path(folder)
        self.what = what
        self.name = name
        self.fd = None

    def acquire(self, wait_s: float = 0.0) -> FolderLock:
        """Take the lock, waiting up to ``wait_s`` seconds for another holder to let it go."""
        if self.fd is not None or fcntl is None:
            return self
        path = self.folder / self.name
        st = lstat_or_none(path)
        if st is not None and not stat.S_ISREG(st.st_mode):
            raise refusal(path, st.st_mode, "locks")
        fd = _open(path, os.O_RDWR | os.O_CREAT | _NOFOLLOW | _NONBLOCK | _BINARY, "locks")
        _regular_or_close(fd, path, "locks")
        deadline = time.monotonic() + wait_s
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except OSError as exc:
                if exc.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                    os.close(fd)
                    raise
                if time.monotonic() < deadline:
                    time.sleep(0.02)
                    continue
                holder = _holder(fd)
                os.close(fd)
                waited = f" (waited {wait_s:g} s)" if wait_s else ""
                raise FolderInUseError(
                    f"{self.what} '{self.folder}' is being written by another femast run ({holder}){waited}; "
                    "wait for it to end, or give this one another folder"
                ) from None
        self.fd = fd
        try:  # who holds it, for the message of the next one (a full disk: the message says less)
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"pid {os.getpid()} on {socket.gethostname()}\n".encode(), 0)
        except OSError:
            pass
        return self

    def release(self) -> None:
        if self.fd is not None:
            fd, self.fd = self.fd, None
            try:
                fcntl.flock(fd, fcntl.LOCK_UN)
            finally:
                os.close(fd)

    def __enter__(self):
        return self.acquire()

    def __exit__(self, *exc):
        self.release()
        return False


def _holder(fd: int) -> str:
    """Who holds the lock, from the lock file ("pid N on HOST"), or "process unknown"."""
    try:
        text = os.pread(fd, 200, 0).decode("utf-8", errors="replace").strip()
    except OSError:
        text = ""
    return text if text.startswith("pid ") and text[4:].split(" ")[0].isdigit() else "process unknown"
