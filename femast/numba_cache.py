"""Stale numba caches after an edit of a helper in another file: found and deleted at import.

numba's on-disk cache (``cache=True``) checks only the source file that *defines* a kernel (its
index stores that file's hash).  A kernel that calls (or inlines) an njit helper of another module
embeds the helper's compiled code, so after an edit of the helper -- a ``git pull`` in an editable
install -- the callers in other files keep running the old helper, silently (numba issue #1833;
the fix, numba PR #8396, is not merged).

:func:`check`, run once at ``import femast`` (before any kernel is loaded: numba loads a kernel's
cache at its first call), guards against that:

1. fast path: a stamp of the package's ``.py`` files (path, mtime, size, inode) equal to the one
   recorded in the cache directory of the package's ``__init__.py`` -> nothing to do (~1.3 ms);
2. otherwise, for each module holding cached kernels (its text contains ``cache=True``), the
   modules it imports from that define numba functions (a decorator ``*jit*``, ``intrinsic``,
   ``overload``..., or ``name = njit(...)(f)``), transitively, from the ``ast`` of the import
   statements (an over-approximation: any name imported from such a module counts); a SHA-1 of their *contents* (so a checkout that only touches mtimes deletes
   nothing) is compared with the one recorded beside that module's cache (``<stem>.femast-deps``);
   when it differs, that module's ``<stem>.*.nbi`` / ``<stem>.*.nbc`` files are deleted and the new
   stamp recorded (~25 ms for femast).  The cache directory is numba's own (its cache locator: ``__pycache__`` beside
   the file, ``NUMBA_CACHE_DIR``, or the user-wide one).

A cache directory that is not writable (a read-only install) is skipped quietly; files another
process deleted first are ignored (two processes starting at once).  ``FEMAST_NUMBA_CACHE_GUARD=0``
turns the guard off.
"""

from __future__ import annotations

import ast
import hashlib
import os
import re

ENV = "FEMAST_NUMBA_CACHE_GUARD"
TREE_STAMP = "__femast_tree__.stamp"  # in the cache directory of the package's __init__.py
DEPS_SUFFIX = ".femast-deps"  # beside a module's cache files: <stem>.femast-deps


def _py_files(root: str) -> list[str]:
    """The ``.py`` files under ``root`` (``__pycache__`` and hidden directories skipped), sorted."""
    out, todo = [], [root]
    while todo:
        d = todo.pop()
        try:
            entries = list(os.scandir(d))
        except OSError:
            continue
        for e in entries:
            if e.name.endswith(".py"):
                out.append(e.path)
            elif e.name != "__pycache__" and not e.name.startswith(".") and e.is_dir():
                todo.append(e.path)
    return sorted(out)


def tree_stamp(root: str, files: list[str]) -> str:
    """SHA-1 of the (path, mtime ns, size, inode) of ``files``: changes on any edit."""
    n = len(root)
    parts = []
    for f in files:
        try:
            st = os.stat(f)
        except OSError:
            continue
        parts.append(f"{f[n:]}\0{st.st_mtime_ns}\0{st.st_size}\0{st.st_ino}")
    return hashlib.sha1("\n".join(parts).encode()).hexdigest()


def _module_name(root: str, package: str, path: str) -> str:
    parts = os.path.relpath(path, root)[:-3].split(os.sep)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join([package, *parts])


# The import statements (a parenthesised list may span lines; backslash continuations are not
# followed), decorators and module-level ``name = njit(...)(f)`` of a module, found line by line:
# ~50x cheaper than parsing whole modules, which matters each time the tree changes.
_IMPORT = re.compile(r"^[ \t]*(from[ \t]+[\w.]+[ \t]+import[ \t]+(?:\([^)]*\)|[^\n]*)|import[ \t]+[^\n]*)", re.M)
_DECORATOR = re.compile(r"^[ \t]*@[ \t]*(?:\w+\.)*(\w+)", re.M)
_WRAPPED = re.compile(r"^\w+[ \t]*=[ \t]*(?:\w+\.)*(\w+)\(.*\)\(", re.M)
_COMPILERS = ("jit", "vectorize", "intrinsic", "overload", "cfunc")


def _import_nodes(text: str) -> list[ast.stmt]:
    """The ``ast`` of each import statement of ``text`` (inside functions too)."""
    out = []
    for m in _IMPORT.finditer(text):
        try:
            out.extend(ast.parse(m.group(1)).body)
        except SyntaxError:  # an "import ..." line of a docstring
            continue
    return out


def _defines_kernels(text: str) -> bool:
    """The module defines numba functions: a decorator naming a numba compiler (``njit``,
    ``numba.njit(...)``, ``vectorize``, ``intrinsic``, ``overload``...) or a module-level
    ``name = njit(...)(f)``."""
    names = [m.group(1) for m in _DECORATOR.finditer(text)] + [m.group(1) for m in _WRAPPED.finditer(text)]
    return any(k in n for n in names for k in _COMPILERS)


def _imports(text: str, modname: str, is_package: bool) -> set[str]:
    """Absolute names of the modules (and of ``module.name`` for each imported name, in case it
    is a submodule) that ``text`` imports from, at any depth (imports inside functions too)."""
    pkg_parts = modname.split(".") if is_package else modname.split(".")[:-1]
    out: set[str] = set()
    for node in _import_nodes(text):
        if isinstance(node, ast.Import):
            for a in node.names:
                out.add(a.name)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg_parts[: len(pkg_parts) - (node.level - 1)]
                if node.module:
                    base = base + node.module.split(".")
                base_name = ".".join(base)
            else:
                base_name = node.module or ""
            out.add(base_name)
            out.update(f"{base_name}.{a.name}" for a in node.names)
    return out


def dependencies(root: str, package: str, files: list[str] | None = None) -> dict[str, list[str]]:
    """For each file of the package holding cached kernels (``cache=True`` in its text and a
    function compiled by numba): the files of the package that define numba functions it imports
    from, transitively (itself excluded), sorted."""
    files = _py_files(root) if files is None else files
    texts, names = {}, {}
    for f in files:
        try:
            with open(f, encoding="utf-8") as fh:
                texts[f] = fh.read()
        except (OSError, UnicodeDecodeError):
            continue
        names[_module_name(root, package, f)] = f
    # a module compiling functions imports numba
    numba_files = {f for f, t in texts.items() if "numba" in t and _defines_kernels(t)}
    direct: dict[str, set[str]] = {}
    for f in numba_files:
        mod = _module_name(root, package, f)
        imported = _imports(texts[f], mod, f.endswith("__init__.py"))
        direct[f] = {names[m] for m in imported if m in names and names[m] in numba_files and names[m] != f}
    out = {}
    for f in sorted(numba_files):
        if "cache=True" not in texts[f]:
            continue
        seen, todo = set(), list(direct.get(f, ()))
        while todo:
            g = todo.pop()
            if g in seen or g == f:
                continue
            seen.add(g)
            todo.extend(direct.get(g, ()))
        out[f] = sorted(seen)
    return out


def deps_stamp(root: str, deps: list[str]) -> str:
    """SHA-1 of the relative paths and contents of ``deps``."""
    h = hashlib.sha1()
    for f in deps:
        h.update(os.path.relpath(f, root).encode() + b"\0")
        try:
            with open(f, "rb") as fh:
                h.update(fh.read())
        except OSError:
            h.update(b"<missing>")
    return h.hexdigest()


def cache_dir(py_file: str) -> str | None:
    """The directory numba caches the kernels of ``py_file`` in (numba's own locator: the first of
    its locator classes that accepts the file, which also requires the directory to be writable),
    or None when there is none."""
    try:
        from numba.core.caching import CompileResultCacheImpl

        code = compile("def _f():\n    pass\n", py_file, "exec")
        ns: dict = {}
        exec(code, ns)
        return CompileResultCacheImpl(ns["_f"]).locator.get_cache_path()
    except Exception:  # no locator (read-only install), an unusual numba: skip quietly
        return None


def _read(path: str) -> str | None:
    try:
        with open(path, encoding="ascii") as fh:
            return fh.read().strip()
    except (OSError, UnicodeDecodeError):
        return None


def _write(path: str, text: str) -> None:
    tmp = f"{path}.{os.getpid()}.tmp"
    try:
        with open(tmp, "w", encoding="ascii") as fh:
            fh.write(text + "\n")
        os.replace(tmp, path)  # atomic: a concurrent reader sees the old or the new stamp
    except OSError:
        try:
            os.remove(tmp)
        except OSError:
            pass


def cache_files(directory: str, py_file: str) -> list[str]:
    """numba's cache files of the kernels of ``py_file`` in ``directory``: ``<stem>.<qualname>-
    <line>.py<ver>.nbi`` and ``.<n>.nbc`` (numba names them after the file's stem)."""
    prefix = os.path.splitext(os.path.basename(py_file))[0] + "."
    try:
        names = os.listdir(directory)
    except OSError:
        return []
    return [
        os.path.join(directory, n) for n in names if n.startswith(prefix) and (n.endswith(".nbi") or n.endswith(".nbc"))
    ]


def check(root: str | None = None, package: str | None = None) -> list[str]:
    """Delete the numba cache files of every module of the package at ``root`` (default: femast)
    whose numba dependencies in other files changed since its cache was stamped; returns the
    deleted paths.  Never raises on file-system errors."""
    if os.environ.get(ENV, "1").strip().lower() in ("0", "no", "off", "false"):
        return []
    root = os.path.dirname(os.path.abspath(__file__)) if root is None else os.path.abspath(root)
    package = os.path.basename(root) if package is None else package
    files = _py_files(root)
    top = cache_dir(os.path.join(root, "__init__.py"))
    if top is None:
        return []
    stamp_file = os.path.join(top, TREE_STAMP)
    tree = tree_stamp(root, files)
    if _read(stamp_file) == tree:
        return []
    deleted = []
    for f, deps in dependencies(root, package, files).items():
        if not deps:
            continue
        directory = cache_dir(f)
        if directory is None:
            continue
        stem = os.path.splitext(os.path.basename(f))[0]
        record = os.path.join(directory, stem + DEPS_SUFFIX)
        new = deps_stamp(root, deps)
        if _read(record) == new:
            continue
        for c in cache_files(directory, f):
            try:
                os.remove(c)
                deleted.append(c)
            except OSError:  # deleted by another process meanwhile, or not ours to delete
                pass
        _write(record, new)
    _write(stamp_file, tree)
    return deleted
