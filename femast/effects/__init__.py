"""The effect contract and the library of physical effects for ``femast compare`` and ``diagnose``.

An effect is a named, documented mechanism with parameters (units, bounds, defaults).  Its
*mechanism* acts on physical quantities (the load through a connection and the displacement it
drives, per axis; time; temperature) and applies to every experiment that declares them in
``Experiment.quantities`` -- a built-in rig or a user's own; rig-specific implementations act on a
rig's own hooks (see :mod:`femast.effects.base` and :mod:`femast.effects.quantities`).  Built in:

=====================  ==========================================  =====================================
name                   mechanism                                   applies to
=====================  ==========================================  =====================================
joint_clearance        backlash, offset +-c with the load's sign    load + displacement; latch-pull
friction_hysteresis    Coulomb friction, play operator              load; latch-pull
progressive_stiffness  stiffness rising with the load (Eq. 25)      load + displacement
cable_hysteresis       loop width proportional to the load          load; latch-pull
pretension_loss        stiffness falling with time; a pretension    displacement + time; bay-torsion,
                       error in the FE models                       tip-cycle, vibration
beam_flexibility       cantilever tube in series                    mast-top
stretch_error          pull-test stretch-removal error              latch-pull
latch_hysteresis       friction band near the latched state         latch-pull, bay-torsion, tip-cycle
ball_joint_friction    |M| = mu B |F| of the ADAM ball joints       bay-torsion, tip-cycle
off_axis_motion        bay top leaves its axis                      bay-torsion
pinching               slip through a gap with friction (embedment) joint-test (connection rigs)
degradation            damage with cumulative slip or energy        joint-test (its damage hook)
added_mass, joint_stick  natural-frequency effects                  vibration
=====================  ==========================================  =====================================

``docs/experiments.md`` documents each one; ``docs/your_own_rig.md`` shows a user's rig using
them beside its own effects.
"""

from . import joints, structure, cables, latch, vibration, connections  # noqa: F401,I001  (register the built-in effects, in this order)
from .base import (
    Effect,
    Implementation,
    add_implementation,
    applicable_effects,
    get_effect,
    list_effects,
    register_effect,
    resolve,
    unregister_effect,
)
from .operators import play, proportional_play
from .parameters import Parameter
from .quantities import Quantity
from .scripts import load_script, loaded_scripts

__all__ = [
    "Effect",
    "Implementation",
    "Parameter",
    "Quantity",
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
