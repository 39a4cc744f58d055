"""Prestressed modal analysis (see docs/architecture.md).

* :mod:`.modes`: :func:`modal_analysis` about a converged state, :class:`Modes`;
* :mod:`.mass`: mass matrices of the element families, point masses and rigid bodies;
* :mod:`.output`: mode shapes as animated VTK series, frequency histories;
* :mod:`.step`: the ``frequency`` step of model scripts.

``femast.modal`` was one module before the package move; its names are re-exported here.
"""

from .modes import (
    EQUILIBRIUM_TOL,
    Modes,
    check_equilibrium,
    default_shift,
    expand_shapes,
    frequencies_of,
    modal_analysis,
    solve_eigen,
)

__all__ = ["Modes", "modal_analysis", "solve_eigen", "expand_shapes", "frequencies_of"]
