"""The built-in rigs: one module per test rig, each written as a user's rig is (docs/your_own_rig.md),
through the public API of :mod:`femast.experiments` and :mod:`femast.effects`.

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
The registry imports this package on first use; it registers each rig's ``EXPERIMENT``.
"""

from femast.experiments import register_experiment

from . import bay_torsion, joint_test, latch_pull, mast_top, platform_pose, tip_cycle, vibration

for _rig in (mast_top, latch_pull, bay_torsion, tip_cycle, vibration, platform_pose, joint_test):
    register_experiment(_rig.EXPERIMENT)
