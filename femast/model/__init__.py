"""The model: what a script defines (see docs/architecture.md).

* :mod:`.model`: :class:`Model` (nodes, elements, boundary conditions, loads, steps: the script verbs);
* :mod:`.step`: :class:`Step` (a static step's loads, prescribed values, temperatures) and its verbs;
* :mod:`.specs`: DOF and load names, the beam and truss specifications;
* :mod:`.point_mass`, :mod:`.frequency`: the point masses and the frequency step of modal analyses;
* :mod:`.sections`: beam cross-sections; :mod:`.amplitudes`: load and prescribed-value histories;
* :mod:`.constraints`: rigid bodies and equal-DOF ties; :mod:`.thermal`: length errors and thermal strain;
* :mod:`.validation`: checks of user input (and the equilibrium check of converged increments).

``femast.model`` was one module before the package move; its names are re-exported here.
"""

from .model import Model
from .specs import LOAD_NAMES, BeamSpec, TrussSpec, dof_index
from .step import Condition, Step

__all__ = ["Model", "Step", "dof_index", "LOAD_NAMES", "BeamSpec", "TrussSpec", "Condition"]
