"""The Rocaspect FE mast with the shrouds' loading/unloading law: the pretension is met on the loading
branch, a load cycle leaves a residual and costs pretension only with the option on."""

import numpy as np
import pytest

from femast.guyed.fe_mast import MastFE


def test_cycle_leaves_a_residual_only_with_hysteresis():
    F = 400.0
    W = np.zeros((4, 6))
    W[:, 0] = [F, 0.0, -F, 0.0]
    res = {}
    for eta in (0.0, 0.05):
        mf = MastFE(1200.0, shroud_hysteresis=eta)
        mf.equilibrate()
        assert mf.state().tension == pytest.approx([1200.0] * 3, rel=1e-8)
        res[eta] = mf.run_wrenches(W)
    u0, u5 = (res[e]["u"][:, 0] - res[e]["u0"][0] for e in (0.0, 0.05))
    assert abs(u0[1]) < 1e-9 and abs(u0[3]) < 1e-9  # the elastic mast returns
    assert u5[1] > 2e-4 and u5[3] < -2e-4  # loading and unloading differ: the top lags the load
    assert np.all(res[0.05]["tension"][1] < 1200.0)  # unloaded from +F: every shroud on its unloading branch
    # the friction tension stiffens loading: less top motion under +F than the elastic mast
    assert 0.9 * u0[0] < u5[0] < u0[0]
