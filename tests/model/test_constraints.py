"""Rigid bodies and ties, exact for large rotations."""

import tempfile

import numpy as np
import pytest

import femast as fm
from femast.analysis import Analysis
from femast.elements.base import IncrementContext
from femast.rotations import expm_so3


def _tower(a=0.3, h=0.5, n=4):
    """Four fixed-base columns at (+-a, +-a); their tops tied to a control node at the centre."""
    m = fm.Model("tower")
    sec = fm.circular_tube(0.02, 0.016, E=70e9, nu=0.33)
    tops = []
    for sx, sy in [(1, 1), (-1, 1), (-1, -1), (1, -1)]:
        base, top = m.node(sx * a, sy * a, 0.0), m.node(sx * a, sy * a, h)
        m.beam(base, top, sec, up=(1, 0, 0), n=n)
        m.fix(base)
        tops.append(top)
    ctrl = m.node(0.0, 0.0, h)
    m.rigid_body(ctrl, tops, name="top frame")
    return m, ctrl, tops, sec


def test_small_rotation_torsional_stiffness_matches_beam_theory():
    # guided cantilever columns: M = 4 (12 EI r^2 / h^3 + GJ / h) theta (linear theory, exact for
    # cubic elements); theta = 1e-6 rad keeps geometric nonlinearity at ~1e-12
    a, h = 0.3, 0.5
    m, ctrl, tops, sec = _tower(a, h)
    theta = 1e-6
    m.step("twist").prescribe(ctrl, ux=0, uy=0, uz=0, rx=0, ry=0, rz=theta)
    res = fm.solve(m, tempfile.mkdtemp(), progress=False)
    r2 = 2 * a * a
    k = 4 * (12 * sec.E * sec.Iz * r2 / h**3 + sec.G * sec.J / h)
    assert res.node_history(ctrl, "rmz")[-1] == pytest.approx(k * theta, rel=1e-8)
    # each top moved with the control node as a rigid body: (Q - I)(X - c), exact
    U = res.frame(-1)["U"]
    Q = expm_so3(np.array([0.0, 0.0, theta]))
    c = m.xyz(ctrl)
    for t in tops:
        X = m.xyz(t)
        np.testing.assert_allclose(
            U[m.index(t)], (Q - np.eye(3)) @ (X - c), atol=1e-16
        )  # roundoff of 0.3 m coordinates


def test_large_rotation_about_any_axis_is_exact_for_tied_nodes():
    # a frame hanging from its control node only, turned by 2.5 rad about a skew axis: a rigid motion
    m = fm.Model("free frame")
    sec = fm.circular_tube(0.02, 0.016, E=70e9)
    n = m.nodes([(0, 0, 0), (1, 0, 0), (1, 1, 0.2), (0, 1, 0.1)])
    for p, q in zip(n, n[1:] + n[:1]):
        m.beam(p, q, sec, up=(0, 0, 1), n=2)
    ctrl = m.node(0.5, 0.5, 0.5)
    m.rigid_body(ctrl, n)
    axis = np.array([1.0, -2.0, 0.5])
    m.step("turn", initial_increment=0.1).rotate(ctrl, axis, 2.5).prescribe(ctrl, ux=0.1, uy=0, uz=0)
    res = fm.solve(m, tempfile.mkdtemp(), progress=False)
    Q = expm_so3(2.5 * axis / np.linalg.norm(axis))
    X = m.coordinates
    c = X[m.index(ctrl)]
    expect = (X - c) @ Q.T + c + np.array([0.1, 0, 0])
    np.testing.assert_allclose(X + res.frame(-1)["U"], expect, atol=1e-12)  # exact rigid motion
    assert np.abs(res.frame(-1)["el/beam/section_forces"]).max() < 1e-6  # N, N m: no deformation


def test_reduced_tangent_with_rigid_body_matches_finite_differences():
    # loaded, deformed tower: the reduced tangent T^T K T + G (lever-arm term) against central FD
    m, ctrl, tops, sec = _tower()
    side = m.node(0.6, 0.0, 0.5)  # an extra tied node carrying a load
    m.rigid_bodies[0] = m.rigid_bodies[0].__class__("top frame", ctrl, tuple(tops) + (side,))
    m.truss(side, m.node(1.2, 0.0, 0.0), EA=1e6)
    m.fix(m.node_labels[-1])
    m.step("load").load(side, fz=-500.0, fx=300.0)
    an = Analysis(m, tempfile.mkdtemp(), progress=False)
    an.run()
    P = an.loads
    ctx = IncrementContext()
    nf = an.dofmap.n_free

    def residual(shift):
        x0, R0, s0 = an.x.copy(), an.R.copy(), an.spin.copy()
        an.system.update(shift)
        r = an.system.residual(an.system.evaluate(ctx), P)[:nf]
        an.x, an.R, an.spin = x0, R0, s0
        return r

    resp = an.system.evaluate(ctx)
    an.system.residual(resp, P)
    K = an.system.tangent(resp, False)[0].toarray()
    h = 1e-7
    Kfd = -np.column_stack([(residual(h * e) - residual(-h * e)) / (2 * h) for e in np.eye(nf)])
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()  # FD truncation/roundoff ~1e-9 relative


def test_tie_pins_coincident_nodes():
    # two cantilevers meeting at a pin (translations tied): a tip load is shared; the pin transmits
    # no moment, so the second beam's root moment is its share times its length (1e-9: linear theory)
    m = fm.Model("pin")
    sec = fm.circular_tube(0.02, 0.016, E=70e9)
    a, b1 = m.node(0, 0, 0), m.node(1, 0, 0)
    c, b2 = m.node(2, 0, 0), m.node(1, 0, 0)
    m.beam(a, b1, sec, n=2)
    m.beam(c, b2, sec, n=2)
    m.fix(a)
    m.fix(c)
    m.tie(b1, b2)
    m.step("load").load(b1, fz=-1e-3)
    res = fm.solve(m, tempfile.mkdtemp(), progress=False)
    # equal cantilevers: each carries half; root moments P/2 * L
    assert res.node_history(a, "rmy")[-1] == pytest.approx(-0.5e-3, rel=1e-6)
    assert res.node_history(c, "rmy")[-1] == pytest.approx(0.5e-3, rel=1e-6)
    np.testing.assert_allclose(res.frame(-1)["U"][m.index(b1)], res.frame(-1)["U"][m.index(b2)], atol=1e-18)


def test_constraint_bad_input():
    m = fm.Model()
    a, b, c = m.node(0, 0, 0), m.node(1, 0, 0), m.node(0, 1, 0)
    with pytest.raises(fm.ModelError, match="fewer than two nodes"):
        m.rigid_body(a, [a])
    m.rigid_body(a, [b], name="one")
    m.rigid_body(c, [b], name="two")
    m.beam(a, c, fm.circular_tube(0.02, 0.01, E=1e9))
    m.step("s")
    with pytest.raises(fm.ModelError, match="node 2 is in two constraints"):
        Analysis(m, tempfile.mkdtemp(), progress=False)
    m2 = fm.Model()
    a, b = m2.node(0, 0, 0), m2.node(1, 0, 0)
    m2.beam(a, b, fm.circular_tube(0.02, 0.01, E=1e9))
    r = m2.node(0.5, 0, 0)
    m2.rigid_body(r, [b])
    m2.fix(b)
    m2.step("s")
    with pytest.raises(fm.ModelError, match="node 2 ux is dependent .* fix or drive the reference"):
        Analysis(m2, tempfile.mkdtemp(), progress=False)
