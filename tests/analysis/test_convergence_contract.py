"""A convergence test of the user's own (femast.analysis.convergence, the contract Newton honours):
OpenSees' NormDispIncr written here, as a class of its own and as a subclass of fm.Convergence
overriding ``check``.  References: the test's own rule (each attempt stops at the first iteration
whose correction norm is at most the tolerance, and not before), the iteration cap it sets, and the
linear cantilever P L^3 / (3 E I) for the answer."""

import numpy as np
import pytest

import femast as fm
from femast.analysis import Analysis

E, L, P = 70e9, 1.0, -5.0  # Pa, m, N: deflection/length ~1e-3, geometric nonlinearity ~1e-6
SEC = fm.circular_tube(0.02, 0.016, E=E)


class NormDispIncr:
    """OpenSees' ``test NormDispIncr tol max_iterations``: converged when the 2-norm of the
    correction (m and rad alike) is at most ``tol``."""

    def __init__(self, tol, max_iterations):
        self.tol, self.max_iterations = tol, max_iterations
        self.calls = []  # (iteration, |du|) of every check

    def check(self, r, du, Du, is_rot, ref_force, ref_moment, length, iteration):
        norm = float(np.linalg.norm(du))
        self.calls.append((iteration, norm))
        return norm <= self.tol, norm / self.tol


class NormDispIncrConvergence(fm.Convergence):
    """The same rule as a subclass of femast's test that overrides the documented ``check``."""

    def __init__(self, tol, max_iterations):
        super().__init__(max_iterations=max_iterations)
        self.tol, self.calls = tol, []

    def check(self, r, du, Du, is_rot, ref_force, ref_moment, length, iteration=0):
        norm = float(np.linalg.norm(du))
        self.calls.append((iteration, norm))
        return norm <= self.tol, norm / self.tol


def _cantilever(convergence, load=P, increments=4):
    m = fm.Model("cantilever")
    a, b = m.node(0, 0, 0), m.node(L, 0, 0)
    m.beam(a, b, SEC, up=(0, 0, 1), n=8)
    m.fix(a)
    m.step("load", initial_increment=1 / increments, max_increment=1 / increments).load(b, fz=load)
    an = Analysis(m, None, progress=False, on_frame=lambda fr: None, convergence=convergence)
    an.run()
    return an, an.x[m.index(b)] - an.X0[m.index(b)]


def _attempts(calls):
    """The checks split into attempts (the iteration count restarts at 1)."""
    out = []
    for it, norm in calls:
        if it == 1:
            out.append([])
        out[-1].append(norm)
    return out


@pytest.mark.parametrize("cls", [NormDispIncr, NormDispIncrConvergence])
def test_newton_stops_exactly_where_the_users_test_says(cls):
    test = cls(1e-9, 40)
    an, tip = _cantilever(test)
    attempts = _attempts(test.calls)
    assert len(test.calls) == an.summary.iterations  # one check per iteration, none skipped
    assert len(attempts) == an.summary.increments == 4  # no cutback
    for norms in attempts:  # each attempt ends at its first correction within the tolerance
        assert norms[-1] <= 1e-9 and all(n > 1e-9 for n in norms[:-1])
    linear = P * L**3 / (3 * E * SEC.Iy)
    assert tip[2] == pytest.approx(linear, rel=1e-4)  # nonlinearity ~1e-6 of it


@pytest.mark.parametrize("cls", [NormDispIncr, NormDispIncrConvergence])
def test_a_loose_test_of_your_own_takes_fewer_iterations_than_femasts(cls):
    # a 1e-4 m correction is far above femast's default correction test (1e-6 of the increment)
    loose = cls(1e-4, 40)
    an_loose, _ = _cantilever(loose, load=-400.0)
    an_default, _ = _cantilever(None, load=-400.0)
    assert an_loose.summary.iterations < an_default.summary.iterations
    assert all(norms[-1] <= 1e-4 for norms in _attempts(loose.calls))


@pytest.mark.parametrize("cls", [NormDispIncr, NormDispIncrConvergence])
def test_the_users_iteration_cap_is_the_one_used(cls):
    never = cls(1e-300, 3)  # never met: every attempt runs to the user's 3 iterations
    with pytest.raises(fm.ConvergenceError, match="no convergence in 3 iterations"):
        _cantilever(never)
    assert {len(norms) for norms in _attempts(never.calls)} == {3}


def test_a_test_without_check_or_with_a_bad_cap_is_refused_in_one_line():
    class NoCheck:
        max_iterations = 10

    with pytest.raises(fm.ModelError, match="NoCheck: a convergence test needs a method check"):
        _cantilever(NoCheck())
    with pytest.raises(fm.ModelError, match="max_iterations=2.5 must be a whole number"):
        _cantilever(NormDispIncr(1e-9, 2.5))
