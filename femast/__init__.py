"""femast: geometrically nonlinear finite elements for jointed deployable masts.

Quick start::

    import femast as fm
    m = fm.Model("cantilever")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=10)
    m.fix(a)
    m.step("load").load(b, fz=-100.0)
    res = fm.solve(m, "results/cantilever")
    print(res.node_history(b, "uz"))
"""

from . import _moved, numba_cache

numba_cache.configure()  # a source checkout: numba's cache in a folder keyed by the kernels' sources

from .analysis import Analysis, solve
from .analysis.control import ArcLength, DisplacementControl, LoadControl, Stabilize
from .analysis.convergence import Convergence
from .errors import (
    ConvergenceError,
    DataFileError,
    EquilibriumError,
    FemastError,
    FolderInUseError,
    ModelError,
    ResultsWriteError,
    SingularModelError,
)
from .model import Model
from .model.amplitudes import Amplitude
from .model.sections import Section, circular_solid, circular_tube, shear_modulus, square_solid, square_tube
from .post.results import Results

__all__ = [
    "Amplitude",
    "Analysis",
    "solve",
    "Model",
    "Results",
    "Section",
    "circular_solid",
    "circular_tube",
    "square_solid",
    "square_tube",
    "shear_modulus",
    "DisplacementControl",
    "LoadControl",
    "Convergence",
    "Stabilize",
    "ArcLength",
    "FemastError",
    "ModelError",
    "SingularModelError",
    "ConvergenceError",
    "DataFileError",
    "EquilibriumError",
    "FolderInUseError",
    "ResultsWriteError",
]
__version__ = "0.1.0"


def __getattr__(name):  # fm.results, fm.sections...: the old top-level modules (they warn: femast._moved)
    if name in _moved.OLD_TOP_LEVEL:
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


from .jit import watch as _watch_compile

_watch_compile()  # announce the first-run numba compile once per process tree (femast.jit)
