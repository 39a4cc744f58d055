"""The loaded side of a latch pull test is not turned by isolated spikes of the load cell.

Data from the independent latch rig of the generalisation benchmark (benchmarks/generalisation:
the latch law written from Stohlman & Pellegrino's equations, numpy only), with single-sample
spikes of either sign added to the force.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

from generalisation import noise as nz  # noqa: E402
from generalisation.cases import get_case, latch_truth  # noqa: E402

from femast.rigs.latch_pull import infer_side, running_median  # noqa: E402


def test_running_median_ignores_two_row_spikes_and_keeps_steps():
    v = np.r_[np.zeros(10), 5.0, -5.0, np.zeros(10), np.ones(10)]
    m = running_median(v, 5)
    assert np.all(m[:22] == 0.0)
    assert np.all(m[24:] == 1.0)


def test_spikes_do_not_turn_the_loaded_side():
    case = get_case("lp_null_white")
    for seed in range(6):
        rng = np.random.default_rng(seed)
        x, dT, kind, _ = latch_truth(case, rng)
        dT_noisy = dT + nz.white(rng, dT.size, 0.5)
        clean = infer_side(x, dT_noisy)
        spiked = infer_side(x, dT_noisy + nz.spikes(rng, dT.size, 12, 10.0))
        np.testing.assert_array_equal(spiked, clean)
        # and the side is the pulling cable of the generator's passes (out: +1, in: -1)
        moving = kind != 0
        assert np.mean(clean[moving] == kind[moving]) > 0.97
