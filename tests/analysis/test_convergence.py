"""The Newton convergence test: the linear-increment rule (Abaqus' R_l) and the round-off load
step that used to fail without it (met in the FE experiments' fits)."""

import tempfile

import numpy as np

from femast.adam import build_mast
from femast.adam.steps import CONVERGENCE, add_initial_steps
from femast.analysis import Analysis
from femast.analysis.convergence import Convergence


def _check(conv, r, du, Du, iteration):
    is_rot = np.array([False, False, True])
    return conv.check(
        np.asarray(r, float),
        np.asarray(du, float),
        np.asarray(Du, float),
        is_rot,
        ref_force=1.0,
        ref_moment=1.0,
        length=1.0,
        iteration=iteration,
    )[0]


def test_linear_increment_rule():
    conv = Convergence()  # force_tol 1e-6, disp_tol 1e-6, linear_tol 1e-8
    du = Du = [1e-3, 0.0, 1e-3]  # first iteration: the correction is the whole increment
    # residual 1e-10 of the reference after one iteration: a linear increment, accepted
    assert _check(conv, [1e-10, 0.0, 1e-10], du, Du, iteration=1)
    # the same state at a later iteration is judged by the correction test (ratio 1: not converged)
    assert not _check(conv, [1e-10, 0.0, 1e-10], du, Du, iteration=2)
    # residual 1e-7: inside force_tol but not linear, and the correction is the whole increment
    assert not _check(conv, [1e-7, 0.0, 0.0], du, Du, iteration=1)
    # the tighter of linear_tol and force_tol applies: with force_tol 1e-9, 1e-8.5 is not linear
    assert not _check(Convergence(force_tol=1e-9), [10**-8.5, 0.0, 0.0], du, Du, iteration=1)


def test_a_round_off_load_change_converges_with_friction_joints():
    # a one-bay ADAM mast (friction ball joints, latches, cables); step 'b' repeats step 'a''s tip
    # load times (1 + 1e-14): the whole increment is round-off.  Before the linear-increment rule
    # every attempt ended in "residual diverging" at a residual ratio of ~2e-10.
    am = build_mast(1)
    add_initial_steps(am)
    load = dict(mz=6.8, fx=5.0)
    am.model.step("a", initial_increment=0.5, max_increment=0.5).load(am.control, **load)
    am.model.step("b", min_increment=1e-3).load(am.control, **{k: v * (1 + 1e-14) for k, v in load.items()})
    with tempfile.TemporaryDirectory() as d:
        an = Analysis(am.model, d, progress=False, convergence=CONVERGENCE)
        res = an.run()
        assert an.summary.steps[-1]["increments"] == 1 and an.summary.steps[-1]["iterations"] <= 1
        F = [res.frame(i) for i in (len(res) - 3, len(res) - 2, len(res) - 1)]
    # the state does not move: the load changed by 1e-14 relative, and step b's one iteration (the
    # linear-increment rule) is one Newton correction from step a's end, i.e. the error left there.
    # The correction test (strict or predicted) bounds that error in each field by disp_tol
    # times that field's largest change in step a's last increment (the test's own measure: the
    # translations in m, the rotations (accumulated spins URA) in rad; both rules leave ~4e-4 and
    # ~6e-4 of that bound here)
    for key in ("U", "URA"):
        assert np.abs(F[2][key] - F[1][key]).max() <= CONVERGENCE.disp_tol * np.abs(F[1][key] - F[0][key]).max()
