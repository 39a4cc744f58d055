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

from .amplitudes import Amplitude
from .analysis import Analysis, solve
from .errors import ConvergenceError, DataFileError, EquilibriumError, FemastError, ModelError, SingularModelError
from .model import Model
from .results import Results
from .sections import Section, circular_solid, circular_tube, shear_modulus, square_solid, square_tube
from .solvers.control import DisplacementControl, LoadControl
from .solvers.stabilize import Stabilize
from .solvers.arclength import ArcLength
from .solvers.convergence import Convergence

__all__ = [
    "Amplitude", "Analysis", "solve", "Model", "Results", "Section", "circular_solid", "circular_tube",
    "square_solid", "square_tube", "shear_modulus", "DisplacementControl", "LoadControl", "Convergence", "Stabilize", "ArcLength",
    "FemastError", "ModelError", "SingularModelError", "ConvergenceError", "DataFileError", "EquilibriumError",
]
__version__ = "0.1.0"
