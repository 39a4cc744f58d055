"""The cable/latch element inside a model run by the Analysis (force-controlled pull test)."""

import numpy as np
import pytest
from scipy.optimize import brentq

import femast as fm
from femast.elements.cable_latch import CableLatchFamily
from femast.elements.latch_law import UNLATCHING, LatchParameters, latch_force

P = LatchParameters.adam_fit()
EA = 2.0e5


def test_force_controlled_unlatching_in_a_model(tmp_path):
    # Section 0 (backstop side) slack, section 1 pulled by F = 60 N at its free end: the bead
    # leaves the backstop (dT_out = 43.9 N there) and stops where dT_out(x) = F on the rising
    # part of the unlatching branch (below the 63.5 N peak).
    m = fm.Model("pull")
    a, latch, grip = m.node(-0.29, 0, 0), m.node(0, 0, 0), m.node(0.5 * (1 + 1e-6), 0, 0)
    m.fix(a)
    m.fix(latch)
    m.fix(grip, "uy", "uz", "rx", "ry", "rz")
    s0, L0B = 0.3, 0.5
    m.add_family(
        CableLatchFamily(
            [[a, latch, grip]], EA=EA, L0=s0 + L0B, latch_node=1, bead=s0 - P.x_backstop, latch=P, name="cable"
        )
    )
    F = 60.0
    m.step("pull", max_increment=0.1).load(grip, fx=F)
    res = fm.Analysis(m, tmp_path / "run", progress=False).run()
    assert res.summary["completed"]
    x = res.element_history("cable", 1, "bead_position")[-1]
    T = res.element_history("cable", 1, "tension")[-1]
    ref = brentq(lambda z: latch_force(z, UNLATCHING, P) - F, -P.x_backstop, -1.43e-3, xtol=1e-15)
    assert x == pytest.approx(ref, abs=1e-11)  # global Newton tolerance on the 60 N balance
    np.testing.assert_allclose(T, [0.0, F], atol=1e-6)  # equilibrium of the grip node
    # grip displacement by hand: the unstretched length of section 1 grew by (x - x0), then stretched
    L0B_now = L0B + (x + P.x_backstop)
    ux = L0B_now * (1 + F / EA) - 0.5 * (1 + 1e-6)
    assert res.node_history(grip, "ux")[-1] == pytest.approx(ux, abs=1e-10)  # same balance, in metres
    # a consistent tangent gives quadratic convergence: a handful of iterations per increment
    assert res.summary["iterations"] <= 4 * res.summary["increments"]
