"""Sheaves (wheels turning on a pin with bearing friction) beside capstan drums (a cable sliding on a
fixed surface): closed forms of each law in slip and stick, both directions, point and sized, and
finite-difference tangents."""

import math

import numpy as np
import pytest

from femast.elements.base import IncrementContext
from femast.elements.cable_devices import CableDeviceFamily, Drum, Pulley, Sheave
from femast.errors import ModelError
from femast.testing import fd_tangent

EA = 1.0e5  # N
X90 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.2, 0.0]])  # a quarter turn at node 1
XT = np.array([[0.0, 0.0, 0.0], [1.0, 0.2, 0.1], [1.3, 1.1, -0.2], [2.2, 1.4, 0.3]])


def ev(fam, X, state):
    return fam.evaluate(np.asarray(X, float), None, state, IncrementContext())


def sheave_ratio(rho, phi, sigma):
    """T_out / T_in of a turning sheave: q - 1 = sigma rho sqrt(1 + q^2 - 2 q cos phi), i.e.
    (1 - rho^2) q^2 - 2 (1 - rho^2 cos phi) q + (1 - rho^2) = 0, the root on the side of sigma."""
    a, b = 1.0 - rho**2, 1.0 - rho**2 * math.cos(phi)
    return (b + sigma * math.sqrt(b * b - a * a)) / a


def pulled(X, end, du):
    Y = X.copy()
    Y[end] += du * (X[end] - X[1]) / np.linalg.norm(X[end] - X[1])
    return Y


@pytest.mark.parametrize("point", [True, False])
@pytest.mark.parametrize("end, sigma", [(2, +1), (0, -1)])
def test_sheave_turning_closed_form(point, end, sigma):
    r, r_pin, mu = 0.05, 0.008, 0.3
    dev = Sheave(radius=r, pin_radius=r_pin, mu=mu, point=point)
    fam = CableDeviceFamily.pretensioned([[0, 1, 2]], X90, EA, 100.0, [dev])
    res = ev(fam, pulled(X90, end, 0.01), fam.initial_state())
    T, phi = res.output["tension"][0], res.output["wrap_angle"][0, 0]
    assert res.state[0, 1] == sigma  # turning, the pulled side ahead
    if point:
        assert phi == pytest.approx(math.pi / 2, abs=1e-15)
    else:  # the sized wheel wraps a little more than the quarter turn of the chords
        assert math.pi / 2 < phi < math.pi / 2 + 2 * r
    assert T[1] / T[0] == pytest.approx(sheave_ratio(mu * r_pin / r, phi, sigma), rel=1e-12)
    # the torque balance itself: (T_out - T_in) r = sigma mu r_pin |F|
    F = math.sqrt(T[0] ** 2 + T[1] ** 2 - 2 * T[0] * T[1] * math.cos(phi))
    assert (T[1] - T[0]) * r == pytest.approx(sigma * mu * r_pin * F, rel=1e-10)
    assert res.output["unstretched_length"][0].sum() == pytest.approx(fam.L0[0], rel=1e-14)


def test_sheave_stick_band_closed_form():
    """Below the bearing's friction torque the wheel does not turn: each side keeps its unstretched
    length; it turns once |T_out - T_in| = rho |F|."""
    T0, r, r_pin, mu = 100.0, 0.05, 0.008, 0.3
    rho = mu * r_pin / r
    fam = CableDeviceFamily.pretensioned([[0, 1, 2]], X90, EA, T0, [Sheave(r, r_pin, mu, point=True)])
    st = fam.initial_state()
    l0 = np.diff(np.r_[0.0, st[0, :1], fam.L0])
    T_lim = T0 * sheave_ratio(rho, math.pi / 2, +1)
    du_limit = l0[1] * (1 + T_lim / EA) - 1.2
    for du in (0.3 * du_limit, 0.99 * du_limit):
        X = X90.copy()
        X[2, 1] += du
        res = ev(fam, X, st)
        T = res.output["tension"][0]
        assert res.state[0, 1] == 0
        assert T[0] == pytest.approx(T0, rel=1e-11)
        assert T[1] == pytest.approx(EA * ((1.2 + du) / l0[1] - 1.0), rel=1e-11)
    X = X90.copy()
    X[2, 1] += 1.01 * du_limit
    res = ev(fam, X, st)
    assert res.state[0, 1] == 1
    assert res.output["tension"][0, 1] / res.output["tension"][0, 0] == pytest.approx(
        sheave_ratio(rho, math.pi / 2, 1), rel=1e-12
    )


def test_drum_is_the_capstan_and_far_lossier_than_a_sheave():
    """A quarter wrap with mu = 0.3: a fixed drum (capstan) passes exp(0.3 pi / 2) = 1.60 of the tension,
    a sheave turning on a pin of a tenth of its radius 1 + 0.03 sqrt(2) + O(rho^2) = 1.043."""
    X = pulled(X90, 2, 0.01)
    drum = CableDeviceFamily.pretensioned([[0, 1, 2]], X90, EA, 100.0, [Drum(mu=0.3)])
    pulley = CableDeviceFamily.pretensioned([[0, 1, 2]], X90, EA, 100.0, [Pulley(mu=0.3)])
    sheave = CableDeviceFamily.pretensioned([[0, 1, 2]], X90, EA, 100.0, [Sheave(0.05, 0.005, 0.3, point=True)])
    Td = ev(drum, X, drum.initial_state()).output["tension"][0]
    Tp = ev(pulley, X, pulley.initial_state()).output["tension"][0]
    Ts = ev(sheave, X, sheave.initial_state()).output["tension"][0]
    assert Td[1] / Td[0] == pytest.approx(math.exp(0.3 * math.pi / 2), rel=1e-12)
    np.testing.assert_array_equal(Td, Tp)  # Drum is the capstan Pulley
    assert Ts[1] / Ts[0] == pytest.approx(sheave_ratio(0.03, math.pi / 2, 1), rel=1e-12)
    assert abs(Ts[1] / Ts[0] - (1 + 0.03 * math.sqrt(2))) < 2 * 0.03**2  # first order in rho


def test_frictionless_sheave_is_a_pulley_bit_for_bit():
    X = pulled(XT, 3, 0.01)
    a = CableDeviceFamily.pretensioned([[0, 1, 2, 3]], XT, EA, 80.0, [Sheave(0.1), Pulley(mu=0.2)])
    b = CableDeviceFamily.pretensioned([[0, 1, 2, 3]], XT, EA, 80.0, [Pulley(radius=0.1), Pulley(mu=0.2)])
    ra, rb = ev(a, X, a.initial_state()), ev(b, X, b.initial_state())
    np.testing.assert_array_equal(ra.f, rb.f)
    np.testing.assert_array_equal(ra.k, rb.k)
    np.testing.assert_array_equal(ra.state, rb.state)


def trans(K):
    idx = np.array([6 * a + c for a in range(K.shape[0] // 6) for c in range(3)])
    return K[np.ix_(idx, idx)]


@pytest.mark.parametrize(
    "devices, pull, modes",
    [
        ([Sheave(0.05, 0.01, 0.4, point=True), Pulley()], 0.01, [1, 3]),
        ([Sheave(0.1, 0.02, 0.4), Pulley()], 0.01, [1, 3]),
        ([Sheave(0.05, 0.01, 0.4, point=True), Sheave(0.08, 0.01, 0.3, point=True)], 0.02, [1, 1]),
        ([Pulley(radius=0.15), Sheave(0.05, 0.01, 0.4, point=True)], 0.00003, [3, 0]),
        ([Drum(mu=0.2), Sheave(0.1, 0.02, 0.4)], 0.03, [1, 1]),
    ],
)
def test_sheave_tangent_matches_finite_differences(devices, pull, modes):
    fam = CableDeviceFamily.pretensioned([[0, 1, 2, 3]], XT, EA, 80.0, devices)
    X = XT.copy()
    X[3] += pull * np.array([0.6, 0.8, 0.0])
    st = fam.initial_state()
    r = ev(fam, X, st)
    np.testing.assert_array_equal(r.state[0, 2:], modes)
    Kfd = fd_tangent(fam, X, None, st, h=1e-7, dofs=range(3))[0]
    scale = np.abs(r.k).max()
    np.testing.assert_allclose(trans(r.k[0]), trans(Kfd), rtol=0, atol=1e-6 * scale)


@pytest.mark.parametrize(
    "dev, words",
    [
        (Sheave(0.0, 0.0, 0.1), "radius = 0.0 m must be > 0"),
        (Sheave(0.05, 0.06, 0.1), "pin_radius = 0.06 m must be smaller than the radius"),
        (Sheave(0.05, 0.01, -0.1), "mu = -0.1 must be a finite number >= 0"),
        (Sheave(0.05, 0.04, 2.0), "must be < 1"),
    ],
)
def test_bad_sheaves_are_named(dev, words):
    with pytest.raises(ModelError, match=words):
        CableDeviceFamily.pretensioned([[0, 1, 2]], X90, EA, 100.0, [dev])


def test_per_element_sheave_friction():
    fam = CableDeviceFamily.pretensioned(
        [[0, 1, 2], [0, 1, 2]],
        X90,
        EA,
        100.0,
        [Sheave(0.05, 0.01, 0.3, point=True)],
        device_values={0: {"mu": [0.3, 0.1]}},
    )
    res = ev(fam, pulled(X90, 2, 0.01), fam.initial_state())
    q = res.output["tension"][:, 1] / res.output["tension"][:, 0]
    assert q[0] == pytest.approx(sheave_ratio(0.06, math.pi / 2, 1), rel=1e-12)
    assert q[1] == pytest.approx(sheave_ratio(0.02, math.pi / 2, 1), rel=1e-12)


@pytest.mark.parametrize(
    "values, words",
    [
        ({"mu_s": [0.3, 0.2], "mu_k": [0.1, 0.25]}, r"element 1: kinetic mu_k .* \(static 0\.2, kinetic 0\.25\)"),
        ({"mu": [0.3, 6.0]}, r"element 1: mu pin_radius / radius = 1\.2 must be < 1 \(mu = 6;"),
        ({"mu": [0.0, 0.3]}, r"element 0: mu \(mu_s\) must be finite and > 0 \(got 0\)"),
    ],
)
def test_per_element_sheave_friction_errors_quote_the_users_mu(values, words):
    # the family stores rho = mu r_pin / r (here 0.2 mu); its messages speak of the mu the user gave
    with pytest.raises(ModelError, match=words):
        CableDeviceFamily.pretensioned(
            [[0, 1, 2], [0, 1, 2]], X90, EA, 100.0, [Sheave(0.05, 0.01, 0.3, point=True)], device_values={0: values}
        )


def test_docs_page_quotes_what_the_example_prints(tmp_path, capsys):
    import re

    from doc_examples import printed_in, run_python_blocks

    text = run_python_blocks("cable_devices.md", cwd=tmp_path)
    out = capsys.readouterr().out
    quoted = re.findall(r"`((?:Drum|Sheave): T_out/T_in[^`]+)`", text)
    assert len(quoted) == 2
    for q in quoted:
        assert printed_in(q, out), q


def eq14_out(x, p):
    """Eq. 14 (Stohlman & Pellegrino), unlatching branch, written out here."""
    rho = p.r + p.R
    y = math.sqrt(max(rho**2 - x**2, 0.0))
    delta = max(y - p.h - p.r, 0.0)
    return -2.0 * p.k * delta * (x - p.mu * y) / (y + p.mu * x)


def test_latch_with_the_bearing_of_its_unit_sheave():
    """ADAM's pulley-and-latch unit: a latch and a sheave at one node.  A sliding bead's jump is Eq. 14
    plus the bearing's rho |F|; out of the rollers' reach the unit is a sheave (closed form above)."""
    from femast.elements.cable_devices import Latch
    from femast.elements.latch_law import LatchParameters

    p = LatchParameters.adam_fit()
    sheave = Sheave(0.01, 0.002, 0.3, point=True)
    rho = 0.3 * 0.002 / 0.01
    Xc = np.array([[0.0, 0.0, 0.0], [0.3, 0.0, 0.0], [0.3, 0.4, 0.0]])  # a quarter turn at the unit
    fam = CableDeviceFamily.pretensioned([[0, 1, 2]], Xc, 2e4, 20.0, [Latch(p, sheave=sheave)])
    st = fam.initial_state()
    inside = out = 0
    for du in np.linspace(0.0, 0.02, 201)[1:]:
        X = Xc.copy()
        X[2, 1] += du
        r = ev(fam, X, st)
        st = r.state
        T, x = r.output["tension"][0], r.output["bead_position"][0, 0]
        if st[0, 1] != 1:
            continue
        F = math.sqrt(T[0] ** 2 + T[1] ** 2)  # (phi = pi / 2: cos phi = 0)
        assert T[1] - T[0] == pytest.approx(eq14_out(x, p) + rho * F, abs=1e-8)
        inside += abs(x) < 2.34e-3
        out += abs(x) > 2.35e-3
    assert inside > 3 and out > 3
    assert T[1] / T[0] == pytest.approx(sheave_ratio(rho, math.pi / 2, 1), rel=1e-10)
    # the tangent of the sliding unit
    X = Xc.copy()
    X[2, 1] += 0.0014
    st0 = fam.initial_state()
    r = ev(fam, X, st0)
    assert r.state[0, 1] == 1
    Kfd = fd_tangent(fam, X, None, st0, h=1e-8, dofs=range(3))[0]
    np.testing.assert_allclose(trans(r.k[0]), trans(Kfd), rtol=0, atol=1e-6 * np.abs(r.k).max())
