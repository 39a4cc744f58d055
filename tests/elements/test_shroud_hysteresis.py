"""The shroud's loading/unloading law (Rocaspect paper Fig. 4a): a friction tension in parallel with
the rope law, |tau_f| <= eta tau_e.  Each branch of a strain cycle against its closed form, the
loop closing at zero load, eta = 0 bit for bit the paper's law, finite-difference tangents."""

import math

import numpy as np
import pytest

import femast as fm
from femast.elements.shroud_cable import ShroudCableFamily, add_shrouds
from femast.elements.shroud_law import DyneemaLaw
from femast.errors import ModelError
from femast.testing import fd_tangent

LAW = DyneemaLaw()
L0 = 2.0  # m


def tau_e(eps):
    """Eq. 27 (tau = (k0 + k1 tau + k2 tau^2) eps) solved for tau, written out here."""
    k0, k1, k2 = LAW.k0, LAW.k1, LAW.k2
    if eps <= 0:
        return 0.0
    a = 1 - k1 * eps
    return 2 * k0 * eps / (a + math.sqrt(a * a - 4 * k0 * k2 * eps * eps))


def rope(eta, ks=None):
    return ShroudCableFamily(np.array([[0, 1]]), L0, LAW, hysteresis=eta, stick_rigidity=ks)


def at(eps):
    return np.array([[0.0, 0.0, 0.0], [L0 * (1 + eps), 0.0, 0.0]])


def walk(fam, path):
    st = fam.initial_state()
    out = []
    for eps in path:
        r = fam.evaluate(at(eps), None, st)
        st = r.state
        out.append(r.output["tension"][0])
    return np.array(out), st


def test_cycle_follows_the_closed_form_branches():
    eta, ks = 0.08, 2.0e7
    fam = rope(eta, ks)
    up = np.linspace(0.0, 2e-3, 41)[1:]
    down = np.linspace(2e-3, 0.5e-3, 31)[1:]
    up2 = np.linspace(0.5e-3, 2.5e-3, 41)[1:]
    back = np.linspace(2.5e-3, 0.0, 51)[1:]
    T, _ = walk(fam, np.r_[up, down, up2, back])
    i = 0
    for eps, t in zip(up, T[i : i + len(up)]):  # loading from slack: stick run, then (1 + eta) tau_e
        expect = min(tau_e(eps) + ks * eps, (1 + eta) * tau_e(eps))
        assert t == pytest.approx(expect, rel=1e-10)  # (the strain from positions: round-off 1e-16 / eps)
    i += len(up)
    e1 = up[-1]
    for eps, t in zip(down, T[i : i + len(down)]):  # reversal: tau_f falls at k_s until -eta tau_e
        expect = max(tau_e(eps) + eta * tau_e(e1) - ks * (e1 - eps), (1 - eta) * tau_e(eps))
        assert t == pytest.approx(expect, rel=1e-10)  # (the strain from positions: round-off 1e-16 / eps)
    i += len(down)
    e2 = down[-1]
    tf2 = -eta * tau_e(e2)  # (the unloading branch was reached before e2)
    assert T[i - 1] == pytest.approx(
        (1 - eta) * tau_e(e2), rel=1e-10
    )  # (the strain from positions: round-off 1e-16 / eps)
    for eps, t in zip(up2, T[i : i + len(up2)]):  # reloading: back up to the loading branch
        expect = min(tau_e(eps) + tf2 + ks * (eps - e2), (1 + eta) * tau_e(eps))
        assert t == pytest.approx(expect, rel=1e-10)  # (the strain from positions: round-off 1e-16 / eps)
    i += len(up2)
    assert T[-1] == 0.0  # the loop closes at zero strain: a slack rope carries nothing
    # loading and unloading tensions at the same strain differ by 2 eta tau_e
    j_up = np.flatnonzero(np.isclose(up2, 2e-3))[0]
    j_back = np.flatnonzero(np.isclose(back, 2e-3))[0]
    t_load, t_unload = T[len(up) + len(down) + j_up], T[len(up) + len(down) + len(up2) + j_back]
    assert t_load - t_unload == pytest.approx(2 * eta * tau_e(2e-3), rel=1e-9)


def test_zero_hysteresis_is_the_paper_law_bit_for_bit():
    a = ShroudCableFamily(np.array([[0, 1]]), L0, LAW)
    b = rope(0.0)
    assert b.n_state == 0
    for eps in (-1e-4, 0.0, 1e-3, 3e-3):
        ra, rb = a.evaluate(at(eps), None, a.initial_state()), b.evaluate(at(eps), None, b.initial_state())
        np.testing.assert_array_equal(ra.f, rb.f)
        np.testing.assert_array_equal(ra.k, rb.k)


@pytest.mark.parametrize("phase", ["stick", "slip-loading", "slip-unloading"])
def test_tangent_matches_finite_differences(phase):
    eta, ks = 0.1, 5.0e6
    offsets = np.array([[[0.1, -0.05, 0.2], [0.0, 0.0, 0.0]]])
    fam = ShroudCableFamily(np.array([[0, 1]]), L0, LAW, offsets=offsets, hysteresis=eta, stick_rigidity=ks)
    X = np.array([[0.0, 0.0, 0.0], [1.6, 0.7, -1.1]])
    R = np.tile(np.eye(3), (2, 1, 1))
    base = np.linalg.norm(X[1] - X[0] - offsets[0, 0])
    fam.L0 = np.array([base / 1.002])
    st = fam.initial_state()
    r = fam.evaluate(X, R, st)  # loaded from slack to 2e-3: on the loading branch
    st = r.state
    d = (X[1] - X[0] - offsets[0, 0]) / base
    Xt = X.copy()
    Xt[1] += {"stick": -2e-5, "slip-loading": 1e-4, "slip-unloading": -2e-3}[phase] * base * d
    r = fam.evaluate(Xt, R, st)
    tf, lim = r.state[0, 1], fam.hysteresis[0, 0] * tau_e(r.state[0, 0])
    assert (abs(tf) < lim) == (phase == "stick")
    Kfd = fd_tangent(fam, Xt, R, st, h=1e-8)[0]
    np.testing.assert_allclose(r.k[0], Kfd, rtol=0, atol=1e-6 * np.abs(r.k[0]).max())


def test_pretension_is_on_the_loading_branch():
    m = fm.Model("rope")
    a, b = m.node(0, 0, 0), m.node(3.0, 0, 4.0)
    fam = add_shrouds(m, [[a, b]], tension=800.0, hysteresis=0.1)
    x = np.zeros((max(a, b) + 1, 3))
    x[a], x[b] = m.xyz(a), m.xyz(b)  # (the family's nodes are the model's labels)
    r = fam.evaluate(x, None, fam.initial_state())
    assert r.output["tension"][0] == pytest.approx(800.0, rel=1e-9)
    assert r.output["friction_tension"][0] == pytest.approx(800.0 * 0.1 / 1.1, rel=1e-9)


@pytest.mark.parametrize(
    "kw, words",
    [
        (dict(hysteresis=1.2), "hysteresis = 1.2 must be in \\[0, 1\\)"),
        (dict(hysteresis=-0.1), "must be in \\[0, 1\\)"),
        (dict(hysteresis=0.1, stick_rigidity=0.0), "stick_rigidity = 0.0 N must be finite and > 0"),
    ],
)
def test_bad_hysteresis_is_named(kw, words):
    with pytest.raises(ModelError, match=words):
        ShroudCableFamily(np.array([[0, 1]]), L0, LAW, **kw)
