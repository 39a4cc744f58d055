"""Pinching and degradation found in connection tests made by another law of the same mechanisms.

The data come from the Bouc-Wen-Baber-Noori connection of the generalisation benchmark
(benchmarks/generalisation/connection.py, numpy only): pinching there is a slip-lock function of
the hysteretic variable, degradation three energy-dependent coefficients -- neither the gap with
friction nor the damage on the effective load of femast's effects.  Each mechanism must lower the
error of a friction model by a large share where it is in the data, and by more than the other
mechanism does (the two are not interchangeable flexibility).
"""

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

from generalisation import connection as conn  # noqa: E402

from femast.experiments import from_arrays, get_experiment  # noqa: E402
from femast.experiments.fitting import fit  # noqa: E402

SIGMA_U, SIGMA_F = 20e-6, 20.0  # m, N: a displacement transducer and a load cell
FRICTION = "friction_hysteresis/iwan"
TRUTH = {
    "pinching": conn.BWBN(zeta_s=0.85, p=2e5, q=0.1, psi=0.3e-3, lam=0.5),
    "degradation": conn.BWBN(dnu=2e4, deta=4e4),
}


def _rms(exp, data, effects):
    return fit(exp, data, effects, noise={"u_m": SIGMA_U}, multistart=False).rms


@pytest.mark.parametrize("hidden", ["pinching", "degradation"])
def test_the_mechanism_in_the_data_explains_it_and_the_other_does_not(hidden):
    exp = get_experiment("joint-test")
    u, _ = conn.cyclic_protocol((1e-3, 2e-3, 3e-3, 4e-3), step=0.08e-3)  # displacement-controlled, 1,250 rows
    F = conn.bwbn_driven(u, TRUTH[hidden], substeps=8)
    rng = np.random.default_rng(7)
    data = from_arrays(exp, F_N=F + rng.normal(0, SIGMA_F, F.size), u_m=u + rng.normal(0, SIGMA_U, u.size))
    other = "degradation" if hidden == "pinching" else "pinching"
    r_friction = _rms(exp, data, [FRICTION])
    r_hidden = _rms(exp, data, [FRICTION, hidden])
    r_other = _rms(exp, data, [FRICTION, other])
    assert r_hidden < 0.7 * r_friction, (r_friction, r_hidden)
    assert r_hidden < 0.8 * r_other, (r_hidden, r_other)
