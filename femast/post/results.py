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
import os
import re
import socket
import warnings
from pathlib import Path

import numpy as np

from ..elements.base import DOF_NAMES
from ..errors import FemastError
from .folder import (
    lstat_or_none,
    open_regular,
    own_dir,
    read_json,
)
from .histories import Histories
from .npz import LOG_NAME, RECORD_MAGIC, TMP_SUFFIX, append_record, record_bytes, scan_log, truncate_log  # noqa: F401
from .summary_check import check_summary

_FRAME_NAME = re.compile(r"^\d+\.npz$")


def _process_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True  # exists but not ours, or cannot tell: assume alive
    return True


class ResultsWarning(UserWarning):
    """A results folder holds partial files or an unreadable summary (ignored)."""


from .writer import (  # noqa: E402,F401 (the writer's names, where they were)
    SUMMARY_RESERVE,
    NullWriter,
    ResultsWriter,
    _log_from_files,
    lock_folder,
    prepare_folder,
    write_json_atomic,
)


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
        if self.folder.exists() and not self.folder.is_dir():
            raise FemastError(f"{self.folder} is a file, not a results folder; give the folder an analysis wrote")
        if lstat_or_none(self.folder / "mesh.npz") is None:
            raise FemastError(f"{self.folder}: not a femast results folder (no mesh.npz); run an analysis first")
        self._mesh = None  # read on first use (an analysis returns its Results: ~1.5 ms per run saved)
        frames = self.folder / "frames"
        names = sorted(p.name for p in own_dir(self.folder, "frames").iterdir()) if lstat_or_none(frames) else []
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
        if lstat_or_none(sfile) is not None:
            try:
                self.summary = check_summary(read_json(sfile, "summary"), sfile)
            except (FemastError, OSError) as exc:
                warnings.warn(
                    f"{exc if isinstance(exc, FemastError) else f'{sfile}: unreadable summary ({exc})'}; "
                    "the run's outcome is unknown",
                    ResultsWarning,
                    stacklevel=2,
                )

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
                with open_regular(self.folder / "mesh.npz") as fh, np.load(fh, allow_pickle=False) as m:
                    self._mesh = {k: m[k] for k in m.files}
            except FemastError:
                raise
            except Exception as exc:
                raise FemastError(
                    f"{self.folder / 'mesh.npz'} is unreadable ({unreadable(exc)}); "
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
                with open_regular(src[0] if isinstance(src, tuple) else src) as fh:
                    if isinstance(src, tuple):  # a record of the frame log
                        fh.seek(src[1])
                    data = io.BytesIO(fh.read(src[2] if isinstance(src, tuple) else -1))
                with np.load(data, allow_pickle=False) as f:
                    self._cache[i] = {k: f[k] for k in f.files}
            except FemastError:
                raise
            except Exception as exc:  # zipfile.BadZipFile, EOFError, ValueError, OSError...
                where = self.files[i] if not isinstance(self.files[i], tuple) else self.files[i][0]
                raise FemastError(
                    f"{where}: frame {i} is unreadable ({unreadable(exc)}); the file is damaged: rerun the analysis"
                ) from None
        return self._cache[i]


DOF_COMPONENTS = DOF_NAMES


def unreadable(exc: Exception) -> str:
    """Why an array file is unreadable, in words (never numpy's hint to load pickled data unsafely)."""
    if isinstance(exc, ValueError) and "pickle" in str(exc):
        return "it holds pickled Python objects, which femast never loads: it is not a file femast wrote"
    return f"{type(exc).__name__}: {exc}"


def run_outcome(exc: BaseException) -> tuple[str, str]:
    """(status, message) of a run ended by ``exc``: "interrupted" for Ctrl-C or a stop
    (KeyboardInterrupt, SystemExit), else "failed" with the error as the reason."""
    if isinstance(exc, (KeyboardInterrupt, SystemExit)):
        return "interrupted", f"interrupted ({type(exc).__name__}) before the last increment"
    if isinstance(exc, FemastError):
        return "failed", f"{type(exc).__name__}: {exc}"
    return "failed", f"unexpected {type(exc).__name__}: {exc}"
