"""Fits of finite-difference experiments with fewer model runs: Broyden secant
Jacobians between finite-difference ones, a finite-difference Jacobian at the solution, and start
Jacobians seeded from an earlier fit.  An analytic model stands in for an FE run; its data come
from numpy with Gaussian noise (no femast code generates them)."""

import numpy as np
import pytest

from femast.experiments import Column, Experiment, Parameter, fitting
from femast.experiments.core import Measured

A_TRUE, B_TRUE, C_TRUE = 2.0, 1.3, 0.4
NOISE = 0.01


def _model(params, data, effects, options):
    t = data["t_s"]
    y = params["a"] * (1.0 - np.exp(-params["b"] * t))
    y = effects.apply("response", y, data=data, params=params, options=options) if effects else y
    return {"y": y}


def _experiment(secant=True):
    exp = Experiment(
        name="rise",
        title="a first-order rise",
        columns=(Column("t_s", "s", "time"), Column("y", "-", "response")),
        channels=("y",),
        parameters=(Parameter("a", "-", 1.5, 0.1, 10.0, "final value"), Parameter("b", "1/s", 0.8, 0.01, 10.0, "rate")),
        model=_model,
        hooks={"response": "y (n,)"},
        # the FE experiments' settings (bay-torsion, tip-cycle): loose tolerances, a 1e-3 step
        fit_options={
            "diff_step": 1e-3,
            "xtol": 1e-4,
            "ftol": 1e-4,
            "gtol": 1e-8,
            "max_nfev_per_param": 30,
            "expensive": True,
        },
    )
    return exp


def _data(seed=3, with_c=False):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 6.0, 120)
    y = A_TRUE * (1.0 - np.exp(-B_TRUE * t)) + (C_TRUE * t * np.exp(-t) if with_c else 0.0)
    return Measured("rise", {"t_s": t, "y": y + NOISE * rng.standard_normal(t.size)})


def _fd_only(monkeypatch):
    """Every Jacobian by finite differences (the behaviour before secant updates)."""
    orig = fitting._FEJacobian.__init__

    def init(self, fun, step, lo, hi, secant=True, J0=None):
        orig(self, fun, step, lo, hi, secant=False, J0=None)

    monkeypatch.setattr(fitting._FEJacobian, "__init__", init)


def test_secant_fit_matches_the_finite_difference_fit_with_fewer_runs(monkeypatch):
    exp, data = _experiment(), _data()
    sec = fitting.fit(exp, data)
    with monkeypatch.context() as m:
        _fd_only(m)
        fd = fitting.fit(exp, data)
    # both find the least-squares solution within what ftol = 1e-4 leaves: a cost change of 1e-4 of
    # about n/2 = 60 (whitened) is 0.006, i.e. sqrt(2 x 0.006) = 0.11 standard errors
    assert np.all(np.abs(sec.x - fd.x) <= 0.15 * fd.stderr)
    # the covariance comes from a finite-difference Jacobian at the solution in both
    np.testing.assert_allclose(sec.stderr, fd.stderr, rtol=1e-3)  # same J up to the 1e-3 FD step
    assert sec.fe_runs < fd.fe_runs
    # and the fit is right: the truth lies within 4 standard errors (noise 0.01 on 120 points)
    assert np.all(np.abs(sec.x - [A_TRUE, B_TRUE]) <= 4 * sec.stderr)


def test_start_sensitivity_replaces_the_first_jacobian_runs():
    exp, data = _experiment(), _data()
    first = fitting.fit(exp, data)
    assert set(first.sensitivity) == {"a", "b"}
    # the sensitivity is d(predicted)/d(parameter): check it against a central difference of the model
    t = data["t_s"]
    a, b = first.x
    da = 1.0 - np.exp(-b * t)
    # a is fitted in log scale (bounds 0.1-10): a forward step h = 1e-3 in ln a is a step (e^h - 1) a, so the
    # difference quotient over h carries (e^h - 1) / h - 1 = h / 2 = 5e-4 of relative error
    np.testing.assert_allclose(first.sensitivity["a"], da, rtol=6e-4, atol=1e-12)
    again = fitting.fit(exp, data, start=dict(zip(first.names, first.x)), start_sensitivity=first.sensitivity)
    plain = fitting.fit(exp, data, start=dict(zip(first.names, first.x)))
    assert np.all(np.abs(again.x - first.x) <= 0.15 * first.stderr)  # ftol, as above
    assert again.fe_runs <= plain.fe_runs - 2  # the two first-Jacobian columns were not run


def test_a_poor_seed_does_not_change_the_answer():
    """A wrong start Jacobian (signs flipped, scaled) only costs runs: the finite-difference check at
    the solution restarts the fit until the Gauss-Newton step predicts nothing more."""
    exp, data = _experiment(), _data(seed=5)
    ref = fitting.fit(exp, data)
    bad = {k: -3.0 * v for k, v in ref.sensitivity.items()}
    res = fitting.fit(exp, data, start={"a": 1.5, "b": 0.8}, start_sensitivity=bad)
    assert np.all(np.abs(res.x - ref.x) <= 0.15 * ref.stderr)  # ftol, as above


@pytest.mark.parametrize("seed", [1, 2])
def test_single_channel_noise_reestimate_needs_no_second_fit(seed):
    """One channel: re-weighting by the re-estimated noise multiplies the whitened residual by a
    constant, so the minimiser and the covariance stay; ratio and cost follow the new noise."""
    exp, data = _experiment(), _data(seed)
    res = fitting.fit(exp, data)
    z = (data["y"] - res.predicted["y"]) / res.noise["y"]
    np.testing.assert_allclose(res.fun, z, rtol=1e-12)  # residual whitened by the final noise
    np.testing.assert_allclose(res.cost, 0.5 * z @ z, rtol=1e-12)


def test_multistart_polishes_only_the_best_start(monkeypatch):
    """Several starts of an expensive fit: each runs to its own minimum, and only the best is polished
    (a finite-difference Jacobian at the solution, for the covariance): the others are discarded."""
    from femast.experiments import fe_jacobian
    from femast.experiments.fit_problem import FitProblem
    from femast.experiments.prediction import parameter_specs

    exp, data = _experiment(), _data(seed=7)
    specs = parameter_specs(exp, [])
    pb = FitProblem(exp, data, specs, None, False, None, None)
    starts = [np.array([1.5, 0.8]), np.array([5.0, 0.05]), np.array([0.3, 6.0])]
    polished = []
    orig = fe_jacobian._polish

    def counting(sol, *args, **kw):
        polished.append(sol.cost)
        return orig(sol, *args, **kw)

    monkeypatch.setattr("femast.experiments.fit_problem._polish", counting)
    sigma = {"y": NOISE}
    best = pb.solve(sigma, starts)
    assert len(polished) == 1
    singles = []
    for x in starts:
        singles.append(pb.solve(sigma, [x]))
    # the one polished is the start whose unpolished minimum was lowest, and nothing better was left out
    assert polished[0] == pytest.approx(min(polished[1:]), rel=1e-12)
    assert best.cost <= min(s.cost for s in singles) * (1 + 1e-4) + 1e-9


def test_a_held_out_fold_started_from_the_full_fit_takes_its_jacobian_from_it():
    """A fold of the held-out check starts where the fit on all the data ended: that fit's derivatives
    there replace the fold's first finite-difference Jacobian, and the fold fit ends where it would
    without them."""
    exp, data = _experiment(), _data(seed=11)
    full = fitting.fit(exp, data)
    rows = np.arange(data.n) % 3 != 0
    start = dict(zip(full.names, full.x))
    noise = {"y": float(full.noise["y"])}
    seeded = fitting.fit(exp, data, start=start, noise=noise, rows=rows, start_sensitivity=full.sensitivity)
    plain = fitting.fit(exp, data, start=start, noise=noise, rows=rows)
    assert seeded.fe_runs <= plain.fe_runs - 2  # the two first-Jacobian columns were not run
    assert np.all(np.abs(seeded.x - plain.x) <= 0.15 * plain.stderr)  # ftol, as above
