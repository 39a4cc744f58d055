"""The model: what a script defines (see docs/architecture.md).

* :mod:`.model`: :class:`Model` (nodes, elements, boundary conditions, loads, steps) and :class:`Step`;
* :mod:`.sections`: beam cross-sections; :mod:`.amplitudes`: load and prescribed-value histories;
* :mod:`.constraints`: rigid bodies and equal-DOF ties; :mod:`.thermal`: length errors and thermal strain;
* :mod:`.validation`: checks of user input (and the equilibrium check of converged increments).

``femast.model`` was one module before the package move; its names are re-exported here.
"""

from .model import LOAD_NAMES, BeamSpec, Condition, Model, Step, TrussSpec, dof_index

__all__ = ["Model", "Step", "dof_index", "LOAD_NAMES", "BeamSpec", "TrussSpec", "Condition"]
