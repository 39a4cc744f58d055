"""Writing a results folder as the analysis runs: the summary, the mesh, the frame log, the status
file (the layout and the durability promises: femast/post/results.py; the folder's own defences:
femast/post/folder.py).

:class:`ResultsWriter` is the one writer of a folder: it locks the folder for the run, writes the
summary "running" first (padded to :data:`SUMMARY_RESERVE` bytes, so that a final summary can be
written over it even on a full disk), removes what an earlier run of the folder left (only femast's
own files), writes the mesh, and appends every frame and status line the moment it is given.  A
write error is a :class:`~femast.errors.ResultsWriteError` naming the folder, and the summary says
"failed".
"""

from __future__ import annotations

import errno
import json
import os
import re
import socket
import struct
import time as _time
from pathlib import Path

import numpy as np

from ..errors import FemastError, ResultsWriteError
from .folder import (
    FolderLock,
    create_new,
    lstat_or_none,
    open_regular,
    open_write,
    own_dir,
    remove_own,
    write_all,
    write_atomic,
)
from .npz import LOG_NAME, RECORD_MAGIC, TMP_SUFFIX, append_record, record_bytes, truncate_log
from .npz import atomic_savez as _atomic_savez

_FRAME_NAME = re.compile(r"^\d+\.npz$")


def write_json_atomic(path: Path, data: dict, sync: bool = False) -> None:
    """Write ``data`` as JSON to ``path`` through a temporary file renamed into place (femast/post/folder.py:
    never through a link; the temporary file removed on an error; fsync'd with ``sync``)."""
    write_atomic(path, json.dumps(data, indent=2, default=_json_default).encode(), sync=sync)


def _json_default(v):
    if isinstance(v, (np.integer,)):
        return int(v)
    return float(v)


def prepare_folder(folder) -> Path:
    """Create results folder ``folder`` (and its ``frames``) or raise a FemastError naming it."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise FemastError(
            f"results folder '{folder}' is an existing file, not a folder; give out= a folder name (or remove the file)"
        )
    try:
        folder.mkdir(parents=True, exist_ok=True)
        own_dir(folder, "frames")
    except (FileExistsError, NotADirectoryError):
        raise FemastError(
            f"results folder '{folder}': a part of the path is an existing file; give out= a "
            "folder whose parents are folders"
        ) from None
    except PermissionError as exc:
        raise FemastError(
            f"results folder '{folder}': no permission to create it ({exc.strerror}); choose a folder you can write to"
        ) from None
    except OSError as exc:
        raise FemastError(
            f"results folder '{folder}' cannot be created ({exc.strerror or exc}); choose another folder"
        ) from None
    return folder


def lock_folder(folder) -> FolderLock:
    """The results folder ``folder`` created and locked for one run (FolderInUseError if another run
    writes there); release it with ``.release()``."""
    return FolderLock(prepare_folder(folder)).acquire()


def _log_from_files(frames: Path, log: Path) -> None:
    """The frame log of a folder written with one file per frame (an earlier femast): the whole
    frames in order, as records (a restarted run appends to it)."""
    names = sorted(p.name for p in frames.iterdir() if _FRAME_NAME.match(p.name))
    fd = create_new(log)
    try:
        for n in names:
            with open_regular(frames / n) as fh:
                data = fh.read()
            write_all(fd, struct.pack("<8sQ", RECORD_MAGIC, len(data)) + data)
    finally:
        os.close(fd)


SUMMARY_RESERVE = 4096  # bytes of the "running" summary (padded): a final summary that fits replaces it in place
_OLD_FRAME_FILE = re.compile(r"^\d+\.npz(\.tmp)?$")  # frames/NNNNNN.npz of an earlier femast, and their partial files


class ResultsWriter:
    """Writes a results folder as the analysis runs (see module docstring): every frame and status
    line goes to the operating system (one ``write``) before :meth:`frame` / :meth:`status` return.
    The folder is locked for the writer's life (``lock``: a :class:`FolderLock` the caller holds, else
    its own); femast/post/folder.py says what else it guarantees."""

    def __init__(self, folder, model, families, resume: int | None = None, lock: FolderLock | None = None):
        """``resume``: continue a restarted run whose first ``resume`` frames are on disk (kept;
        later frames and partial files are removed; status lines are appended)."""
        self.folder = prepare_folder(folder)
        self._own_lock = lock is None
        self._lock = FolderLock(self.folder).acquire() if lock is None else lock
        self._started = _time.time()
        self.count = resume or 0
        self._error = None
        self._log = self._sta = None
        self._log_end = None  # bytes of whole records in the frame log (a failed append is cut off there)
        try:
            self._start(model, families, resume)
        except OSError as exc:  # a full disk, a read-only folder: named, and the summary says "failed"
            self._close_files()
            self._error = exc
            try:
                self._write_summary(
                    {"status": "failed", "completed": False, "message": f"ResultsWriteError: {self._message(exc)}"}
                )
            except OSError:
                pass
            self._release()
            raise ResultsWriteError(self._message(exc)) from exc
        except BaseException as exc:
            self._close_files()
            if isinstance(exc, FemastError):  # (a link or FIFO where femast writes: the summary says why)
                try:
                    self._write_summary({"status": "failed", "completed": False, "message": f"FemastError: {exc}"})
                except (OSError, FemastError):
                    pass
            self._release()
            raise

    def _start(self, model, families, resume):
        """The summary "running", the old frames cleared, the mesh, the frame log and status file opened."""
        # the stale summary of an earlier run goes first: a kill from here on leaves "running"
        self._write_summary(self._running(), padded=True)
        frames = own_dir(self.folder, "frames")
        log = frames / LOG_NAME
        if resume is not None and lstat_or_none(log) is None:  # a folder of one file per frame (femast < 0.x)
            _log_from_files(frames, log)
        for old in sorted(frames.iterdir()):  # one-file-per-frame frames of an earlier run, partial files
            if _OLD_FRAME_FILE.match(old.name) or old.name == LOG_NAME + TMP_SUFFIX:
                remove_own(old)
        if resume is None:  # an earlier run's frames and restart point do not belong to this run's
            remove_own(log)
            if lstat_or_none(self.folder / "restart") is not None:
                remove_own(own_dir(self.folder, "restart") / "restart.json")
        elif resume < 1 or truncate_log(log, resume) < resume:
            raise FemastError(
                f"{self.folder}: the restart point names {resume} frames but fewer are on disk; "
                "run the analysis again from the start"
            )
        mesh = {
            "node_labels": model.node_labels,
            "X": model.coordinates,
            "families": np.array([f.name for f in families]),
        }
        for f in families:
            mesh[f"conn/{f.name}"] = model.node_labels[np.asarray(f.nodes)]
            mesh[f"labels/{f.name}"] = np.asarray(getattr(f, "labels", np.arange(1, f.n_elements + 1)))
        _atomic_savez(self.folder / "mesh.npz", **mesh)  # (replaces an earlier run's)
        self._log = open_write(log, append=True)
        self._log_end = os.lseek(self._log, 0, os.SEEK_END)
        self._sta = open_write(self.folder / "status.sta", append=True, truncate=resume is None)
        if resume is not None:
            self._write_line(f"{'':>12} restarted from frame {resume}\n")
        else:
            self._write_line(
                f"{'STEP':>12} {'INC':>5} {'ATT':>3} {'ITER':>4} {'STEP TIME':>11} "
                f"{'TOTAL TIME':>11} {'INC TIME':>11} {'LOAD FACTOR':>12}  NOTE\n"
            )

    def status(self, step, inc, attempt, iterations, time, total_time, dtime, lam, note=""):
        """Write one status line to ``status.sta`` (one unbuffered append; a note of one line, at most
        :data:`NOTE_CHARS` characters)."""
        note = " ".join(str(note).split())
        if len(note) > NOTE_CHARS:
            note = note[: NOTE_CHARS - 3] + "..."
        self._write_line(
            f"{step:>12.12} {inc:5d} {attempt:3d} {iterations:4d} {time:11.4e} {total_time:11.4e} "
            f"{dtime:11.4e} {lam:12.5e}  {note}\n"
        )

    def _write_line(self, line: str):
        try:
            append_record(self._sta, line.encode())
        except OSError as exc:
            self._failed(exc)

    def frame(self, **data):
        """Append one frame to the frame log: on return its bytes are the operating system's (a
        process killed from then on loses nothing of it).  Arrays may be modified afterwards."""
        self.append(record_bytes(data))

    def append(self, record: bytes):
        """Append one frame already encoded as a frame-log record (:class:`~femast.post.frame_coder.FrameCoder`)."""
        try:
            append_record(self._log, record)
        except OSError as exc:
            try:  # the part of the record that was written goes (it frees the space the summary needs)
                os.ftruncate(self._log, self._log_end)
            except OSError:
                pass
            self._failed(exc)
        self._log_end += len(record)
        self.count += 1

    def _message(self, exc) -> str:
        return (
            f"could not write results to '{self.folder}': {exc.strerror or exc}; free disk space or give "
            "the analysis another results folder (out=)"
        )

    def _failed(self, exc):
        self._error = exc
        raise ResultsWriteError(self._message(exc)) from exc

    def write_file(self, path, data: bytes, sync: bool = False):
        """Write ``data`` to ``path`` inside the folder, atomically (a restart point's files:
        femast/post/folder.py), or a ResultsWriteError."""
        try:
            write_atomic(path, data, sync=sync)
        except OSError as exc:
            self._failed(exc)

    def flush(self):
        """Make the frames written so far durable: fsync of the frame log (they are already the
        operating system's, written as they came).  A restart point calls this before it names them
        (restart.py fsyncs its own files too), so that it holds after a power cut as well; one
        fsync per restart point, none per frame."""
        if self._log is not None:
            try:
                os.fsync(self._log)
            except OSError as exc:
                self._failed(exc)

    def _running(self) -> dict:
        return {
            "status": "running",
            "completed": False,
            "pid": os.getpid(),
            "host": socket.gethostname(),
            "started": self._started,
            "message": "the analysis is running (or its process was killed before it could finish)",
        }

    def _close_files(self):
        for fd in (self._log, self._sta):
            if fd is not None:
                os.close(fd)
        self._log = self._sta = None

    def _release(self):
        if self._own_lock:
            self._lock.release()

    def close(self, summary: dict):
        """Close the frame log and the status file and write the final summary (``summary["status"]``
        says how the run ended; "failed" if a frame could not be written); a ResultsWriteError if the
        summary cannot be written at all."""
        try:
            self._close_files()
            self._write_summary(summary)
        except OSError as exc:
            self._error = exc
            raise ResultsWriteError(self._message(exc)) from exc
        finally:
            self._release()

    def _write_summary(self, summary: dict, padded: bool = False):
        """The summary, atomically; ``padded``: to :data:`SUMMARY_RESERVE` bytes with blanks (JSON
        allows them), so that on a full disk the final one can still be written over it in place."""
        final = {**summary, "pid": os.getpid(), "host": socket.gethostname(), "started": self._started}
        if self._error is not None and final.get("status") == "completed":
            final.update(status="failed", completed=False, message=f"ResultsWriteError: {self._message(self._error)}")
        path = self.folder / "summary.json"
        text = json.dumps(final, indent=2, default=_json_default).encode()
        if padded:
            text += b" " * (SUMMARY_RESERVE - len(text) - 1) + b"\n"
        try:
            write_atomic(path, text)
        except OSError as exc:
            if exc.errno != errno.ENOSPC or padded:
                raise
            self._summary_in_place(path, final)

    def _summary_in_place(self, path, final: dict):
        """A full disk: the summary written over the padded "running" one, in blocks the file already
        has (the steps' list left out, the message shortened, if that is what it takes to fit)."""
        short = {k: final[k] for k in ("status", "completed", "increments", "iterations", "cutbacks") if k in final}
        short.update(pid=final["pid"], host=final["host"], message=str(final.get("message", ""))[:2000])
        short["message"] += " (the disk was full: the summary is shortened)"
        text = json.dumps(short).encode()
        while len(text) >= SUMMARY_RESERVE and short["message"]:
            short["message"] = short["message"][: len(short["message"]) // 2]
            text = json.dumps(short).encode()
        fd = open_write(path)
        try:
            if os.fstat(fd).st_size < len(text):
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
            os.pwrite(fd, text + b" " * (os.fstat(fd).st_size - len(text)), 0)
        finally:
            os.close(fd)


NOTE_CHARS = 300  # the longest note of a status line (an error's text is cut there)


class NullWriter:
    """The writer of an analysis with ``out=None``: keeps nothing (frames go only to on_frame)."""

    count = 0

    def status(self, *args, **kwargs):
        pass

    def frame(self, **data):
        self.count += 1

    def flush(self):
        pass

    def close(self, summary: dict):
        pass
