"""The built-in rigs: one module per test rig, each written as a user's rig is (docs/your_own_rig.md),
with the public names of :mod:`femast.experiments` and :mod:`femast.effects`.  The package sits above
the experiments framework, which imports no rig: like any installed package of rigs, it registers its
experiments through the ``femast.experiments`` entry point (``pyproject.toml``), which the registry
reads on first use.

======================  ======================================================================
module                  rig
======================  ======================================================================
``mast_top``            wrench on a mast top and its displacement (Rocaspect guyed mast, 3R model)
``latch_pull``          pull test of a cable latch (ADAM, Stohlman & Pellegrino, Eqs. 12-14)
``bay_torsion``         single ADAM bay under torsion (FE)
``tip_cycle``           ADAM mast under tip load cycles (FE)
``vibration``           natural frequencies of a prestressed bay side (FE modal)
``platform_pose``       cable-robot platform on compliant masts (Rocaspect)
``joint_test``          a connection's cyclic test: force (moment) in, displacement (rotation) out
======================  ======================================================================

:mod:`femast.rigs.synthetic` generates data with hidden effects from their models.
The registry (:mod:`femast.experiments.registry`) registers :data:`EXPERIMENTS` (the entry point's
object) on first use of an experiment name, in the order of :data:`BUILT_IN`.
"""

from . import bay_torsion, joint_test, latch_pull, mast_top, platform_pose, tip_cycle, vibration

#: the built-in rigs, in the order ``femast experiments`` lists them
BUILT_IN = (mast_top, latch_pull, bay_torsion, tip_cycle, vibration, platform_pose, joint_test)
#: their experiments: the object of femast's ``femast.experiments`` entry point (pyproject.toml)
EXPERIMENTS = tuple(rig.EXPERIMENT for rig in BUILT_IN)
