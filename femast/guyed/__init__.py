"""Guyed compliant masts of a cable-driven parallel robot (the Rocaspect paper).

Modules, one concept each (SI units throughout):

* :mod:`.cdpr` -- CDPR statics: cable vectors, wrench matrix, tension distribution, mast-top
  wrenches (Eqs. 1-3, 7).
* :mod:`.mast_3r` -- three-elastic-joint model (Eqs. 4-7, Eq. 6 sign corrected).
* :mod:`.cantilever` -- cantilever beam compliance (Eqs. 8-15, Bredt torsion constant).
* :mod:`.shroud` -- Dyneema rope law (Eq. 25; units, secant and tangent stiffness).
* :mod:`.complete_mast` -- beam plus shrouds, active and passive stiffness (Eqs. 16-26).
* :mod:`.identify` -- least-squares identification with uncertainties (Eqs. 27-30).
* :mod:`.rocaspect` -- the paper's robot: published values and documented assumptions.
"""

from .._moved import renamed_attributes
from ..elements.shroud_law import (
    ROCASPECT_X_S,
    DyneemaLaw,
    axial_rigidity_secant,
    axial_rigidity_tangent,
    shroud_stiffness,
    strain_from_tension,
    tension_from_strain,
)
from .cantilever import (
    cantilever_compliance,
    cantilever_compliance_local,
    cantilever_stiffness,
    displacement_beam,
    mast_section,
)
from .cdpr import (
    CdprGeometry,
    TensionDistribution,
    cable_vectors,
    gravity_wrench,
    is_feasible,
    mast_top_wrenches,
    tension_distribution,
    trajectory_loads,
    wrench_matrix,
)
from .complete_mast import (
    MastStiffness,
    ShroudSet,
    active_stiffness,
    displacement_complete,
    mast_stiffness,
    passive_stiffness,
    shroud_wrench_matrix,
)
from .identify import FitResult, fit_3r, fit_beam_E, fit_shroud_law
from .mast_3r import compliance_3r, displacement_3r, jacobian_3r

#: old names, kept for one release (they warn): femast 0.3 removes them
__getattr__ = renamed_attributes(__name__, {"SEED_X_S": "ROCASPECT_X_S"})
