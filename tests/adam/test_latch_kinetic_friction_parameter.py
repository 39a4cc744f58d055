"""BayParameters.latch_mu_k reaches the ADAM latch cables; None is the paper's one coefficient."""

import numpy as np
import pytest

from femast.adam import BayParameters, build_bay
from femast.errors import ModelError


def test_latch_mu_k_reaches_the_latch_family():
    am = build_bay(latch_mu_k=0.03)
    np.testing.assert_array_equal(am.latch.mu_k, 0.03)
    np.testing.assert_array_equal(am.latch.latch[:, 3], 0.07)  # the static coefficient stays the fit's mu
    one = build_bay()
    np.testing.assert_array_equal(one.latch.mu_k, one.latch.latch[:, 3])


def test_kinetic_above_static_is_named():
    with pytest.raises(ModelError, match="latch_mu_k = 0.1 must lie in \\[0, latch.mu = 0.07\\]"):
        BayParameters(latch_mu_k=0.1)
