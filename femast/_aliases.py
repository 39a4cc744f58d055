"""The import paths of before the package move, kept working.

``import femast.results``, ``from femast.sections import ...``, ``from femast import plotstyle``,
``femast.solvers.control``... resolve to the modules at their new places (``femast.post.results``,
``femast.model.sections``, ``femast.analysis.solvers.control``): the *same* module objects, loaded
once from their one file (so numba's ``cache=True``, keyed on the source path, keeps working and
``isinstance`` sees one class).  The aliases are lazy: an old path costs nothing until imported.
``femast.model``, ``femast.modal`` and ``femast.verification`` kept their names (packages now,
re-exporting the old module's names).  New code imports the new paths.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys

#: old module (before the move) -> where it is now
OLD_PATHS = {
    "femast.amplitudes": "femast.model.amplitudes",
    "femast.sections": "femast.model.sections",
    "femast.constraints": "femast.model.constraints",
    "femast.thermal": "femast.model.thermal",
    "femast.validation": "femast.model.validation",
    "femast.model_arrays": "femast.model.arrays",
    "femast.assembly": "femast.analysis.assembly",
    "femast.dofs": "femast.analysis.dofs",
    "femast.reduction": "femast.analysis.reduction",
    "femast.configuration": "femast.analysis.configuration",
    "femast.solvers": "femast.analysis.solvers",  # and its submodules
    "femast.mass": "femast.modal.mass",
    "femast.modal_output": "femast.modal.output",
    "femast.frequency_step": "femast.modal.step",
    "femast.results": "femast.post.results",
    "femast.vtk": "femast.post.vtk",
    "femast.render": "femast.post.render",
    "femast.plotstyle": "femast.post.plotstyle",
    "femast.verification_arclength": "femast.verification.arclength",
    "femast.verification_modal": "femast.verification.modal",
    "femast.references": "femast.verification.references",
    "femast.guyed.shroud": "femast.elements.shroud_law",  # the law of the shroud element
}


def new_path(name: str) -> str | None:
    """Where the old module ``name`` is now (None if ``name`` is not an old path)."""
    if name in OLD_PATHS:
        return OLD_PATHS[name]
    head, _, tail = name.partition(".solvers.")
    if head == "femast" and tail:
        return f"femast.analysis.solvers.{tail}"
    return None


class _Alias(importlib.abc.Loader):
    def __init__(self, target: str):
        self.target = target

    def create_module(self, spec):
        return None

    def exec_module(self, module):
        # the import system returns what sys.modules holds under the name after exec_module
        sys.modules[module.__name__] = importlib.import_module(self.target)


class _OldPaths(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        new = new_path(name) if name.startswith("femast.") else None
        return importlib.util.spec_from_loader(name, _Alias(new)) if new else None


def install() -> None:
    """Put the old-path finder first on ``sys.meta_path`` (once)."""
    if not any(isinstance(f, _OldPaths) for f in sys.meta_path):
        sys.meta_path.insert(0, _OldPaths())


def attribute(name: str):
    """``femast.<name>`` for an old top-level module name (``fm.results``...), else AttributeError."""
    if f"femast.{name}" in OLD_PATHS:
        return importlib.import_module(f"femast.{name}")
    raise AttributeError(f"module 'femast' has no attribute {name!r}")
