"""The predicted-correction acceptance of Newton iterations: an iteration whose force test
passes is accepted when its simplified Newton correction (one more solve with the factorisation in
hand) shows the next correction below the correction tolerance (femast/analysis/convergence.py).

Checks: one iteration fewer than the strict rule on a hardening spring whose equilibrium is the
root of a cubic (closed form) and on a large-deflection cantilever (against a tightly converged
run), each answer within the correction tolerance; the rule's refusals (a non-contracting sequence,
one iteration's rate, a provisional answer); the strict rule still selectable; bad options.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import femast as fm
from femast.analysis import Analysis
from femast.analysis.convergence import Convergence, scaled_size
from femast.analysis.newton import accept_predicted
from femast.elements.base import ElementFamily, ElementResponse
from femast.errors import ModelError

K, U0 = 1e3, 0.01  # the spring: f(u) = K u (1 + (u / U0)^2), N and m


class _Hardening(ElementFamily):
    """A hardening spring on ux of one node (at x = 1 m), uy and uz held by linear springs K;
    ``band`` = (lo, hi, u_star): answers with lo < |u - u_star| < hi (m) are provisional."""

    active_dofs = (0, 1, 2)
    path_independent = True

    def __init__(self, node, band=None):
        self.name, self.nodes, self.band = "hardening", np.array([[node]]), band

    def evaluate(self, x, R, state, ctx=None):
        p = x[self.nodes[0, 0]]
        u = p[0] - 1.0
        f = np.zeros((1, 6))
        k = np.zeros((1, 6, 6))
        f[0, 0] = K * u * (1.0 + (u / U0) ** 2)
        k[0, 0, 0] = K * (1.0 + 3.0 * (u / U0) ** 2)
        for i in (1, 2):
            f[0, i] = K * p[i]
            k[0, i, i] = K
        prov = self.band is not None and self.band[0] < abs(u - self.band[2]) < self.band[1]
        return ElementResponse(f=f, k=k, state=state, provisional=prov)


def _u_star(P):
    """The spring's equilibrium under P (N): the real root of K u^3 / U0^2 + K u - P = 0 (Cardano:
    one real root, the cubic is increasing)."""
    a = K / U0**2
    q, r = K / (3 * a), -P / (2 * a)  # depressed cubic u^3 + 3 q u + 2 r = 0
    s = math.sqrt(r * r + q**3)
    return math.copysign(abs(-r + s) ** (1 / 3), -r + s) + math.copysign(abs(-r - s) ** (1 / 3), -r - s)


def _spring(P, band=None, **conv):
    m = fm.Model("spring")
    n = m.node(1.0, 0.0, 0.0)
    m.add_family(_Hardening(n, band))
    m.step("pull", initial_increment=1.0, max_increment=1.0).load(n, fx=P)
    an = Analysis(m, None, progress=False, on_frame=lambda fr: None, convergence=fm.Convergence(**conv))
    an.run()
    return an.summary.iterations, an.state.x[0, 0] - 1.0


@pytest.mark.parametrize("P, tol", [(100.0, 1e-6), (10.0, 1e-3)])
def test_one_iteration_fewer_on_the_hardening_spring_within_the_tolerance(P, tol):
    u_star = _u_star(P)
    assert K * u_star * (1 + (u_star / U0) ** 2) == pytest.approx(P, rel=1e-14)  # the closed form
    it_strict, u_strict = _spring(P, force_tol=tol, disp_tol=tol, predicted=False)
    it, u = _spring(P, force_tol=tol, disp_tol=tol)
    assert it == it_strict - 1
    # one increment from u = 0: the increment is u itself; the predicted rule bounds the error left
    # by disp_tol |Du| (the estimate carries a factor 2 of margin, so this is the tolerance itself)
    assert abs(u - u_star) <= tol * abs(u)
    # ... and it does use that room: the strict rule's answer is closer (one more quadratic step)
    assert abs(u_strict - u_star) < abs(u - u_star)


def test_the_increments_step_and_one_correction_are_not_a_rate():
    # P = 0.1 N: nearly linear (u / U0 ~ 0.01); the strict rule accepts iteration 3.  Iteration 2's
    # simplified correction would pass (the rule counted from k = 2 accepted it), but its one
    # contraction is that of a correction against the increment's own first step: not a rate
    it_strict, _ = _spring(0.1, predicted=False)
    it, u = _spring(0.1)
    assert it_strict == 3 and it == 3
    assert abs(u - _u_star(0.1)) <= 1e-6 * abs(u)


def test_a_provisional_iterate_is_not_accepted_on_its_prediction():
    P = 100.0
    u_star = _u_star(P)
    it_strict, _ = _spring(P, predicted=False)
    it, u = _spring(P)
    assert it == it_strict - 1 and abs(u - u_star) > 1e-14  # the early iterate, 1.7e-7 u* away
    # the same run, with every answer 1e-14 .. 1e-4 m from the solution marked provisional: the
    # early iterate is refused, the strict one (~1e-16 m away) accepted
    it_p, u_p = _spring(P, band=(1e-14, 1e-4, u_star))
    assert it_p == it_strict
    assert abs(u_p - u_star) <= 1e-14


def _cantilever():
    m = fm.Model("cantilever")
    a, b = m.node(0, 0, 0), m.node(1.0, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), up=(0, 0, 1), n=8)
    m.fix(a)
    m.step("bend", initial_increment=0.25, max_increment=0.25).load(b, fz=-400.0, my=30.0)
    return m


def _frames(conv):
    frames = []
    an = Analysis(
        _cantilever(),
        None,
        progress=False,
        convergence=conv,
        on_frame=lambda fr: frames.append((np.array(fr["U"]), np.array(fr["UR"]))),
    )
    an.run()
    return an, frames[1:]  # the increments' frames (the first is the initial state)


def test_the_cantilever_agrees_with_a_tightly_converged_run_to_the_tolerance():
    tol = 1e-6
    strict, f_strict = _frames(fm.Convergence(force_tol=tol, disp_tol=tol, predicted=False))
    pred, f_pred = _frames(fm.Convergence(force_tol=tol, disp_tol=tol))
    _, f_ref = _frames(fm.Convergence(force_tol=1e-8, disp_tol=1e-11, predicted=False))
    assert pred.summary.increments == strict.summary.increments == 4
    # 21 -> 19: increments 3 and 4 accepted one iteration early; increment 1 passes the strict test
    # as early, increment 2's prediction (7.0e-7, true next correction 7.4e-7) is refused by the
    # factor 2 of margin
    assert pred.summary.iterations < strict.summary.iterations
    prev = (np.zeros_like(f_ref[0][0]), np.zeros_like(f_ref[0][1]))
    for (U, UR), (Ur, URr) in zip(f_pred, f_ref):
        # each field's error within disp_tol times that field's largest increment (the correction
        # test's measure; a tip deflection of ~0.3 m and rotations of ~0.5 rad)
        assert np.abs(U - Ur).max() <= tol * np.abs(Ur - prev[0]).max()
        assert np.abs(UR - URr).max() <= tol * np.abs(URr - prev[1]).max()
        prev = (Ur, URr)


def test_the_rule_refuses_one_rate_and_a_non_contracting_sequence():
    c = Convergence()  # disp_tol 1e-6, max_contraction 0.5
    # a quadratic sequence (the 40-bay mast's increment 0: corrections 9.4e-4, 2.0e-4, then c~ 6.7e-10)
    assert c.accept_predicted(9.38e-4, 2.04e-4, 6.66e-10)
    # the 1000-bay mast's soft mode: |du_3| = 0.995 |du_2|, c~ = 2.45e-8 looks converged, but the
    # true next correction was 3.6e-7 (15 x c~): not contracting, refused
    assert not c.accept_predicted(3.93e-3, 3.91e-3, 2.45e-8)
    # a prediction that itself does not contract, or whose error estimate 2 c~ / (1 - theta) is above
    # disp_tol, is refused
    assert not c.accept_predicted(1e-2, 1e-6 * 1.5, 0.9e-6)
    assert not c.accept_predicted(1e-2, 1e-3, 5e-7)
    assert c.accept_predicted(1e-2, 1e-3, 4.9e-7)
    # NaN and a zero previous correction (no rate) never accept; the strict rule never does
    for args in ((math.nan, 1e-3, 1e-12), (1e-2, math.nan, 1e-12), (1e-2, 1e-3, math.nan), (0.0, 0.0, 0.0)):
        assert not c.accept_predicted(*args)
    assert not Convergence(predicted=False).accept_predicted(9.38e-4, 2.04e-4, 6.66e-10)


class _Solver:
    def __init__(self):
        self.solves = 0

    def solve(self, r):
        self.solves += 1
        return np.asarray(r) * 1e-9


class _System:
    """What newton.accept_predicted uses of a System."""

    def __init__(self):
        self.solver, self.is_rot, self.length = _Solver(), np.array([False, False, True]), 1.0

        class _S:
            solve_time = 0.0

        self.summary = _S()

    def scaled_size(self, v, Du):
        return scaled_size(np.asarray(v, float), np.asarray(Du, float), self.is_rot, self.length)


def test_newton_solves_for_the_prediction_only_after_a_contraction():
    sys_, conv = _System(), Convergence()
    r, Du = np.array([1.0, 0.0, 0.0]), np.array([1.0, 0.0, 1.0])  # c~ = 1e-9 of Du
    assert not accept_predicted(sys_, conv, r, Du, [3.93e-3, 3.91e-3])  # not contracting
    assert sys_.solver.solves == 0
    assert accept_predicted(sys_, conv, r, Du, [1e-3, 2e-4])
    assert sys_.solver.solves == 1


def test_scaled_size_is_the_correction_test_measure():
    is_rot = np.array([False, False, True, True])
    du = np.array([1e-3, -2e-3, 0.0, 3e-4])
    Du = np.array([1.0, 0.5, 1e-2, -1e-2])
    assert scaled_size(du, Du, is_rot, 2.0) == pytest.approx(max(2e-3 / 1.0, 3e-4 / 1e-2))
    # round-off increments: floors 1e-9 x length (m) and 1e-9 rad
    assert scaled_size(np.array([1e-12, 0, 0, 0.0]), np.zeros(4), is_rot, 2.0) == pytest.approx(1e-12 / 2e-9)
    assert math.isnan(scaled_size(np.array([math.nan, 0, 0, 0.0]), Du, is_rot, 2.0))


@pytest.mark.parametrize("bad", [0.0, 1.0, -0.5, 2.0])
def test_bad_max_contraction_is_a_model_error(bad):
    with pytest.raises(ModelError, match="max_contraction"):
        Convergence(max_contraction=bad)


@pytest.mark.parametrize(
    "is_rot",
    [[False, False, True, True], [True, True, True, True], [False] * 4, []],
    ids=["both fields", "rotations only", "translations only", "no DOFs"],
)
def test_measure_reports_the_scaled_size_of_every_field_layout(is_rot):
    """Convergence.measure's correction size (computed from the correction test's own maxima) equals
    scaled_size for mixed, rotation-only, translation-only and empty fields, NaN included, and the
    correction test passes exactly when that size is within disp_tol."""
    c = Convergence()
    mask = np.array(is_rot, dtype=bool)
    n, L = mask.size, 3.0
    rng = np.random.default_rng(5)
    Du_cases = [rng.normal(size=n), np.zeros(n), rng.normal(size=n) * 1e-12]  # (floors for the last two)
    for Du in Du_cases:
        for scale in (1e-3, 1e-7, 0.0):
            du = rng.normal(size=n) * scale * (np.abs(Du).max(initial=0.0) + 1e-9)
            ok, _, forces, size = c.measure(np.zeros(n), du, Du, mask, 1.0, 1.0, L, iteration=5)
            want = scaled_size(du, Du, mask, L)
            assert size == want  # the same arithmetic: the same bits
            assert forces and ok == (size <= c.disp_tol)
    if n:
        du = np.zeros(n)
        du[-1] = math.nan
        _, _, _, size = c.measure(np.zeros(n), du, np.ones(n), mask, 1.0, 1.0, L, iteration=5)
        assert math.isnan(size) and math.isnan(scaled_size(du, np.ones(n), mask, L))
    else:
        assert scaled_size(np.zeros(0), np.zeros(0), mask, L) == 0.0


@pytest.mark.parametrize("bad", ["half", None, math.nan])
def test_max_contraction_that_is_not_a_number_is_a_model_error(bad):
    with pytest.raises(ModelError, match="max_contraction"):
        Convergence(max_contraction=bad)


def test_a_stabilised_step_accepted_on_its_prediction_stays_within_the_tolerance():
    """A viscously stabilised step of a truss model (translations only: no rotation field): the rule
    accepts an iterate early there too, each frame stays within disp_tol of the strict run's
    (times that increment's largest displacement), and the unstabilised step after it reaches the
    equilibrium that scipy's fsolve gives for the two-bar system (tests/analysis/test_stabilize.py)."""
    from test_stabilize import _exact_equilibrium, _guyed_mast

    tol = fm.Convergence().disp_tol
    runs = {}
    for predicted in (False, True):
        m, top = _guyed_mast(fm.Stabilize(), second_step=True)
        frames = []
        an = Analysis(
            m,
            None,
            progress=False,
            convergence=fm.Convergence(predicted=predicted),
            on_frame=lambda fr: frames.append(np.array(fr["U"])),
        )
        an.run()
        runs[predicted] = (an.summary.steps[0]["iterations"], frames)
    (it_strict, strict), (it_pred, pred) = runs[False], runs[True]
    assert it_pred < it_strict  # the stabilised step took at least one early acceptance
    assert len(pred) == len(strict)
    for k in range(1, len(pred)):
        assert np.abs(pred[k] - strict[k]).max() <= tol * np.abs(strict[k] - strict[k - 1]).max()
    x_exact, z_exact = _exact_equilibrium()
    pos = m.coordinates[m.index(top)] + pred[-1][m.index(top)]
    # the force tolerance 1e-6 of ~400 N with stiffnesses ~1e5..1e7 N/m: ~1e-9 m (as test_stabilize)
    assert pos[0] == pytest.approx(x_exact, abs=1e-9) and pos[2] == pytest.approx(z_exact, abs=1e-9)
