"""Static and kinetic friction of cable devices (drum, sheave, latch): a device slips when its static
band (mu_s) is exceeded, slides on at the kinetic law (mu_k), and grips again when it stops or
reverses; closed-form stick-slip sequences; mu_s = mu_k is the one-coefficient law bit for bit."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from femast.elements.base import IncrementContext
from femast.elements.cable_devices import CableDeviceFamily, Drum, Latch, Sheave
from femast.elements.latch_law import LatchParameters
from femast.errors import ModelError

EA = 1.0e5  # N
T0 = 100.0  # N
X90 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.2, 0.0]])  # a quarter turn at node 1
PHI = math.pi / 2


def ev(fam, X, st):
    return fam.evaluate(X, None, st, IncrementContext())


def sliding_tensions(L, L0, ratio):
    """Both sections sliding with T_out = ratio T_in: sum of l0_i = L_i / (1 + T_i / EA) is L0."""
    t = brentq(lambda t: L[0] / (1 + t / EA) + L[1] / (1 + ratio * t / EA) - L0, 1e-6, 1e5, xtol=1e-13, rtol=1e-15)
    return t, ratio * t


def test_drum_stick_slip_sequence():
    mu_s, mu_k = 0.4, 0.2
    fam = CableDeviceFamily.pretensioned([[0, 1, 2]], X90, EA, T0, [Drum(mu_s=mu_s, mu_k=mu_k)])
    st = fam.initial_state()
    l0 = np.diff(np.r_[0.0, st[0, :1], fam.L0])
    rs, rk = math.exp(mu_s * PHI), math.exp(mu_k * PHI)
    du_slip = l0[1] * (1 + rs * T0 / EA) - 1.2  # the pull at which the static band is reached

    def at(u):
        X = X90.copy()
        X[2, 1] += u
        return X

    # 1. stick up to the static band
    for u in np.linspace(0.1, 0.95, 5) * du_slip:
        r = ev(fam, at(u), st)
        assert r.state[0, 1] == 0 and r.output["tension"][0, 0] == pytest.approx(T0, rel=1e-11)
        st = r.state
    # 2. past it: slips, and slides at the kinetic ratio (a drop from the static one)
    u = 1.05 * du_slip
    r = ev(fam, at(u), st)
    T = r.output["tension"][0]
    assert r.state[0, 1] == 1 and T[1] / T[0] == pytest.approx(rk, rel=1e-12)
    np.testing.assert_allclose(T, sliding_tensions([1.0, 1.2 + u], fam.L0[0], rk), rtol=1e-11)
    st = r.state
    # 3. pulled on: slides on at mu_k
    u *= 1.2
    r = ev(fam, at(u), st)
    T = r.output["tension"][0]
    assert r.state[0, 1] == 1 and T[1] / T[0] == pytest.approx(rk, rel=1e-12)
    st = r.state
    # 4. held: the cable stops (arrest) and grips again, same tensions
    r = ev(fam, at(u), st)
    assert r.state[0, 1] == 0
    np.testing.assert_allclose(r.output["tension"][0], T, rtol=1e-11)
    st = r.state
    # 5. pulled a little more: above the kinetic ratio but inside the static band, it holds
    l0 = np.diff(np.r_[0.0, st[0, :1], fam.L0])
    u2 = u + 0.5 * (l0[1] * (1 + rs * T[0] / EA) - 1.2 - u)
    r = ev(fam, at(u2), st)
    T2 = r.output["tension"][0]
    assert r.state[0, 1] == 0 and rk < T2[1] / T2[0] < rs
    assert T2[0] == pytest.approx(T[0], rel=1e-11)
    st = r.state
    # 6. released: it holds on reversal while T_out / T_in > exp(-mu_s phi) ...
    r = ev(fam, at(u2 - 0.3 * du_slip), st)
    T3 = r.output["tension"][0]
    assert r.state[0, 1] == 0 and 1 / rs < T3[1] / T3[0] < T2[1] / T2[0] and T3[0] == pytest.approx(T[0], rel=1e-11)
    st = r.state
    # ... then slips back at the kinetic ratio
    r = ev(fam, at(-du_slip), st)
    T4 = r.output["tension"][0]
    assert r.state[0, 1] == -1 and T4[1] / T4[0] == pytest.approx(1 / rk, rel=1e-12)
    np.testing.assert_allclose(T4, sliding_tensions([1.0, 1.2 - du_slip], fam.L0[0], 1 / rk), rtol=1e-11)


def test_one_coefficient_is_mu_s_equal_mu_k_bit_for_bit():
    X = X90.copy()
    for one, two in (
        (Drum(mu=0.3), Drum(mu_s=0.3, mu_k=0.3)),
        (Sheave(0.05, 0.01, 0.3, point=True), Sheave(0.05, 0.01, point=True, mu_s=0.3)),
        (Latch(LatchParameters.adam_fit()), Latch(LatchParameters.adam_fit(), mu_s=0.07, mu_k=0.07)),
    ):
        a = CableDeviceFamily.pretensioned([[0, 1, 2]], X90, EA, T0, [one])
        b = CableDeviceFamily.pretensioned([[0, 1, 2]], X90, EA, T0, [two])
        sa, sb = a.initial_state(), b.initial_state()
        for u in np.r_[np.linspace(0, 0.03, 16), np.linspace(0.03, -0.01, 11)]:
            X[2, 1] = 1.2 + u
            ra, rb = ev(a, X, sa), ev(b, X, sb)
            np.testing.assert_array_equal(ra.f, rb.f)
            np.testing.assert_array_equal(ra.k, rb.k)
            sa, sb = ra.state, rb.state


def eq14(x, sigma, p, mu):
    """Eq. 14 (Stohlman & Pellegrino) with friction coefficient mu, written out here."""
    rho = p.r + p.R
    y = math.sqrt(max(rho * rho - x * x, 0.0))
    delta = max(y - p.h - p.r, 0.0)
    return -2.0 * p.k * delta * (x - sigma * mu * y) / (y + sigma * mu * x)


def test_latch_leaves_its_backstop_at_mu_s_and_slides_at_mu_k():
    p = LatchParameters.adam_fit()
    mu_s, mu_k = 0.12, 0.05
    X = np.array([[0.0, 0, 0], [0.5, 0, 0], [1.0, 0, 0]])
    fam = CableDeviceFamily.pretensioned([[0, 1, 2]], X, 2e4, 5.0, [Latch(p, mu_s=mu_s, mu_k=mu_k)])
    st = fam.initial_state()
    peak_static = eq14(-p.x_backstop, 1, p, mu_s)  # the jump that starts the bead off its backstop
    seen_slide = held = False
    for u in np.linspace(0.0, 3e-3, 301)[1:]:
        Xp = X.copy()
        Xp[2, 0] += u
        r = ev(fam, Xp, st)
        T, mode, x = r.output["tension"][0], r.state[0, 1], r.output["bead_position"][0, 0]
        jump = T[1] - T[0]
        if mode == 2:
            assert jump <= peak_static + 1e-9
        elif mode == 1:
            assert jump == pytest.approx(eq14(x, 1, p, mu_k), abs=1e-8)
            seen_slide = True
        if seen_slide and not held and mode == 1:
            # hold the pull: the bead stops and grips; a small further pull stays inside the static band
            r2 = ev(fam, Xp, r.state)
            assert r2.state[0, 1] == 0
            Xq = Xp.copy()
            Xq[2, 0] += 1e-7
            r3 = ev(fam, Xq, r2.state)
            j3 = r3.output["tension"][0, 1] - r3.output["tension"][0, 0]
            assert r3.state[0, 1] == 0 and eq14(x, 1, p, mu_k) < j3 < eq14(x, 1, p, mu_s)
            held = True
        st = r.state
    assert seen_slide and held
    assert peak_static > eq14(-p.x_backstop, 1, p, mu_k)


@pytest.mark.parametrize(
    "dev, words",
    [
        (Drum(mu_s=0.1, mu_k=0.2), "kinetic mu_k = 0.2 above static mu_s = 0.1"),
        (Drum(mu=0.2, mu_s=0.3), "give mu \\(static = kinetic\\) or mu_s"),
        (Drum(mu_s=-0.1), "mu_s = -0.1 must be a finite friction coefficient"),
        (Latch(LatchParameters.adam_fit(), mu_k=0.1), "kinetic mu_k = 0.1 above static mu_s = 0.07"),
    ],
)
def test_bad_friction_pairs_are_named(dev, words):
    with pytest.raises(ModelError, match=words):
        CableDeviceFamily.pretensioned([[0, 1, 2]], X90, EA, T0, [dev])


def test_single_latch_element_with_kinetic_friction_matches_the_device_family():
    """CableLatchFamily (the ADAM models' latch cable) with mu_k and the device family's Latch along a
    pull - release - relatch path: two implementations, the same stick-slip states; mu_k = mu is the
    one-coefficient element bit for bit."""
    from femast.elements.cable_devices import Pulley
    from femast.elements.cable_latch import CableLatchFamily

    p = LatchParameters.adam_fit()
    X = np.array([[-0.40, 0.0, 0.0], [0.0, 0.12, 0.02], [0.45, 0.01, 0.0], [0.9, 0.3, 0.0]])
    old = CableLatchFamily.pretensioned([[0, 1, 2, 3]], X, EA=2e4, T0=20.0, latch_node=2, latch=p, mu_k=0.03)
    new = CableDeviceFamily.pretensioned([[0, 1, 2, 3]], X, 2e4, 20.0, [Pulley(), Latch(p, mu_k=0.03)])
    one = CableLatchFamily.pretensioned([[0, 1, 2, 3]], X, EA=2e4, T0=20.0, latch_node=2, latch=p)
    same = CableLatchFamily.pretensioned([[0, 1, 2, 3]], X, EA=2e4, T0=20.0, latch_node=2, latch=p, mu_k=p.mu)
    so, sn, s1, s2 = old.initial_state(), new.initial_state(), one.initial_state(), same.initial_state()
    statuses = set()
    for du in np.r_[np.linspace(0, 0.004, 60), np.full(3, 0.004), np.linspace(0.004, -0.004, 120)]:
        Xp = X.copy()
        Xp[3, 0] += du
        ro, rn = ev(old, Xp, so), ev(new, Xp, sn)
        so, sn = ro.state, rn.state
        np.testing.assert_allclose(rn.output["tension"], ro.output["tension"], rtol=1e-9, atol=1e-9)
        assert rn.output["bead_position"][0, 1] == pytest.approx(ro.output["bead_position"][0], abs=1e-12)
        statuses.add(int(ro.state[0, 1]))
        r1, r2 = ev(one, Xp, s1), ev(same, Xp, s2)
        np.testing.assert_array_equal(r1.f, r2.f)
        np.testing.assert_array_equal(r1.k, r2.k)
        s1, s2 = r1.state, r2.state
    assert {0, 1, -1} <= statuses
