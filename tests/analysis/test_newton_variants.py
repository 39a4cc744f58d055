"""Newton variants: Broyden's update, modified and quasi-Newton runs reaching
the full-Newton solution with fewer factorisations than iterations, the options' errors."""

from __future__ import annotations

import numpy as np
import pytest

import femast as fm
from femast.analysis import Analysis
from femast.analysis.newton import Newton
from femast.analysis.tangent_update import Broyden


def test_broyden_solves_an_affine_system_from_a_wrong_inverse():
    """Good Broyden on F(x) = b - A x from H0 = A0^-1 (A0 != A): Gay's theorem bounds the
    iterations by 2n for an affine map; the result is the exact solution."""
    rng = np.random.default_rng(0)
    n = 6
    A = rng.normal(size=(n, n)) + 6 * np.eye(n)  # unsymmetric, well conditioned
    A0 = A + 0.3 * rng.normal(size=(n, n))  # the factorised (wrong) matrix
    b = rng.normal(size=n)
    solve = lambda v: np.linalg.solve(A0, v)  # noqa: E731
    br = Broyden()
    x = np.zeros(n)
    r = b - A @ x
    for k in range(2 * n + 1):  # noqa: B007 (the count is read after the loop)
        s = br.direction(solve, r)
        x = x + s
        r = b - A @ x
        br.step(s, r)
        if np.abs(r).max() <= 1e-12 * np.abs(b).max():
            break
    assert k + 1 <= 2 * n  # Gay (1979): at most 2n steps on an affine problem
    np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=0, atol=1e-10 * np.abs(b).max())


def _bent_cantilever():
    m = fm.Model("cantilever")
    a, b = m.node(0, 0, 0), m.node(1.0, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), up=(0, 0, 1), n=8)
    m.fix(a)
    m.step("bend", initial_increment=0.25, max_increment=0.25).load(b, fz=-400.0, my=30.0)
    return m, b


@pytest.mark.parametrize("tangent", ["modified", "quasi-newton"])
def test_modified_and_quasi_newton_reach_the_full_newton_solution(tangent):
    conv = fm.Convergence(force_tol=1e-9, disp_tol=1e-9, max_iterations=60)
    runs = {}
    for t in ("full", tangent):
        m, tip = _bent_cantilever()
        an = Analysis(m, None, progress=False, on_frame=lambda fr: None, tangent=t, convergence=conv)
        an.run()
        runs[t] = (an.x[m.index(tip)] - an.X0[m.index(tip)], an.summary.iterations, an.solver.factorizations)
    (u_full, it_full, f_full), (u, it, f) = runs["full"], runs[tangent]
    assert f_full == it_full  # full Newton: one factorisation per iteration
    assert f < it  # the variant reuses factorisations
    # both meet the 1e-9 displacement test; the large deflection (0.3 m) amplifies little
    np.testing.assert_allclose(u, u_full, rtol=0, atol=1e-7 * np.abs(u_full).max())


def _run(m, **kw):
    an = Analysis(m, None, progress=False, on_frame=lambda fr: None, **kw)
    an.run()
    return an


def test_auto_is_full_newton_reusing_the_last_factorisation_at_the_next_increment():
    m, tip = _bent_cantilever()
    auto = _run(m)
    assert auto.algorithm.method() == "full"
    s = auto.summary
    # every increment after the first starts on the previous one's last factorisation
    assert s.increments == 4 and auto.solver.factorizations == s.iterations - (s.increments - 1)
    m, _ = _bent_cantilever()
    full = _run(m, tangent="full")
    assert full.solver.factorizations == full.summary.iterations  # "full": a new tangent every iteration
    # the reused tangent is one converged correction away from the exact one: the same solution to
    # far below the 1e-6 tolerances (quadratic convergence from there)
    i = m.index(tip)
    u_auto, u_full = auto.x[i] - auto.X0[i], full.x[i] - full.X0[i]
    np.testing.assert_allclose(u_auto, u_full, rtol=0, atol=1e-9 * np.abs(u_full).max())


def test_auto_reuses_no_factorisation_across_steps_or_with_path_dependent_families():
    m, tip = _bent_cantilever()
    m.step("more", initial_increment=0.5, max_increment=0.5).load(tip, fz=-500.0, my=30.0)
    an = _run(m)
    s = an.summary
    assert [st["increments"] for st in s.steps] == [4, 2]
    assert an.solver.factorizations == s.iterations - (4 - 1) - (2 - 1)  # none at each step's start
    m, _ = _bent_cantilever()
    an = Analysis(m, None, progress=False, on_frame=lambda fr: None)
    for f in an.families:
        f.path_independent = False  # a response that may depend on more than the configuration
    an.run()
    assert an.solver.factorizations == an.summary.iterations


@pytest.mark.parametrize(
    "kw, match",
    [(dict(refactor_every=0), "refactor_every"), (dict(slow=1.5), "slow"), (dict(tangent="bfgs"), "tangent='bfgs'")],
)
def test_bad_newton_options_are_model_errors(kw, match):
    with pytest.raises(fm.ModelError, match=match):
        Newton(**kw)
