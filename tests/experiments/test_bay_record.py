"""bay-torsion records the latches' bead positions from the latch family's committed state and
derives the zones after the run (reading an element output builds the family's whole
output dict, 20 % of a run); they must equal the family's own outputs at every frame."""

import numpy as np

from femast.analysis import Analysis
from femast.rigs import bay_torsion as bt


def test_committed_beads_and_zones_equal_the_latch_outputs():
    from femast.adam import build_bay
    from femast.adam.steps import CONVERGENCE, add_initial_steps

    am = build_bay(bt.bay_parameters(bt.bay_inputs({}, bt.EXPERIMENT.options)))
    add_initial_steps(am, hold_control=("ux", "uy", "rz"))
    th = np.radians([0.0, 1.0, 2.6, 3.0, 1.5, 0.0])  # through the release and back: all four zones
    t = np.arange(len(th), dtype=float)
    am.model.step(
        "path", period=t[-1], initial_increment=1.0, max_increment=1.0, min_increment=1e-5, max_increments=600
    ).follow(am.control, t, rz=th, ux=0 * t, uy=0 * t)
    fam = am.latch_family
    got, want = [], []

    def record(fr):
        got.append(an.states[k][:, 0].copy())
        want.append((np.array(fr[f"el/{fam}/bead_position"]), np.array(fr[f"el/{fam}/latch_zone"])))

    an = Analysis(am.model, None, progress=False, convergence=CONVERGENCE, on_frame=record)
    k = next(i for i, f in enumerate(an.families) if f.name == fam)
    an.run()
    out = bt._latch_outputs(an.families[k], np.array(got))
    bead = np.array([w[0] for w in want])
    zone = np.array([w[1] for w in want])
    assert np.array_equal(out["bead"], bead, equal_nan=True)
    assert np.array_equal(out["zone"], zone)
    assert len(np.unique(zone)) >= 3  # the path visits several zones (the comparison means something)
