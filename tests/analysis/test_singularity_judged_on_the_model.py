"""Singularity judged on the model: the linear solver never calls a tangent singular that a sparse LU
solves (a pivot is judged against its own DOF's stiffness, and a suspect factorisation is confirmed
by SuperLU with partial pivoting), while a real mechanism is still refused and named by its DOFs.

Models: a telescoping column (three nested tubes joined at two overlaps by rigid bodies carrying
pads, a stiff axial strut and a soft torsion pad, the bearing planes a few mm from the tubes' mesh
nodes), a chain of springs from 1e12 down to 1e-3 N/m (and the other way round) against the series
closed form, and two real mechanisms."""

import numpy as np
import pytest

import femast as fm


def telescoping_column(EI, k, tip=3.867, length=1.5, n=6):
    """Three tubes (EI, N m^2) of ``length`` on one axis, the middle one starting at 1.253 m and the
    top one ending at ``tip`` (m); at each overlap, two bearing planes (the inner tube's bottom, the
    outer tube's top).  A bearing plane: a rigid body on the outer tube's node carrying four
    horizontal truss pads to the inner tube's node on 0.1 m arms (k/2 N/m each way), a stiff axial
    strut (EA = 1e9 N/m x its 0.1 m) and, to a 0.1 m arm on the inner tube, a soft torsion pad
    (EA = 1e-2 k x 0.1 m).  Tip loaded sideways and down.  Returns (model, tip node)."""
    E = 70e9
    sec = fm.Section(E=E, G=E / 2.6, A=0.01, Iy=EI / E, Iz=EI / E, J=2 * EI / E, name="tube")
    m = fm.Model("telescoping column")
    spans = [(0.0, length), (1.253, 1.253 + length), (tip - length, tip)]
    planes = [(spans[1][0], spans[0][1]), (spans[2][0], spans[1][1])]
    cuts = {round(z, 9) for pl in planes for z in pl}
    tubes = []
    for z0, z1 in spans:
        zs = sorted(set(np.round(np.linspace(z0, z1, n + 1), 9)) | {c for c in cuts if z0 < c < z1})
        nodes = [m.node(0, 0, z) for z in zs]
        for a, b in zip(nodes[:-1], nodes[1:]):
            m.beam(a, b, sec, up=(1, 0, 0))
        tubes.append(dict(zip(zs, nodes)))
    m.fix(tubes[0][0.0])
    arm = 0.1
    for j, pl in enumerate(planes):
        for z in (round(z, 9) for z in pl):
            outer, inner = tubes[j][z], tubes[j + 1][z]
            arms = [m.node(dx, dy, z) for dx, dy in ((arm, 0), (-arm, 0), (0, arm), (0, -arm))]
            strut = m.node(0, 0, z - arm)
            m.rigid_body(outer, arms + [strut])
            for a in arms:
                m.truss(a, inner, EA=k / 2 * arm)
            m.truss(strut, inner, EA=1e9 * arm)
            t = m.node(arm, arm, z)
            m.rigid_body(inner, [t])
            m.truss(arms[0], t, EA=1e-2 * k * arm)
    top = tubes[2][round(tip, 9)]
    m.step("load").load(top, fx=1e3, fz=-2e3)
    return m, top


@pytest.mark.parametrize(
    "EI, k, tip",
    [
        (5e7, 1e6, 3.867),
        (5e8, 1e8, 3.867),
        # the top tube's lower bearing plane 1.3 mm below a mesh node of the middle tube: a 1.3 mm beam
        # element (12 EI / L^3 ~ 3e18 N/m) beside 5e7 N/m pads and a 1e6 N/m torsion pad, where a pivot test against the largest
        # pivot of the whole tangent calls the sideways DOFs a mechanism
        (5e8, 1e8, 4.0017),
    ],
)
def test_the_telescoping_column_is_solved_by_the_default_solver(EI, k, tip):
    """EI (N m^2), k (N/m), tip (m): the default solver and SuperLU agree on the tip's displacement."""
    tips = {}
    for solver in ("auto", "superlu"):
        m, top = telescoping_column(EI, k, tip=tip)
        an = fm.Analysis(m, None, progress=False, on_frame=lambda fr: None, linear_solver=solver)
        an.run()  # (no SingularModelError; the end of the run is checked for equilibrium)
        i = m.index(top)
        tips[solver] = an.x[i] - an.X0[i]
    # two independent factorisations (LAPACK's band solver, or SuperLU's confirmation, vs SuperLU)
    np.testing.assert_allclose(tips["auto"], tips["superlu"], rtol=1e-7, atol=1e-9 * np.abs(tips["superlu"]).max())
    assert tips["auto"][0] > 0.0  # pushed sideways (+x), as loaded


def _chain(ks, F):
    m = fm.Model("spring chain")
    nodes = [m.node(float(i), 0, 0) for i in range(len(ks) + 1)]
    for a, b, k in zip(nodes[:-1], nodes[1:], ks):
        m.truss(a, b, EA=k * 1.0)  # (1 m long: EA / L = k)
    m.fix(nodes[0])
    for n in nodes[1:]:
        m.fix(n, "uy", "uz")
    m.step("pull").load(nodes[-1], fx=F)
    return m, nodes[-1]


@pytest.mark.parametrize("order", ["stiff at the support", "soft at the support"])
@pytest.mark.parametrize("solver", ["auto", "banded", "superlu"])
def test_a_spring_chain_spanning_1e_3_to_1e12_n_per_m_matches_the_series_closed_form(order, solver):
    ks = 10.0 ** np.arange(12, -4, -1)  # 1e12 ... 1e-3 N/m
    ks = ks if order == "stiff at the support" else ks[::-1]
    F = 1e-6  # N: the softest spring stretches 1 mm
    m, tip = _chain(ks, F)
    an = fm.Analysis(m, None, progress=False, on_frame=lambda fr: None, linear_solver=solver)
    an.run()
    i = m.index(tip)
    # springs in series carry the same force: the tip moves F sum(1/k) (N = EA (l - L0) / L0 exactly)
    assert an.x[i, 0] - an.X0[i, 0] == pytest.approx(F * np.sum(1.0 / ks), rel=1e-7)


def test_a_real_mechanism_is_still_refused_and_named_by_its_dofs():
    """A square frame of four pin-jointed trusses without a diagonal sways freely in its plane."""
    m = fm.Model("sway")
    a, b, c, d = m.node(0, 0, 0), m.node(1, 0, 0), m.node(1, 1, 0), m.node(0, 1, 0)
    for p, q in ((a, b), (b, c), (c, d), (d, a)):
        m.truss(p, q, EA=1e6)
    m.fix(a)
    m.fix(b)
    for n in (c, d):
        m.fix(n, "uz")
    m.step("push").load(c, fx=10.0)
    with pytest.raises(fm.SingularModelError) as err:
        fm.solve(m, None, progress=False, on_frame=lambda fr: None)
    msg = str(err.value)
    assert "the free DOFs of the mechanism include" in msg
    assert "node 3 ux" in msg and "node 4 ux" in msg  # the sway: both top nodes along x


def test_a_beam_free_to_twist_is_named_by_its_torsion_dofs():
    m = fm.Model("twist")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=2)
    m.fix(a, "ux", "uy", "uz", "ry", "rz")  # torsion (rx) left free
    m.step("load").load(b, fz=-10.0)
    with pytest.raises(fm.SingularModelError, match=r"mechanism include: .*node \d+ rx"):
        fm.solve(m, None, progress=False, on_frame=lambda fr: None)
