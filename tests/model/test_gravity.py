"""Gravity (step.gravity): body forces from the mass model against closed forms: a cantilever
under its own weight, a hanging cable (the exact equilibrium of an elastic chain, and the elastic
catenary), point masses with offsets and rigid bodies, ramps and removal over steps."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import femast as fm
from femast.errors import ModelError

G = 9.81


def _run(m):
    """The last frame (U, URA, RF: (n, 6) reactions) and the analysis."""
    last = {}

    def keep(d):
        last.update(U=d["U"].copy(), URA=d["URA"].copy(), RF=d["RF"].copy(), step=d["step"])

    an = fm.Analysis(m, None, progress=False, on_frame=keep)
    an.run()
    return last, an


def _cantilever(n=8, rho=2700.0, L=1.0, axis=(1, 0, 0)):
    sec = fm.circular_tube(0.02, 0.016, E=70e9).with_(rho=rho)
    m = fm.Model("self-weight")
    a, b = m.node(0, 0, 0), m.node(*(L * np.asarray(axis, float)))
    m.beam(a, b, sec, n=n)
    m.fix(a)
    return m, sec, a, b


@pytest.mark.parametrize("n", [1, 4])
def test_cantilever_under_self_weight(n):
    """Tip deflection q L^4 / 8EI, tip rotation q L^3 / 6EI (consistent loads: exact at the nodes);
    root reactions: the weight and q L^2 / 2.  L = 0.5 m: w/L = 1.4e-4, geometric terms ~ 2e-8."""
    L = 0.5
    m, sec, a, b = _cantilever(n=n, L=L)
    m.step("weight").gravity(g=(0, 0, -G))
    fr, _ = _run(m)
    q = sec.rho * sec.A * G
    EI = sec.E * sec.Iy
    assert fr["U"][m.index(b), 2] == pytest.approx(-q * L**4 / (8 * EI), rel=1e-6)
    assert fr["URA"][m.index(b), 1] == pytest.approx(q * L**3 / (6 * EI), rel=1e-6)
    RF = fr["RF"][m.index(a)]
    assert RF[2] == pytest.approx(q * L, rel=1e-12)
    assert RF[4] == pytest.approx(-q * L**2 / 2, rel=1e-6)


def test_gravity_adds_to_a_concentrated_load_at_the_same_node():
    L = 0.5
    m, sec, a, b = _cantilever(n=4, L=L)
    P = 0.5
    m.step("weight and load").gravity(g=(0, 0, -G)).load(b, fz=-P)
    fr, _ = _run(m)
    q = sec.rho * sec.A * G
    EI = sec.E * sec.Iy
    w = fr["U"][m.index(b), 2]
    assert w == pytest.approx(-q * L**4 / (8 * EI) - P * L**3 / (3 * EI), rel=1e-6)


def test_gravity_ramps_stays_and_is_removed():
    """Step 1 applies g, step 2 a load only (g stays), step 3 removes g (the load stays)."""
    L = 0.5
    m, sec, a, b = _cantilever(n=4, L=L)
    m.step("g").gravity()
    m.step("load").load(b, fy=0.5)
    m.step("no g").gravity(g=(0, 0, 0))
    tips = []
    an = fm.Analysis(m, None, progress=False, on_frame=lambda d: tips.append((d["step"], d["U"][m.index(b)].copy())))
    an.run()
    q = sec.rho * sec.A * G
    EI = sec.E * sec.Iy
    last = {s: u for s, u in tips}
    assert sorted(last) == ["g", "initial", "load", "no g"]
    last = {1: last["g"], 2: last["load"], 3: last["no g"]}
    wq = q * L**4 / (8 * EI)
    wp = 0.5 * L**3 / (3 * EI)
    assert last[1][2] == pytest.approx(-wq, rel=1e-6) and abs(last[1][1]) < 1e-12 * wq
    assert last[2][2] == pytest.approx(-wq, rel=1e-5) and last[2][1] == pytest.approx(wp, rel=1e-5)
    assert abs(last[3][2]) < 1e-6 * wq and last[3][1] == pytest.approx(wp, rel=1e-6)


def test_point_mass_with_offset_and_rigid_body():
    """A rigid body (mass m, centre of mass at c) on a vertical column: the base reactions are the
    weight and the moment of the weight about the base, (c - base) x (m g)."""
    m = fm.Model("column with a mass")
    base, top = m.node(0, 0, 0), m.node(0, 0, 1.0)
    m.beam(base, top, fm.circular_tube(0.3, 0.24, E=200e9), up=(1, 0, 0), n=2)
    m.fix(base)
    ref = m.node(0, 0, 1.2)
    mass, centre = 30.0, np.array([0.3, -0.1, 1.25])
    m.rigid_body(ref, [top], mass=mass, centre=centre)
    pm = 2.0
    m.point_mass(top, pm, offset=(0.0, 0.2, 0.0))
    m.step("weight").gravity(g=(0, 0, -G))
    fr, _ = _run(m)
    RF = fr["RF"][m.index(base)]
    W = np.array([0, 0, -G])
    # reactions balance the weight (small displacements: moments about the initial geometry)
    assert np.allclose(RF[:3], -(mass + pm) * W, rtol=0, atol=1e-8 * (mass + pm) * G)
    M_expected = -(np.cross(centre, mass * W) + np.cross([0, 0.2, 1.0], pm * W))
    assert np.allclose(RF[3:], M_expected, rtol=1e-5)  # (a stiff column: its sway moves the lever arms by 1e-6)


def _chain_reference(n, span, L0, EA, W):
    """Exact equilibrium of n elastic links (unstretched L0/n each) between supports at the same
    height, loads W/n at the n-1 interior nodes (lumped mass: the supports take the end halves):
    horizontal force H from the span by bisection; returns (H, sag at mid-span)."""
    l0 = L0 / n
    P = W / n

    def shape(H):
        V = 0.5 * (n - 1) * P  # vertical force in the first link (symmetry)
        x = z = 0.0
        zs = [0.0]
        for _ in range(n):
            T = math.hypot(H, V)
            ell = l0 * (1 + T / EA)
            x += ell * H / T
            z -= ell * V / T
            zs.append(z)
            V -= P
        return x, zs

    H = brentq(lambda H: shape(H)[0] - span, 1e-6 * W, 1e6 * W, xtol=1e-14 * W, rtol=1e-15)
    return H, -shape(H)[1][n // 2]


def _elastic_catenary_sag(span, L0, EA, W):
    """Irvine's elastic catenary (supports level): span = 2H/w asinh(V/H) + H L0/EA, V = W/2,
    sag = (sqrt(H^2 + V^2) - H)/w + w L0^2 / (8 EA), w = W/L0."""
    w, V = W / L0, W / 2
    H = brentq(lambda H: 2 * H / w * math.asinh(V / H) + H * L0 / EA - span, 1e-6 * W, 1e6 * W, xtol=1e-14 * W)
    return H, (math.hypot(H, V) - H) / w + w * L0**2 / (8 * EA)


@pytest.mark.parametrize("n", [16, 64])
def test_hanging_cable_sag(n):
    span, EA, T0, mpl = 10.0, 2e5, 50.0, 0.5
    m = fm.Model("hanging cable")
    nodes = [m.node(x, 0, 0) for x in np.linspace(0, span, n + 1)]
    for a, b in zip(nodes[:-1], nodes[1:]):
        m.truss(a, b, EA=EA, pretension=T0, tension_only=True, mass_per_length=mpl)
    m.fix(nodes[0])
    m.fix(nodes[-1])
    for nd in nodes[1:-1]:
        m.fix(nd, "uy")
    m.step("weight", initial_increment=0.1).gravity()
    fr, _ = _run(m)
    W = mpl * span * G  # mass per drawn length
    L0 = span / (1 + T0 / EA)
    sag = -fr["U"][m.index(nodes[n // 2]), 2]
    H, sag_chain = _chain_reference(n, span, L0, EA, W)
    assert sag == pytest.approx(sag_chain, rel=1e-8)
    assert fr["RF"][m.index(nodes[0]), 0] == pytest.approx(-H, rel=1e-8)
    # the continuous elastic catenary, to the chain's discretisation error O(1/n^2)
    _, sag_cat = _elastic_catenary_sag(span, L0, EA, W)
    assert sag == pytest.approx(sag_cat, rel=2.0 / n**2)


def test_bad_gravity_is_named():
    m, sec, a, b = _cantilever(n=2)
    s = m.step("g")
    with pytest.raises(ModelError, match="implausible.*m/s\\^2"):
        s.gravity(g=(0, 0, -9810.0))
    with pytest.raises(ModelError, match="3-vector"):
        s.gravity(g=(0, -9.81))
    m2, *_ = _cantilever(n=2, rho=0.0)
    m2.step("g").gravity()
    with pytest.raises(ModelError, match="gravity on a model without mass"):
        _run(m2)
