"""Results on disk, written increment by increment, readable without femast.

Layout of a results folder::

    mesh.npz              node labels, reference coordinates, element connectivity per family
    frames/frames.npzs    the frames: a record appended per converged increment (the record:
                          b"FEMASTFR", a little-endian uint64 n, n bytes of .npz; femast/post/npz.py)
    status.sta            one line per increment, like Abaqus' .sta file
    summary.json          the run's status: written at the start as ``"status": "running"``
                          (replacing any summary of an earlier run into the folder) and at the
                          end as "completed" (every step done), "failed" (an error; ``message``
                          says which) or "interrupted" (Ctrl-C or a stop)

The mesh and the summary are written to a temporary name and renamed into place (``os.replace``);
frames are appended to the frame log, so a run killed outright leaves at most a partial last
record, which :class:`Results` ignores with a warning.  Folders of one ``frames/NNNNNN.npz`` per
frame (written by femast 0.1 before the frame log) are read as before, and a restart from one converts them to a log.  A summary still saying "running" after its process has gone (a kill -9, a power cut)
is reported by :attr:`Results.status` as "interrupted".

Each frame holds: ``step`` (name), ``increment``, ``time`` (step time, s),
``total_time`` (s), ``load_factor``, ``iterations``, ``U`` (n, 3) displacements (m),
``R`` (n, 3, 3) nodal rotation matrices, ``UR`` (n, 3) rotation vectors (rad, |UR| <= pi),
``URA`` (n, 3) accumulated spins (rad; the total rotation for rotations about a fixed
axis, beyond 2 pi), ``RF`` (n, 6) reactions (N, N m), ``P`` (n, 6) applied loads, and
element outputs as ``el/<family>/<name>``.  Read them with :class:`Results`, or with
numpy alone (:func:`femast.post.npz.read_log`).

Durability: a frame is appended to the frame log, and its status line to ``status.sta``, in the
analysis' own thread the moment its increment converges, before the analysis tells anyone else
(``on_frame`` recorders, other observers) or starts the next increment.  Once written, the bytes
belong to the operating system: a process killed outright (kill -9, the OOM killer) loses no
increment it finished, and at most the record it was writing is cut short (ignored on reading).
Frames are not fsync'd one by one: the OS writes its cache to disk within seconds (Linux: ~30 s),
and only a power cut or an OS crash in that window can lose the last increments; call
:func:`os.sync` after a run that must survive one (restart points fsync the log before naming its
frames: :meth:`ResultsWriter.flush`).  An fsync per frame (1-10 ms on a VM's disk) would cost a
small model more than its increment.  A frame of a small model costs ~0.03 ms to encode and append (see
``Step.output_frequency`` and ``Analysis(out=None)``).  A write error (a full disk) raises
:class:`~femast.errors.ResultsWriteError` in the analysis at the frame that could not be written (or
at the start, if the mesh cannot be), and the summary says "failed".
"""

from __future__ import annotations

import io
import json
import os
import re
import socket
import struct
import time as _time
import warnings
from pathlib import Path

import numpy as np

from ..elements.base import DOF_NAMES
from ..errors import FemastError, ResultsWriteError
from .histories import Histories
from .npz import LOG_NAME, RECORD_MAGIC, TMP_SUFFIX, append_record, record_bytes, scan_log, truncate_log  # noqa: F401
from .npz import atomic_savez as _atomic_savez

_FRAME_NAME = re.compile(r"^\d+\.npz$")


def write_json_atomic(path: Path, data: dict) -> None:
    """Write ``data`` as JSON to ``path`` through a temporary file renamed into place."""
    path = Path(path)
    tmp = path.with_name(path.name + TMP_SUFFIX)
    with open(tmp, "w") as fh:
        json.dump(data, fh, indent=2, default=_json_default)
    # not fsync'd: the rename publishes a whole file to any reader, and a process kill loses nothing
    # written; the summary's durability against a power cut is that of the frames (module docstring)
    os.replace(tmp, path)


def _json_default(v):
    if isinstance(v, (np.integer,)):
        return int(v)
    return float(v)


def _process_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True  # exists but not ours, or cannot tell: assume alive
    return True


def prepare_folder(folder) -> Path:
    """Create results folder ``folder`` (and its ``frames``) or raise a FemastError naming it."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise FemastError(
            f"results folder '{folder}' is an existing file, not a folder; give out= a folder name (or remove the file)"
        )
    try:
        (folder / "frames").mkdir(parents=True, exist_ok=True)
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


def _log_from_files(frames: Path, log: Path) -> None:
    """The frame log of a folder written with one file per frame (an earlier femast): the whole
    frames in order, as records (a restarted run appends to it)."""
    names = sorted(p.name for p in frames.glob("*.npz") if _FRAME_NAME.match(p.name))
    with open(log, "wb") as fh:
        for n in names:
            data = (frames / n).read_bytes()
            fh.write(struct.pack("<8sQ", RECORD_MAGIC, len(data)) + data)


class ResultsWarning(UserWarning):
    """A results folder holds partial files or an unreadable summary (ignored)."""


class ResultsWriter:
    """Writes a results folder as the analysis runs (see module docstring): every frame and status
    line goes to the operating system (one ``write``) before :meth:`frame` / :meth:`status` return."""

    def __init__(self, folder, model, families, resume: int | None = None):
        """``resume``: continue a restarted run whose first ``resume`` frames are on disk (kept;
        later frames and partial files are removed; status lines are appended)."""
        self.folder = prepare_folder(folder)
        self._started = _time.time()
        self.count = resume or 0
        self._error = None
        self._log = self._sta = None
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
            raise ResultsWriteError(self._message(exc)) from exc
        except BaseException:
            self._close_files()
            raise

    def _start(self, model, families, resume):
        """The summary "running", the old frames cleared, the mesh, the frame log and status file opened."""
        # the stale summary of an earlier run goes first: a kill from here on leaves "running"
        write_json_atomic(self.folder / "summary.json", self._running())
        frames = self.folder / "frames"
        log = frames / LOG_NAME
        if resume is not None and not log.exists():  # a folder of one file per frame (femast < 0.x)
            _log_from_files(frames, log)
        for pattern in ("*.npz", "*" + TMP_SUFFIX):  # one-file-per-frame frames of an earlier run
            for old in frames.glob(pattern):
                old.unlink()
        if resume is None:  # an earlier run's restart point does not belong to this run's frames
            log.unlink(missing_ok=True)
            (self.folder / "restart" / "restart.json").unlink(missing_ok=True)
        elif truncate_log(log, resume) < resume:
            raise FemastError(
                f"{self.folder}: the restart point names {resume} frames but fewer are on disk; "
                "run the analysis again from the start"
            )
        (self.folder / ("mesh.npz" + TMP_SUFFIX)).unlink(missing_ok=True)
        mesh = {
            "node_labels": model.node_labels,
            "X": model.coordinates,
            "families": np.array([f.name for f in families]),
        }
        for f in families:
            mesh[f"conn/{f.name}"] = model.node_labels[np.asarray(f.nodes)]
            mesh[f"labels/{f.name}"] = np.asarray(getattr(f, "labels", np.arange(1, f.n_elements + 1)))
        _atomic_savez(self.folder / "mesh.npz", **mesh)  # (replaces an earlier run's)
        self._log = os.open(log, _APPEND, 0o666)
        self._sta = os.open(self.folder / "status.sta", _APPEND | (0 if resume is not None else os.O_TRUNC), 0o666)
        if resume is not None:
            self._write_line(f"{'':>12} restarted from frame {resume}\n")
        else:
            self._write_line(
                f"{'STEP':>12} {'INC':>5} {'ATT':>3} {'ITER':>4} {'STEP TIME':>11} "
                f"{'TOTAL TIME':>11} {'INC TIME':>11} {'LOAD FACTOR':>12}  NOTE\n"
            )

    def status(self, step, inc, attempt, iterations, time, total_time, dtime, lam, note=""):
        """Write one status line to ``status.sta`` (one unbuffered append)."""
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
        try:
            append_record(self._log, record_bytes(data))
        except OSError as exc:
            self._failed(exc)
        self.count += 1

    def append(self, record: bytes):
        """Append one frame already encoded as a frame-log record (:class:`~femast.post.frame_coder.FrameCoder`)."""
        try:
            append_record(self._log, record)
        except OSError as exc:
            self._failed(exc)
        self.count += 1

    def _message(self, exc) -> str:
        return (
            f"could not write results to '{self.folder}': {exc.strerror or exc}; free disk space or give "
            "the analysis another results folder (out=)"
        )

    def _failed(self, exc):
        self._error = exc
        raise ResultsWriteError(self._message(exc)) from exc

    def flush(self):
        """Make the frames written so far durable: fsync of the frame log (they are already the
        operating system's, written as they came).  A restart point calls this before it names them
        (restart.py fsyncs its own files too), so that it holds after a power cut as well; one
        fsync per restart point, none per frame."""
        if self._log is not None:
            os.fsync(self._log)

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

    def close(self, summary: dict):
        """Close the frame log and the status file and write the final summary (``summary["status"]``
        says how the run ended; "failed" if a frame could not be written)."""
        self._close_files()
        self._write_summary(summary)

    def _write_summary(self, summary: dict):
        final = {**summary, "pid": os.getpid(), "host": socket.gethostname(), "started": self._started}
        if self._error is not None and final.get("status") == "completed":
            final.update(status="failed", completed=False, message=f"ResultsWriteError: {self._message(self._error)}")
        write_json_atomic(self.folder / "summary.json", final)


_APPEND = os.O_WRONLY | os.O_CREAT | os.O_APPEND | getattr(os, "O_BINARY", 0)


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


class Results(Histories):
    """Read a results folder: ``Results("results/run")``.

    ``len(results)`` frames (converged increments, frame 0 is the initial state);
    ``results.frame(i)`` a dict of arrays (SI units: m, rad, N, N m), ``results.frame(step="load")``
    the last frame of a step; ``results.node_history(label, "uz")`` a history over the frames
    (components ux uy uz in m, rx ry rz accumulated rotations in rad, rfx..rfz reactions in N,
    rmx..rmz in N m, fx..mz applied loads); ``results.element_history(family, label, name)``;
    ``results.time`` the total time of each frame, ``results.steps`` the step name of each frame.
    """

    def __init__(self, folder):
        self.folder = Path(folder)
        mesh_file = self.folder / "mesh.npz"
        if not mesh_file.exists():
            raise FemastError(f"{self.folder}: not a femast results folder (no mesh.npz); run an analysis first")
        self._mesh = None  # read on first use (an analysis returns its Results: ~1.5 ms per run saved)
        frames = self.folder / "frames"
        names = sorted(p.name for p in frames.iterdir()) if frames.is_dir() else []
        log = frames / LOG_NAME
        if LOG_NAME in names:  # the frame log: a record per frame
            records, rest = scan_log(log)
            self.files = [(log, offset, length) for offset, length in records]
            self.partial = [f"{LOG_NAME} (a partial last frame, {rest} bytes)"] if rest else []
        else:  # one file per frame (folders written before the log)
            self.files = [frames / n for n in names if _FRAME_NAME.match(n)]
            self.partial = [n for n in names if not _FRAME_NAME.match(n)]
        if self.partial:
            warnings.warn(
                f"{self.folder}: ignoring {len(self.partial)} partial or foreign file(s) in frames/ "
                f"({', '.join(self.partial[:5])}{', ...' if len(self.partial) > 5 else ''}"
                "): left by a run that was killed (or whose disk filled up) while writing",
                ResultsWarning,
                stacklevel=2,
            )
        self._cache = {}
        sfile = self.folder / "summary.json"
        self.summary = None
        if sfile.exists():
            try:
                self.summary = json.loads(sfile.read_text())
            except (ValueError, OSError) as exc:
                warnings.warn(
                    f"{sfile}: unreadable summary ({exc}); the run's outcome is unknown", ResultsWarning, stacklevel=2
                )
            else:
                if not isinstance(self.summary, dict):
                    self.summary = None

    @property
    def status(self) -> str:
        """How the run that wrote the folder ended: "completed", "failed", "interrupted",
        "running" (its process is still alive) or "unknown" (no summary).  A summary saying
        "running" whose process is gone (killed) reads "interrupted"."""
        s = self.summary
        if not s:
            return "unknown"
        status = s.get("status") or ("completed" if s.get("completed") else "failed")
        if status == "running":
            same_host = s.get("host") == socket.gethostname()
            if same_host and isinstance(s.get("pid"), int) and not _process_alive(s["pid"]):
                return "interrupted"
        return status

    def __len__(self):
        return len(self.files)

    @property
    def mesh(self) -> dict:
        """The arrays of mesh.npz: node_labels, X (m), families, conn/<family>, labels/<family>."""
        if self._mesh is None:
            try:
                with np.load(self.folder / "mesh.npz", allow_pickle=False) as m:
                    self._mesh = {k: m[k] for k in m.files}
            except Exception as exc:
                raise FemastError(
                    f"{self.folder / 'mesh.npz'} is unreadable ({type(exc).__name__}: {exc}); "
                    "the folder is damaged: rerun the analysis"
                ) from None
        return self._mesh

    @property
    def node_labels(self) -> np.ndarray:
        return self.mesh["node_labels"]

    @property
    def X(self) -> np.ndarray:
        """Reference nodal coordinates (m)."""
        return self.mesh["X"]

    @property
    def families(self) -> list[str]:
        return [str(f) for f in self.mesh["families"]]

    def frame(self, i: int | None = None, *, step: str | None = None, index: int = -1) -> dict:
        """The arrays of frame ``i`` (0 = initial state; negative counts from the end), or with
        ``step``, frame ``index`` of that step (``res.frame(step="load")``: its last converged
        increment; ``index=0`` its first; :meth:`frame_number` gives the frame's number)."""
        if step is not None:
            if i is not None:
                raise FemastError("give a frame number or step=NAME (with index=), not both")
            i = self.frame_number(step, index)
        elif i is None:
            raise FemastError("give a frame number (0 = initial state, -1 = last) or step=NAME")
        try:
            i = range(len(self.files))[int(i)]
        except IndexError:
            raise FemastError(
                f"{self.folder}: frame {i} does not exist; the folder has {len(self.files)} frames "
                f"(0..{len(self.files) - 1}, or -1 for the last)"
            ) from None
        if i not in self._cache:
            src = self.files[i]
            try:
                if isinstance(src, tuple):  # a record of the frame log
                    with open(src[0], "rb") as fh:
                        fh.seek(src[1])
                        src = io.BytesIO(fh.read(src[2]))
                with np.load(src, allow_pickle=False) as f:
                    self._cache[i] = {k: f[k] for k in f.files}
            except Exception as exc:  # zipfile.BadZipFile, EOFError, ValueError, OSError...
                where = self.files[i] if not isinstance(self.files[i], tuple) else self.files[i][0]
                raise FemastError(
                    f"{where}: frame {i} is unreadable ({type(exc).__name__}: {exc}); "
                    "the file is damaged: rerun the analysis"
                ) from None
        return self._cache[i]


DOF_COMPONENTS = DOF_NAMES


def run_outcome(exc: BaseException) -> tuple[str, str]:
    """(status, message) of a run ended by ``exc``: "interrupted" for Ctrl-C or a stop
    (KeyboardInterrupt, SystemExit), else "failed" with the error as the reason."""
    if isinstance(exc, (KeyboardInterrupt, SystemExit)):
        return "interrupted", f"interrupted ({type(exc).__name__}) before the last increment"
    if isinstance(exc, FemastError):
        return "failed", f"{type(exc).__name__}: {exc}"
    return "failed", f"unexpected {type(exc).__name__}: {exc}"
