"""Where numba caches femast's kernels: a folder keyed by the kernels' sources in a source checkout.

numba's on-disk cache (``cache=True``) checks only the source file that *defines* a kernel.  A
kernel that calls (or inlines) an njit helper of another file embeds the helper's compiled code,
so after an edit of the helper -- a ``git pull`` in an editable install -- the callers in other
files would keep running the old helper, silently (numba issue #1833).

An installed package (a wheel under ``site-packages``) never changes one file at a time: an
update rewrites every file, which invalidates every cache entry, so nothing is done there.  In a
source checkout (an editable install, or the tree on ``PYTHONPATH``), :func:`configure`, called
once by ``import femast``, points numba's cache at a folder named after a SHA-1 of the package's
numba sources (every ``.py`` file with a numba-compiled function)::

    femast/__pycache__/numba-<key>/          (or $NUMBA_CACHE_DIR/femast-<key>/ when that is set)

through ``numba.config.CACHE_DIR``, numba's public setting behind ``NUMBA_CACHE_DIR``.  An edit
of any kernel or helper gives a new key, so a new, empty folder: every kernel is compiled afresh
once, and no stale helper can be loaded.  The three newest ``numba-*`` folders of the checkout are
kept; older ones are deleted when a new one is made.  Nothing else is read, written or deleted,
and nothing at all happens in an installed package.  Note that ``numba.config.CACHE_DIR`` is
process-wide: in a source checkout of femast, the cache files of the caller's own kernels go to
the same folder.  ``FEMAST_NUMBA_CACHE_GUARD=0`` leaves numba's settings alone.
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil

ENV = "FEMAST_NUMBA_CACHE_GUARD"
KEEP = 3  # newest keyed folders kept in a checkout's __pycache__
_PREFIX = "numba-"


def is_source_checkout(root: str) -> bool:
    """``root`` is not inside an installation folder (``site-packages`` / ``dist-packages``)."""
    parts = os.path.normcase(os.path.abspath(root)).split(os.sep)
    return not any(p in ("site-packages", "dist-packages") for p in parts)


# a decorator naming a numba compiler (``@njit``, ``@numba.njit(...)``, ``@intrinsic``...) or a call
# ``njit(...)``: the file compiles code that cached kernels may embed
_COMPILES = re.compile(
    rb"^[ \t]*@[ \t]*(?:\w+\.)*(?:njit|jit|vectorize|guvectorize|intrinsic|overload\w*|cfunc|stencil)\b|\bnjit\(", re.M
)


def source_key(root: str) -> str:
    """SHA-1 (16 hex digits) of the relative paths and contents of the ``.py`` files under
    ``root`` that compile code with numba (``__pycache__`` and hidden folders skipped)."""
    h = hashlib.sha1()
    for dirpath, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__" and not d.startswith("."))
        for name in sorted(files):
            if not name.endswith(".py"):
                continue
            path = os.path.join(dirpath, name)
            try:
                with open(path, "rb") as fh:
                    data = fh.read()
            except OSError:
                continue
            if _COMPILES.search(data):
                h.update(os.path.relpath(path, root).encode() + b"\0" + data + b"\0")
    return h.hexdigest()[:16]


def _writable_folder(path: str) -> bool:
    try:
        os.makedirs(path, exist_ok=True)
    except OSError:
        return False
    return os.access(path, os.W_OK | os.X_OK)


def _prune(parent: str, keep: str) -> None:
    """Delete the ``numba-*`` folders of ``parent`` beyond the :data:`KEEP` newest (never ``keep``)."""
    try:
        entries = [e for e in os.scandir(parent) if e.name.startswith(_PREFIX) and e.is_dir(follow_symlinks=False)]
    except OSError:
        return
    entries.sort(key=lambda e: e.stat(follow_symlinks=False).st_mtime, reverse=True)
    for e in entries[KEEP:]:
        if os.path.abspath(e.path) != os.path.abspath(keep):
            shutil.rmtree(e.path, ignore_errors=True)  # (another process may be deleting it too)


def configure(root: str | None = None, package: str | None = None) -> str | None:
    """Point numba's cache at the keyed folder of the source checkout ``root`` (default: femast);
    returns the folder, or None when nothing was changed (an installed package, the guard off, no
    writable folder)."""
    if os.environ.get(ENV, "1").strip().lower() in ("0", "no", "off", "false"):
        return None
    root = os.path.dirname(os.path.abspath(__file__)) if root is None else os.path.abspath(root)
    package = os.path.basename(root) if package is None else package
    if not is_source_checkout(root):
        return None
    key = source_key(root)
    user_dir = os.environ.get("NUMBA_CACHE_DIR", "").strip()
    if user_dir:
        folder, parent = os.path.join(user_dir, f"{package}-{key}"), None  # shared: others' folders stay
    else:
        parent = os.path.join(root, "__pycache__")
        folder = os.path.join(parent, _PREFIX + key)
    new = not os.path.isdir(folder)
    if not _writable_folder(folder):
        return None
    from numba import config

    config.CACHE_DIR = folder
    if new and parent is not None:
        _prune(parent, folder)
    return folder
