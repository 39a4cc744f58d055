"""Effect families: generalised forms whose simpler forms are special cases, checked
against closed forms (Jenkins loops, Masing rules of the Iwan model) and the old forms exactly."""

import numpy as np
import pytest

from femast.effects import get_effect, play, resolve
from femast.effects.base import forms_of
from femast.effects.latch import fade
from femast.effects.operators import IWAN_ELEMENTS, iwan, iwan_strengths, jenkins, proportional_iwan, proportional_play
from femast.errors import ModelError
from femast.experiments import Parameter, fit, get_experiment, predict
from femast.rigs.synthetic import latch_pull_data, mast_top_data, mast_top_path

CYCLE = np.concatenate([np.linspace(0, 10, 101), np.linspace(10, -10, 201), np.linspace(-10, 4, 141)])


def test_jenkins_special_cases_are_play_and_the_elastic_joint_exactly():
    np.testing.assert_array_equal(jenkins(CYCLE, 2.0, 0.0), play(CYCLE, 2.0))
    np.testing.assert_array_equal(jenkins(CYCLE, 2.0, 1.0), CYCLE)


def test_jenkins_loop_closed_form_stick_slope_alpha_slip_slope_one():
    r, a = 2.0, 0.25
    y = jenkins(CYCLE, r, a)
    u = CYCLE
    # virgin loading: stuck (slope alpha) until the slider carries r, i.e. (1 - a) u = r, then u - r
    us = r / (1 - a)
    first = u[:101]
    np.testing.assert_allclose(y[:101], np.where(first < us, a * first, first - r), atol=1e-12)
    # after the reversal at 10: stuck until the slider load changed by 2 r: u = 10 - 2 r / (1 - a)
    down = u[101:302]
    u_slip = 10.0 - 2 * r / (1 - a)
    expect = np.where(down > u_slip, 10.0 - r - a * (10.0 - down), down + r)
    np.testing.assert_allclose(y[101:302], expect, atol=1e-12)


def _virgin_uniform(v, R):
    """Virgin curve of the Iwan model with uniformly distributed strengths on [0, R] (closed form)."""
    return np.where(np.abs(v) < R, np.sign(v) * v * v / (2 * R), v - np.sign(v) * R / 2)


def test_iwan_uniform_strengths_follow_the_closed_form_virgin_curve_and_masing_branch():
    R, N = 10.0, IWAN_ELEMENTS
    u = np.concatenate([np.linspace(0, 15, 301), np.linspace(15, -15, 601)])
    y = iwan(u, R, 1.0, 0.0)
    expect = np.concatenate(
        [_virgin_uniform(u[:301], R), _virgin_uniform(15.0, R) - 2 * _virgin_uniform((15.0 - u[301:]) / 2, R)]
    )
    # mid-quantile rule on an integrand with one slope kink: virgin error <= R / (8 N^2), the Masing
    # branch doubles it (f(U) - 2 f(.)): R / (4 N^2)
    np.testing.assert_allclose(y[:301], expect[:301], atol=R / (8 * N**2) * (1 + 1e-9))
    np.testing.assert_allclose(y, expect, atol=R / (4 * N**2) * (1 + 1e-9))


def test_iwan_special_cases():
    u = CYCLE
    np.testing.assert_allclose(iwan(u, 3.0, 1.0, 1.0), u, atol=1e-14)  # all elastic
    r = iwan_strengths(3.0, 1e6)  # beta -> inf: every strength at R: the play operator
    np.testing.assert_allclose(r, 3.0, rtol=1e-4)
    np.testing.assert_allclose(iwan(u, 3.0, 1e6, 0.0), play(u, 3.0), atol=1e-3)  # 3.0 (1 - q^1e-6) < 1e-4 x 3
    # columns are independent
    two = iwan(np.column_stack([u, -u]), 3.0, 1.5, 0.2)
    np.testing.assert_allclose(two[:, 1], iwan(-u, 3.0, 1.5, 0.2), atol=0)


def test_proportional_iwan_limits_and_zero_closing_loops():
    u = CYCLE
    # beta -> inf: every coefficient at eta, the proportional play (eta (1 - q^1e-6) |u| < 1e-4 x 0.3 x 10)
    np.testing.assert_allclose(proportional_iwan(u, 0.3, 1e6, 0.0), proportional_play(u, 0.3), atol=3e-4)
    np.testing.assert_allclose(proportional_iwan(u, 0.3, 2.0, 1.0), u, atol=1e-14)  # no friction
    zero = np.abs(u) < 1e-12
    assert zero.sum() >= 2 and np.all(proportional_iwan(u, 0.5, 0.7, 0.2)[zero] == 0.0)  # loops close at zero


def test_proportional_iwan_uniform_coefficients_follow_the_closed_form_return_branch():
    # beta = 1: eta_j uniform on [0, H].  Loading 0 -> P: each group carries (1 - eta_j) u, mean (1 - H/2) u.
    # Back down to 0 < u < P: group j carries min((1 - eta_j) P, (1 + eta_j) u); the groups with
    # eta < e* = (P - u)/(P + u) have released.  Mean over [0, H] in closed form:
    H, P, N = 0.6, 10.0, IWAN_ELEMENTS
    up, down = np.linspace(0, P, 201), np.linspace(P, 0.0, 401)[1:]
    y = proportional_iwan(np.concatenate([up, down]), H, 1.0, 0.0)
    np.testing.assert_allclose(y[:201], (1 - H / 2) * up, rtol=1e-12)
    e = np.minimum((P - down) / (P + down), H)
    expect = (down * (e + e * e / 2) + P * ((H - H * H / 2) - (e - e * e / 2))) / H
    # mid-quantile (midpoint) rule on an integrand with one slope kink of size u + P <= 2 P:
    # error <= 2 P H / (8 N^2)
    np.testing.assert_allclose(y[201:], expect, atol=2 * P * H / (8 * N**2))


def test_forms_are_listed_and_selected_by_name():
    exp = get_experiment("mast-top")
    assert forms_of("friction_hysteresis", exp) == (
        "friction_hysteresis",
        "friction_hysteresis/jenkins",
        "friction_hysteresis/iwan",
        "friction_hysteresis/per_axis",
    )
    ((name, impl),) = resolve(exp, ["friction_hysteresis/iwan"])
    assert name == "friction_hysteresis/iwan" and [p.name for p in impl.parameters] == ["M_f", "beta", "alpha"]
    ((name, impl),) = resolve(exp, ["friction_hysteresis/play"])  # the default form by its name
    assert name == "friction_hysteresis"
    with pytest.raises(ModelError, match="unknown form 'dahl'.*play, jenkins, iwan, per_axis"):
        resolve(exp, ["friction_hysteresis/dahl"])


def _mt():
    exp = get_experiment("mast-top")
    data, _ = mast_top_data(path=mast_top_path(n=200, kind="cycles", amplitude_N=150.0, seed=2), seed=2)
    return exp, data


def test_generalised_forms_reduce_exactly_to_the_default_forms_mast_top():
    exp, data = _mt()
    ms = 0.01 * np.max(np.abs(exp.prepared(data)["m"]), axis=0)
    base = {"k_theta1": 2.6e5, "k_theta2": 2.4e5}
    for old, new in [
        ({"friction_hysteresis": {"M_f": 7.0}}, {"friction_hysteresis/jenkins": {"M_f": 7.0, "alpha": 0.0}}),
        ({"progressive_stiffness": {"beta": 3e-4}}, {"progressive_stiffness/quadratic": {"beta": 3e-4, "beta2": 0.0}}),
    ]:
        a, b = predict(exp, data, base, old), predict(exp, data, base, new)
        for c in exp.channels:
            np.testing.assert_array_equal(a[c], b[c])
    # clearance: the smooth form with M_c = the default form's 1 % of max |m_k|, joint by joint; the
    # per-axis form with equal gaps
    m = exp.prepared(data)["m"][:, :2]
    impl = get_effect("joint_clearance").implementation(exp)
    ctx = {"load": m, "quantities": exp.quantities}
    for j in range(2):
        theta0 = np.zeros((data.n, 2))
        a = impl.apply(theta0, {"c": 2e-4}, ctx)[:, j]
        b = impl.forms["smooth"].apply(theta0, {"c": 2e-4, "M_c": float(ms[j])}, ctx)[:, j]
        np.testing.assert_allclose(a, b, rtol=1e-15, atol=0)
        assert np.all(np.abs(b - 2e-4 * np.tanh(m[:, j] / ms[j])) < 1e-18)
    for old, new in [
        ({"joint_clearance": {"c": 2e-4}}, {"joint_clearance/per_axis": {"c_x": 2e-4, "c_y": 2e-4}}),
        ({"friction_hysteresis": {"M_f": 7.0}}, {"friction_hysteresis/per_axis": {"M_f_x": 7.0, "M_f_y": 7.0}}),
    ]:
        a, b = predict(exp, data, base, old), predict(exp, data, base, new)
        for c in exp.channels:
            np.testing.assert_array_equal(a[c], b[c])
    # pretension: saturating -> linear as t_c -> inf: 1 - exp(-tau/t) ~ tau/t (1 - tau/2t): error <= 1/(2 t_c)
    a = predict(exp, data, base, {"pretension_loss": {"lam": 0.2}})
    b = predict(exp, data, base, {"pretension_loss/saturating": {"lam": 0.2, "t_c": 100.0}})
    for c in exp.channels:
        np.testing.assert_allclose(b[c], a[c], atol=0.2 / 100.0 * np.max(np.abs(a[c])))


def test_latch_fade_family_contains_the_exponential_and_the_linear_fade():
    d = np.linspace(0, 1e-3, 51)
    np.testing.assert_array_equal(fade(d, 3e-4, 0.0), np.exp(-d / 3e-4))
    np.testing.assert_allclose(fade(d, 3e-4, 1.0), np.clip(1 - d / 3e-4, 0, None), atol=1e-15)
    np.testing.assert_allclose(fade(d, 3e-4, -1.0), 1 / (1 + d / 3e-4), rtol=1e-14)
    np.testing.assert_allclose(fade(d, 3e-4, 1e-6), np.exp(-d / 3e-4), rtol=1e-5)  # continuous at 0
    exp = get_experiment("latch-pull")
    data, _ = latch_pull_data(seed=1)
    a = predict(exp, data, None, {"latch_hysteresis": {"F_h": 6.0, "ell": 2e-4}})
    b = predict(exp, data, None, {"latch_hysteresis/shaped": {"F_h": 6.0, "ell": 2e-4, "gamma": 0.0}})
    np.testing.assert_array_equal(a["dT_N"], b["dT_N"])
    a = predict(exp, data, None, {"joint_clearance": {"c": 1e-4}})
    b = predict(exp, data, None, {"joint_clearance/smooth": {"c": 1e-4, "F_c": 1.0}})
    np.testing.assert_array_equal(a["dT_N"], b["dT_N"])


def test_jenkins_form_recovers_a_finite_stick_stiffness_the_play_form_cannot():
    exp, data = _mt()
    truth = {"friction_hysteresis/jenkins": {"M_f": 8.0, "alpha": 0.4}}
    clean = predict(exp, data, {"k_theta1": 2.7e5, "k_theta2": 2.3e5}, truth)
    rng = np.random.default_rng(5)
    for c in exp.channels:
        data.columns[c] = clean[c] + rng.normal(0, 2e-5, data.n)
    data.cache.clear()
    rp = fit(exp, data, ["friction_hysteresis"])
    rj = fit(exp, data, ["friction_hysteresis/jenkins"])
    assert rj.bic < rp.bic - 10
    p = rj.effect_params["friction_hysteresis/jenkins"]
    i = rj.names.index("friction_hysteresis/jenkins.alpha")
    assert abs(p["alpha"] - 0.4) < 4 * rj.stderr[i] + 1e-3, (p, rj.stderr[i])  # within 4 standard errors


def test_bad_starts_are_named():
    with pytest.raises(ModelError, match="parameter a: start 5.0 m lies outside its bounds"):
        Parameter("a", "m", 1.0, 0.0, 2.0, "x", starts=(0.5, 5.0))
    exp, data = _mt()
    with pytest.raises(ModelError, match=r"fit start: friction_hysteresis.M_f = -1.0 N m lies outside its bounds"):
        fit(exp, data, ["friction_hysteresis"], start={"friction_hysteresis.M_f": -1.0})
