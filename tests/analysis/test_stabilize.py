"""Viscous stabilisation (*STABILIZE) of an initially unstable step."""

import tempfile

import numpy as np
import pytest
from scipy.optimize import fsolve

import femast as fm

H, A = 2.0, 1.0  # mast height, anchor offset (m)
EA_MAST, EA_GUY = 1e7, 2e5  # N
SLACK = 3e-4  # guys 0.03 % longer than their initial span: slack at the start
PX, PZ = 50.0, -400.0  # top load (N): lateral and compressive


def _guyed_mast(stabilize=None, second_step=False):
    """A pin-based bar mast with two slack guys, loaded at the top (planar: top uy fixed).
    At the start the mast is a mechanism (its lean is resisted by nothing)."""
    m = fm.Model("guyed")
    base, top = m.node(0, 0, 0), m.node(0, 0, H)
    left, right = m.node(-A, 0, 0), m.node(A, 0, 0)
    m.truss(base, top, EA=EA_MAST, family="mast")
    span = np.hypot(A, H)
    for anchor in (left, right):
        m.truss(anchor, top, EA=EA_GUY, L0=span * (1 + SLACK), tension_only=True, family=f"guy{anchor}")
        m.fix(anchor)
    m.fix(base)
    m.fix(top, "uy")
    s = m.step("load", initial_increment=0.1, stabilize=stabilize)
    s.load(top, fx=PX, fz=PZ)
    if second_step:
        m.step("settle", initial_increment=1.0)
    return m, top


def _exact_equilibrium():
    """Top position from equilibrium of the two-bar system (bar + taut left guy), by fsolve from
    a good starting point: independent of femast's elements and solver."""
    L_guy0 = np.hypot(A, H) * (1 + SLACK)

    def residual(p):
        x, z = p
        lb = np.hypot(x, z)
        Nb = EA_MAST * (lb - H) / H
        lg = np.hypot(x + A, z)
        Ng = max(EA_GUY * (lg - L_guy0) / L_guy0, 0.0)
        f = Nb * np.array([x, z]) / lb + Ng * np.array([x + A, z]) / lg
        return [PX - f[0], PZ - f[1]]

    return fsolve(residual, [0.05, H], xtol=1e-14)


def test_unstabilised_initial_step_fails():
    m, top = _guyed_mast()
    with pytest.raises((fm.SingularModelError, fm.ConvergenceError), match=r"node 2 ux"):
        fm.solve(m, tempfile.mkdtemp(), progress=False)


def test_stabilised_step_converges_near_equilibrium_with_small_energy_ratio():
    m, top = _guyed_mast(fm.Stabilize(), second_step=True)
    an = fm.Analysis(m, tempfile.mkdtemp(), progress=False)
    res = an.run()
    info = an.summary.steps[0]
    assert 0 < info["stabilization_ratio"] < 0.05  # the 5 % bound
    x_exact, z_exact = _exact_equilibrium()
    steps = res.steps
    i_stab = max(i for i, s in enumerate(steps) if s == "load")
    pos = res.X[m.index(top)] + res.frame(i_stab)["U"][m.index(top)]
    # stabilised end state: the viscous forces of the last increment bias it; with an energy
    # ratio of ~2 % the lean (4.6 mm) is within 1e-5 m (observed 5.5e-7 m)
    assert pos[0] == pytest.approx(x_exact, abs=1e-5)
    assert pos[2] == pytest.approx(z_exact, abs=1e-5)
    # the following unstabilised step, started from there, reaches the exact equilibrium
    # (Newton force tolerance 1e-6 -> 1e-9 m with these stiffnesses)
    pos = res.X[m.index(top)] + res.frame(-1)["U"][m.index(top)]
    assert pos[0] == pytest.approx(x_exact, abs=1e-9)
    assert pos[2] == pytest.approx(z_exact, abs=1e-9)


def test_large_damping_warns():
    m, top = _guyed_mast(fm.Stabilize(factor=50.0))
    with pytest.warns(fm.analysis.StabilizationWarning, match="stabilisation energy is"):
        fm.Analysis(m, tempfile.mkdtemp(), progress=False).run()


def test_damped_tangent_keeps_the_tangents_pattern_and_equals_scipys_sum():
    import scipy.sparse as sp

    from femast.analysis import Analysis

    an = Analysis(_guyed_mast()[0], tempfile.mkdtemp(), progress=False)
    rng = np.random.default_rng(5)
    K = sp.random(6, 6, density=0.4, random_state=5, format="csr") + sp.eye(6, format="csr")
    K.data[::3] = 0.0  # explicit zeros, as early in a stabilised step
    c = rng.random(6)
    D = an.system.plus_diagonal(K, c)
    np.testing.assert_array_equal(D.toarray(), (K + sp.diags(c)).toarray())  # the same sums, same bits
    assert np.array_equal(D.indptr, K.indptr) and np.array_equal(D.indices, K.indices)  # zeros kept:
    assert D.nnz == K.nnz  # one pattern
    assert an.system.plus_diagonal(K, 2 * c) is D  # refilled in place
    np.testing.assert_array_equal(D.toarray(), (K + sp.diags(2 * c)).toarray())
    K2 = sp.csr_matrix(np.triu(np.ones((4, 4)), 1))  # no diagonal entries: scipy's sum
    np.testing.assert_array_equal(
        an.system.plus_diagonal(K2, np.ones(4)).toarray(), np.triu(np.ones((4, 4)), 1) + np.eye(4)
    )


def test_a_stabilised_adam_run_analyses_one_ordering():
    # before, scipy's sum dropped the zero entries of the early damped tangents: each new nonzero
    # made a new pattern and a new ordering analysis (four per run of a mast)
    from femast.adam import build_mast
    from femast.adam.steps import CONVERGENCE, add_initial_steps
    from femast.analysis import Analysis

    am = build_mast(2)
    add_initial_steps(am)
    assert any(st.stabilize is not None for st in am.model.steps)
    am.model.step("load", initial_increment=0.5).load(am.control, mz=6.8, fx=5.0)
    an = Analysis(am.model, None, progress=False, convergence=CONVERGENCE, on_frame=lambda fr: None)
    an.run()
    assert an.solver.analyses == 1
