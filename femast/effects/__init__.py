"""Library of physical effects for ``femast compare`` and ``femast diagnose`` (issue 7).

Each effect is a named, documented mechanism with parameters (units, bounds, defaults) and one
implementation per experiment it applies to (see :mod:`femast.effects.base`).  Built in:

=====================  ==========================================  ==========================================
name                   mechanism                                   implemented for
=====================  ==========================================  ==========================================
joint_clearance        backlash, offset +-c with the load's sign    mast-top, latch-pull
friction_hysteresis    Coulomb friction, play operator              mast-top, latch-pull
beam_flexibility       cantilever tube in series (000 Eqs. 8-15)    mast-top
progressive_stiffness  EA(tau) of seed 000 Eq. 25                   mast-top
cable_hysteresis       loop width proportional to the load          mast-top, latch-pull
pretension_loss        stiffness vs pretension; pretension error    mast-top, bay-torsion, tip-cycle
stretch_error          Eq. 15 stretch-removal error (seed 001)      latch-pull
latch_hysteresis       friction band near the latched state         latch-pull, bay-torsion, tip-cycle
ball_joint_friction    |M| = mu B |F| (seed 001 Sec. II.B.1)        bay-torsion, tip-cycle
off_axis_motion        bay top leaves its axis (seed 001 Sec. VI)   bay-torsion
=====================  ==========================================  ==========================================

On the FE experiments (bay-torsion, tip-cycle) the effects change what the FE model is built with
(hook ``bay_parameters``) or the path it is driven along (``control_path``).
``docs/experiments.md`` documents each one and shows how to register an effect from a script.
"""

from . import joints, structure, cables, latch, vibration  # noqa: F401,I001  (register the built-in effects, in this order)
from .base import (
    Effect,
    Implementation,
    add_implementation,
    applicable_effects,
    get_effect,
    list_effects,
    load_script,
    loaded_scripts,
    register_effect,
    resolve,
    unregister_effect,
)
from .operators import play, proportional_play
from .parameters import Parameter

__all__ = [
    "Effect",
    "Implementation",
    "Parameter",
    "register_effect",
    "add_implementation",
    "get_effect",
    "list_effects",
    "applicable_effects",
    "resolve",
    "unregister_effect",
    "load_script",
    "loaded_scripts",
    "play",
    "proportional_play",
]
