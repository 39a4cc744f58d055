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

from . import _aliases, numba_cache

numba_cache.configure()  # a source checkout: numba's cache in a folder keyed by the kernels' sources

_aliases.install()  # the import paths of before the package move (issue 15) keep working

from .analysis import Analysis, solve
from .analysis.solvers.arclength import ArcLength
from .analysis.solvers.control import DisplacementControl, LoadControl
from .analysis.solvers.convergence import Convergence
from .analysis.solvers.stabilize import Stabilize
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


def __getattr__(name):  # fm.results, fm.sections...: the old top-level modules, imported on first use
    return _aliases.attribute(name)


from .jit import watch as _watch_compile

_watch_compile()  # announce the first-run numba compile once per process tree (femast.jit)
