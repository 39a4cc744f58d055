"""The built-in rigs: one module per test rig, each written as a user's rig is (docs/your_own_rig.md),
through the framework's names (the public names of :mod:`femast.experiments`, imported from the
framework's modules that define them, so that no rig imports the package whose registry lists it)
and :mod:`femast.effects`.

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

:mod:`femast.experiments.rigs.synthetic` generates data with hidden effects from their models.
The registry (:mod:`femast.experiments.registry`) imports this package on first use of an
experiment name and registers the ``EXPERIMENT`` of each rig of :data:`BUILT_IN`, in its order.
"""

from . import bay_torsion, joint_test, latch_pull, mast_top, platform_pose, tip_cycle, vibration

#: the built-in rigs, in the order ``femast experiments`` lists them
BUILT_IN = (mast_top, latch_pull, bay_torsion, tip_cycle, vibration, platform_pose, joint_test)
