"""No result without equilibrium: tolerances are validated, and a completed run's residual and the
balance of its reactions against the applied loads are checked at its end for every element family
(beams, trusses, cable devices, ball joints, shrouds, latches, user elements), whatever convergence
test accepted its increments.  A stabilised last step is not flagged (its viscous forces are part of
the balance)."""

import numpy as np
import pytest
from femast.benchmarks.stabilize_energy import guyed_mast

import femast as fm
from femast.elements.ball_joint import add_ball_joints
from femast.elements.base import ElementFamily, ElementResponse
from femast.elements.cable_devices import CableDeviceFamily, Pulley
from femast.elements.cable_latch import CableLatchFamily
from femast.elements.latch_law import LatchParameters
from femast.elements.shroud_cable import add_shrouds


def beams():
    m = fm.Model("beams")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=4)
    m.fix(a)
    m.step("load").load(b, fz=-500.0)
    return m


def trusses():  # a shallow two-bar arch pressed down (not through)
    m = fm.Model("trusses")
    a, c, b = m.node(0, 0, 0), m.node(1, 0.1, 0), m.node(2, 0, 0)
    m.truss(a, c, EA=1e5)
    m.truss(c, b, EA=1e5)
    m.fix(a)
    m.fix(b)
    m.fix(c, "uz")
    m.step("press").load(c, fy=-25.0)
    return m


def cable_devices():  # a cable turned 90 degrees over a sized friction pulley, its end pulled
    m = fm.Model("cable devices")
    a, p, b = m.node(0, 0, 0), m.node(1, 0, 0), m.node(1, 1.2, 0)
    X = np.vstack([np.zeros(3), m.coordinates])  # (rows by node label)
    m.add_family(CableDeviceFamily.pretensioned([[a, p, b]], X, 1e5, 100.0, [Pulley(radius=0.05, mu=0.3)]))
    m.fix(a)
    m.fix(p)
    m.fix(b, "uz")
    m.step("pull").load(b, fy=300.0, fx=50.0)
    return m


def ball_joints():  # a cantilever hung from a fixed node through a sticking ball joint
    m = fm.Model("ball joints")
    a, b, c = m.node(0, 0, 0), m.node(0, 0, 0), m.node(1, 0, 0)
    add_ball_joints(m, [(a, b)], mu=0.5, B=0.004, k_pen=1e8, k_stick=1e6)
    m.beam(b, c, fm.circular_tube(0.02, 0.016, E=70e9), n=4)
    m.fix(a)
    m.step("load").load(c, fz=-100.0)
    return m


def shrouds():  # a mast held by a Dyneema shroud, pushed towards its anchor
    m = fm.Model("shrouds")
    base, top, anchor = m.node(0, 0, 0), m.node(0, 0, 2.0), m.node(1.0, 0, 0)
    m.beam(base, top, fm.circular_tube(0.03, 0.026, E=70e9), n=4, up=(1, 0, 0))
    add_shrouds(m, [(top, anchor)], tension=500.0)
    m.fix(base)
    m.fix(anchor)
    m.step("push").load(top, fx=-3000.0)
    return m


def latches():  # the pull test of docs/cable_latch_element.md
    lp = LatchParameters.adam_fit()
    m = fm.Model("latches")
    a, l, g = m.node(-0.29, 0, 0), m.node(0, 0, 0), m.node(0.5000005, 0, 0)
    m.fix(a)
    m.fix(l)
    m.fix(g, "uy", "uz", "rx", "ry", "rz")
    latch = CableLatchFamily([[a, l, g]], EA=2e5, L0=0.8, latch_node=1, bead=0.3 - lp.x_backstop, latch=lp)
    m.add_family(latch)
    m.step("pull", max_increment=0.1).load(g, fx=60.0)
    return m


class HardeningSprings(ElementFamily):
    """Springs between two nodes, f = k (d + 100 d^3) per axis (d: relative displacement, m).  Not
    self-equilibrated (the default of a user element): equal and opposite forces off the line
    between the nodes are a couple."""

    name = "hardening"
    active_dofs = (0, 1, 2)

    def __init__(self, nodes, X0, k):
        self.nodes = np.asarray(nodes, dtype=np.int64)
        self.X0, self.k = X0, k

    def evaluate(self, x, R, state, ctx=None):
        n = len(self.nodes)
        f, K = np.zeros((n, 12)), np.zeros((n, 12, 12))
        for e, (i, j) in enumerate(self.nodes):
            d = x[j] - x[i] - (self.X0[j] - self.X0[i])
            F, kk = self.k * (d + 100 * d**3), np.diag(self.k * (1 + 300 * d**2))
            f[e, :3], f[e, 6:9] = -F, F
            K[e, :3, :3] = K[e, 6:9, 6:9] = kk
            K[e, :3, 6:9] = K[e, 6:9, :3] = -kk
        return ElementResponse(f=f, k=K, state=state)


def user_elements():
    m = fm.Model("user elements")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.add_family(HardeningSprings([[a, b]], m.coordinates, 1e3))
    m.fix(a)
    m.step("pull").load(b, fx=200.0, fy=50.0)
    return m


FAMILIES = [beams, trusses, cable_devices, ball_joints, shrouds, latches, user_elements]


class AcceptsAnything(fm.Convergence):
    """A convergence test of one's own that accepts every iterate after the first (a broken one)."""

    def measure(self, r, du, Du, is_rot, ref_force, ref_moment, length, iteration=0):
        _, worst, _, size = super().measure(r, du, Du, is_rot, ref_force, ref_moment, length, iteration)
        return iteration >= 1, worst, True, size


@pytest.mark.parametrize("build", FAMILIES, ids=[f.__name__ for f in FAMILIES])
def test_a_completed_run_out_of_equilibrium_fails_loudly_for_every_family(build, tmp_path):
    res = fm.solve(build(), tmp_path / "good", progress=False)  # the same model converged: no alarm
    assert res.status == "completed"
    with pytest.raises(fm.EquilibriumError, match=r"the completed run is not in equilibrium: a residual of") as err:
        fm.solve(build(), tmp_path / "bad", progress=False, convergence=AcceptsAnything())
    assert "tighten its tolerances" in str(err.value)
    assert fm.Results(tmp_path / "bad").status == "failed"


@pytest.mark.parametrize(
    "options, named",
    [
        ({"force_tol": 1e10, "disp_tol": 1e10, "linear_tol": 1e10}, "force_tol = 1e+10 is not a tolerance"),
        ({"force_tol": float("nan")}, "force_tol = nan is not a tolerance"),
        ({"disp_tol": 0.0}, "disp_tol = 0 is not a tolerance"),
        ({"linear_tol": -1e-8}, "linear_tol = -1e-08 is not a tolerance"),
        ({"force_tol": "1e-6"}, "force_tol = '1e-6' is not a tolerance"),
        ({"max_iterations": 0}, "max_iterations = 0 must be at least 1"),
        ({"max_iterations": 2.5}, "max_iterations = 2.5 must be a whole number"),
    ],
)
def test_tolerances_are_validated(options, named):
    with pytest.raises(fm.ModelError, match="Convergence") as err:
        fm.Convergence(**options)
    assert named in str(err.value)


def test_tolerances_changed_after_construction_are_validated_by_the_analysis():
    conv = fm.Convergence()
    conv.force_tol = 1e10
    with pytest.raises(fm.ModelError, match="force_tol = 1e\\+10 is not a tolerance"):
        fm.Analysis(beams(), None, progress=False, on_frame=print, convergence=conv)


def test_a_family_that_claims_balance_but_pulls_on_the_ground_is_named(tmp_path):
    """A spring to the ground (one node's force only) marked self-equilibrated: the family is named."""

    class GroundSpring(ElementFamily):
        name = "ground spring"
        active_dofs = (0, 1, 2)
        self_equilibrated = True  # (wrong: it is tied to the ground)

        def __init__(self, nodes, X0, k):
            self.nodes, self.X0, self.k = np.asarray(nodes, dtype=np.int64), X0, k

        def evaluate(self, x, R, state, ctx=None):
            i = self.nodes[0, 0]
            f, K = np.zeros((1, 6)), np.zeros((1, 6, 6))
            f[0, :3] = self.k * (x[i] - self.X0[i])
            K[0, :3, :3] = np.eye(3) * self.k
            return ElementResponse(f=f, k=K, state=state)

    m = fm.Model("ground")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.truss(a, b, EA=1e5)
    m.fix(a)
    spring = m.add_family(GroundSpring([[b]], m.coordinates, 1e3))
    m.step("pull").load(b, fx=10.0, fy=5.0, fz=1.0)
    with pytest.raises(fm.EquilibriumError, match="element family 'ground spring' is marked self-equilibrated"):
        fm.solve(m, tmp_path / "r", progress=False)
    spring.self_equilibrated = False  # what it is: its resultant is a support reaction, and the run balances
    assert fm.solve(m, tmp_path / "r", progress=False).status == "completed"


def test_a_stabilised_last_step_is_in_balance_with_its_viscous_forces(tmp_path):
    """The guyed bar of docs/stabilize.md ends in its stabilised step: the viscous forces left in
    its last increment are part of the balance, not an error."""
    # strong damping (the viscous forces left are a quarter of the load), no warning asked for
    m = guyed_mast(fm.Stabilize(factor=5.0, warn_ratio=2.0), settle=False)
    an = fm.Analysis(m, tmp_path / "r", progress=False)
    res = an.run()
    assert res.status == "completed"
    assert an.state.stabilization_force > 10 * 0.01 * 400.0  # far beyond the 1 % residual allowed without them
