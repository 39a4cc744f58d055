"""Bad input gets a clear femast error naming the item."""

import math
import tempfile

import numpy as np
import pytest

import femast as fm


def _sec():
    return fm.circular_tube(0.02, 0.016, E=70e9)


def test_unknown_node_is_named():
    m = fm.Model()
    a = m.node(0, 0, 0)
    with pytest.raises(fm.ModelError, match=r"unknown node 99"):
        m.beam(a, 99, _sec())
    with pytest.raises(fm.ModelError, match=r"unknown node 7"):
        m.fix(7)
    with pytest.raises(fm.ModelError, match=r"unknown node 5"):
        m.step("s").load(5, fx=1.0)


def test_coincident_nodes_and_zero_length():
    m = fm.Model()
    a, b = m.node(0, 0, 0), m.node(0, 0, 0)
    with pytest.raises(fm.ModelError, match=r"beam 1-2: nodes 1 and 2 coincide"):
        m.beam(a, b, _sec())
    with pytest.raises(fm.ModelError, match=r"truss 1-2: nodes 1 and 2 coincide"):
        m.truss(a, b, EA=1e5)
    with pytest.raises(fm.ModelError, match=r"node 1 is defined twice"):
        m.node(1, 1, 1, label=1)


def test_up_vector_parallel_to_element():
    m = fm.Model()
    a, b = m.node(0, 0, 0), m.node(0, 0, 2.0)
    with pytest.raises(fm.ModelError, match=r"up-vector .* parallel to the element axis"):
        m.beam(a, b, _sec(), up=(0, 0, 1))


def test_missing_or_bad_section_property():
    with pytest.raises(fm.ModelError, match=r"property J is missing"):
        fm.Section(E=1e9, G=4e8, A=1e-4, Iy=1e-8, Iz=1e-8, J=None, name="rod")
    with pytest.raises(fm.ModelError, match=r"property E=nan must be a finite positive"):
        fm.Section(E=float("nan"), G=4e8, A=1e-4, Iy=1e-8, Iz=1e-8, J=2e-8, name="rod")
    with pytest.raises(fm.ModelError, match=r"inner .* < outer"):
        fm.square_tube(0.05, 0.06, E=70e9)


def test_non_finite_numbers_are_refused():
    m = fm.Model()
    with pytest.raises(fm.ModelError, match=r"node 1 coordinate y = nan is not finite"):
        m.node(0.0, float("nan"), 0.0)
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    with pytest.raises(fm.ModelError, match=r"EA = inf is not finite"):
        m.truss(a, b, EA=math.inf)
    with pytest.raises(fm.ModelError, match=r"load fy on node 2 = nan"):
        m.step("s").load(b, fy=float("nan"))
    with pytest.raises(fm.ModelError, match=r"row 1 .* not finite"):
        fm.Amplitude([0, 0.5, 1], [0, float("nan"), 1])


def test_rigid_body_mode_names_the_free_dofs():
    m = fm.Model()
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, _sec(), n=2)
    m.fix(a, "ux", "uy", "uz", "ry", "rz")  # rx (torsion about the axis) left free: a mechanism
    m.step("s").load(b, fy=1.0)
    with pytest.raises(fm.SingularModelError, match=r"singular.*node \d+ rx"):
        fm.solve(m, tempfile.mkdtemp(), progress=False)


def test_dof_both_loaded_and_fixed():
    m = fm.Model()
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, _sec())
    m.fix(a)
    m.step("s").load(a, fx=1.0)
    with pytest.raises(fm.ModelError, match=r"node 1 ux is both loaded and fixed"):
        fm.Analysis(m, tempfile.mkdtemp(), progress=False)


def test_non_convergence_keeps_converged_increments_and_says_where(tmp_path):
    # A node held only by a tension-only cable: pulled, it is stable; when the load reverses the
    # cable goes slack at step time 0.5 (N = fx at equilibrium) and no equilibrium exists beyond it.
    m = fm.Model()
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.truss(a, b, EA=1e4, tension_only=True, pretension=1.0)
    m.fix(a)
    m.step("pull", initial_increment=0.5).load(b, fx=10.0)
    m.step("push", initial_increment=0.1, max_increment=0.1).load(b, fx=-10.0)
    out = tmp_path / "run"
    with pytest.raises(
        fm.ConvergenceError, match=r"step 'push': increment fell below the minimum .* step time 0\.[45]"
    ):
        fm.solve(m, out, progress=False)
    res = fm.Results(out)
    steps = res.steps
    assert steps.count("pull") == 2  # both converged increments of step 1 kept
    assert steps.count("push") >= 4  # the push increments before the cable went slack
    t_last = res.scalar_history("time")[-1]
    # cut back towards the slack point, then gave up; the slack point itself (load = N = 0 at t = 0.5)
    # is an equilibrium that a linear increment reaches in one iteration
    assert 0.45 < t_last <= 0.5
    assert res.summary is not None and res.summary["completed"] is False
    N = res.element_history("cable", 1, "N")
    # the kept frames are equilibrium states: cable force = applied load.  Residual tolerance:
    # 1e-6 x max(load, zero-force floor 1e-6 EA/L x L = 1e-2 N) -> atol 1e-7 N covers it
    np.testing.assert_allclose(N[1:], res.node_history(b, "fx")[1:], rtol=1e-9, atol=1e-7)
