"""Mass of ADAM-type models: densities of the members, mass per length of the cables,
the pulley-and-latch units and the corner pieces, added to a built :class:`AdamModel`.

Stohlman & Pellegrino give no mass.  The defaults are stated choices (SI):

* members: carbon-fibre tubes (E = 120 GPa in :class:`BayParameters`), rho = 1550 kg/m^3;
* cables: stranded steel, mass per length = 7850 kg/m^3 x EA / 200 GPa (the cable EA of the
  bay parameters over steel's modulus: 1.33e-3 kg/m for the default EA = 3.4e4 N);
* pulley-and-latch unit (latch, bead, pulley, housing): the effective mass identified from the
  the paper's vibration fit (Eq. 16 read in lbf, see :mod:`femast.adam.vibration`), ``UNIT_MASS``;
* corner pieces (ball ends, fittings): 0.02 kg each, lumped at the corner node (a guess: only
  the mast's modes use it, not the bay-side method).
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError

RHO_CFRP = 1550.0  # kg/m^3
RHO_STEEL = 7850.0  # kg/m^3
E_STEEL = 200e9  # Pa
#: Effective mass of a pulley-and-latch unit, kg: identified from Stohlman & Pellegrino, Eq. 16 by
#: ``benchmarks/adam_vibration.py`` (femast.adam.vibration.identify_unit_mass).
UNIT_MASS = 0.0211
CORNER_MASS = 0.02  # kg


def cable_mass_per_length(cable_EA: float) -> float:
    """Mass per length (kg/m) of a steel cable of axial rigidity ``cable_EA`` (N)."""
    return RHO_STEEL * cable_EA / E_STEEL


def add_mass(
    am,
    rho_members: float = RHO_CFRP,
    cable_mass: float | None = None,
    unit_mass: float = UNIT_MASS,
    corner_mass: float = CORNER_MASS,
):
    """Give the members of ``am`` (an :class:`~femast.adam.build.AdamModel`) density
    ``rho_members`` (kg/m^3), its cables ``cable_mass`` kg/m (default :func:`cable_mass_per_length`
    of the bay's EA; lumped), point masses ``unit_mass`` (kg) at every pulley-and-latch unit and
    ``corner_mass`` (kg) at every corner node that is not fixed.  Returns ``am``."""
    for name, v in (("rho_members", rho_members), ("unit_mass", unit_mass), ("corner_mass", corner_mass)):
        if not np.isfinite(v) or v < 0:
            raise ModelError(f"add_mass: {name} = {v!r} must be finite and >= 0 (SI)")
    m = am.model
    cm = cable_mass_per_length(am.params.cable_EA) if cable_mass is None else float(cable_mass)
    if not np.isfinite(cm) or cm < 0:
        raise ModelError(f"add_mass: cable_mass = {cable_mass!r} kg/m must be finite and >= 0")
    for b in m.beams:
        b.section = b.section.with_(rho=rho_members)
    for t in m.trusses:
        if t.family == am.arm_family:
            t.mass_per_length = cm
    for f in m.families:
        if f.name == am.latch_family:
            f.mass_per_length = cm
    for u in np.asarray(am.units).ravel():
        if unit_mass > 0:
            m.point_mass(int(u), unit_mass, name=f"latch unit {int(u)}")
    fixed = set(m.fixed)
    for c in np.asarray(am.corners).ravel():
        if corner_mass > 0 and int(c) not in fixed:
            m.point_mass(int(c), corner_mass, name=f"corner {int(c)}")
    return am
