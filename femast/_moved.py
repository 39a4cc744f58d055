"""Module paths that moved, kept for one release as thin modules that warn.

Each old path is a real file (``femast/sections.py``, ``femast/latch.py``,
``femast/analysis/solvers/linear.py``, ``femast/experiments/rigs/mast_top.py``, ...) of three lines: :func:`moved` warns with a
:class:`DeprecationWarning` that names the new path and the release that removes the old one,
then puts the new module in ``sys.modules`` under the old name, so the import returns the *same*
module object (one class for ``isinstance``, numba's cache keyed on the one source file).  No
import hook: IDEs, type checkers and ``python -m`` see ordinary files.  femast's own code, tests,
benchmarks and docs import the new paths (``tests/test_architecture.py`` checks).

Renamed names and option values warn the same way for one release: :func:`renamed` (an old keyword
or value), :func:`renamed_attributes` (a module's old names), :class:`RenamedKeys` (a result dict's
old keys); ``tests/test_renamed_names.py`` tests each.
"""

from __future__ import annotations

import importlib
import inspect
import sys
import warnings

#: the femast release that removes the old paths
REMOVED_IN = "0.3"

#: old top-level module names, reachable as ``femast.<name>`` attributes until REMOVED_IN
OLD_TOP_LEVEL = frozenset(
    {
        "amplitudes",
        "sections",
        "constraints",
        "thermal",
        "validation",
        "model_arrays",
        "assembly",
        "dofs",
        "reduction",
        "configuration",
        "solvers",
        "mass",
        "modal_output",
        "frequency_step",
        "results",
        "vtk",
        "render",
        "plotstyle",
        "verification_arclength",
        "verification_modal",
        "references",
        "latch",
    }
)


def moved(old: str, new: str, warn: bool = True):
    """Make the module being imported as ``old`` the module ``new`` (warning first, unless not
    ``warn``: a package whose submodules warn on their own)."""
    if warn:
        _warn_moved(old, new)
    module = importlib.import_module(new)
    sys.modules[old] = module  # what the import of ``old`` returns
    return module


def moved_package(old: str, new: str):
    """For an old package whose modules are old paths too (each a module of :func:`moved` in the old
    package's folder): warn like :func:`moved` and return the module ``__getattr__`` that gives the new
    package's names.  The old package stays a module of its own, so that ``old.module`` is found in
    the old folder and is the new module, never a second copy of it loaded under the old name."""
    _warn_moved(old, new)

    def __getattr__(name):
        return getattr(importlib.import_module(new), name)

    return __getattr__


def _warn_moved(old: str, new: str) -> None:
    """The :class:`DeprecationWarning` of an old module path, at the line of the code that imported it."""
    frame = _importer()
    g = frame.f_globals if frame is not None else {}
    warnings.warn_explicit(
        f"{old} has moved to {new}: import it from there ({old} is removed in femast {REMOVED_IN})",
        DeprecationWarning,
        frame.f_code.co_filename if frame is not None else "<unknown>",
        frame.f_lineno if frame is not None else 0,
        module=g.get("__name__", "<unknown>"),
        registry=g.setdefault("__warningregistry__", {}),
    )


def _importer():
    """The frame of the code that imported the old path: the first frame outside the import
    machinery, this module, the old-path module and femast's package ``__getattr__``."""
    frame = inspect.currentframe()
    while frame is not None:
        name = frame.f_globals.get("__name__", "")
        if not (
            name == __name__
            or name == "femast"
            or name.startswith("importlib")
            or frame.f_code.co_filename.startswith("<frozen importlib")
            or frame.f_globals.get("moved") is moved
            or frame.f_globals.get("moved_package") is moved_package
        ):
            return frame
        frame = frame.f_back
    return None


def renamed(old: str, new: str, stacklevel: int = 3) -> None:
    """Warn that the name or option value ``old`` is now ``new`` (a :class:`DeprecationWarning` naming
    both and the release that removes ``old``), at the caller of the function that calls this."""
    warnings.warn(
        f"{old} is now {new}: use the new name ({old} is removed in femast {REMOVED_IN})",
        DeprecationWarning,
        stacklevel=stacklevel,
    )


def renamed_attributes(module_name: str, names: dict):
    """A module ``__getattr__`` that gives each old name of ``names`` (old -> new) the object of its
    new name, with the warning of :func:`renamed`."""
    module = sys.modules[module_name]

    def __getattr__(name):
        if name in names:
            renamed(f"{module_name}.{name}", f"{module_name}.{names[name]}")
            return getattr(module, names[name])
        raise AttributeError(f"module {module_name!r} has no attribute {name!r}")

    return __getattr__


class RenamedKeys(dict):
    """A dict whose old keys (``renames``: old -> new) still read, with the warning of :func:`renamed`:
    ``d[old]``, ``d.get(old)`` and ``old in d`` all see the new key's entry (the old key is not
    stored: iterating, ``keys()`` and ``len`` show only the new names)."""

    def __init__(self, data=(), renames=None, what="the result"):
        super().__init__(data)
        self.renames, self.what = dict(renames or {}), what

    def _new_key(self, key, stacklevel=4):
        """The new name of an old ``key`` (with the warning), or ``key`` itself."""
        if key in self.renames and not dict.__contains__(self, key):
            new = self.renames[key]
            renamed(f"{self.what}[{key!r}]", f"{self.what}[{new!r}]", stacklevel=stacklevel)
            return new
        return key

    def __missing__(self, key):
        new = self._new_key(key)
        if new is key:
            raise KeyError(key)
        return self[new]

    def get(self, key, default=None):
        return dict.get(self, self._new_key(key), default)

    def __contains__(self, key):
        return dict.__contains__(self, self._new_key(key))
