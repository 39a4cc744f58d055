"""Latch law of Stohlman & Pellegrino, Eqs. 6-14 (femast.elements.latch_law)."""

import math

import numpy as np
import pytest

from femast.elements.latch_law import (
    LATCHING,
    UNLATCHING,
    ZONE_BACKSTOP,
    ZONE_BEHIND_AXIS,
    ZONE_FREE,
    ZONE_IN_FRONT,
    LatchParameters,
    contact_half_width,
    friction_band,
    latch_energy,
    latch_force,
    latch_zone,
    roller_opening,
)
from femast.errors import ModelError

P = LatchParameters.adam_fit()
MM = 1e-3


def test_adam_fit_in_si():
    p = LatchParameters.from_mm(r=1.1, x_backstop=2.0, k=100.0, mu=0.07, h=1.5, R=2.4)
    np.testing.assert_allclose(p.as_array(), P.as_array(), rtol=1e-15)  # same numbers, two unit paths
    np.testing.assert_allclose(P.as_array(), [1.1e-3, 2.0e-3, 1e5, 0.07, 1.5e-3, 2.4e-3], rtol=1e-15)  # exact SI


def test_hand_values_at_roller_axis():
    # x = 0: delta = R - h = 0.9 mm, y = r + R, so Eq. 14 gives dT = -/+ 2 k delta mu.
    hand = 2 * 1e5 * 0.9e-3 * 0.07  # 12.6 N
    assert latch_force(0.0, LATCHING, P) == pytest.approx(-hand, rel=1e-12)  # closed form, rounding only
    assert latch_force(0.0, UNLATCHING, P) == pytest.approx(hand, rel=1e-12)  # closed form, rounding only
    assert roller_opening(0.0, P) == pytest.approx(0.9e-3, rel=1e-12)  # Eq. 10 by hand


def test_hand_value_at_backstop():
    # x = -2 mm: y = sqrt(3.5^2 - 2^2) mm, delta = y - 2.6 mm, computed by hand from Eqs. 10, 14.
    y = math.sqrt(3.5**2 - 2.0**2)
    d = y - 2.6
    out = -2 * 100.0 * d * (-2.0 - 0.07 * y) / (y + 0.07 * -2.0)  # N with mm and N/mm
    inn = -2 * 100.0 * d * (-2.0 + 0.07 * y) / (y - 0.07 * -2.0)
    assert latch_force(-2 * MM, UNLATCHING, P) == pytest.approx(out, rel=1e-12)  # unit conversion only
    assert latch_force(-2 * MM, LATCHING, P) == pytest.approx(inn, rel=1e-12)  # unit conversion only
    assert out == pytest.approx(43.87, abs=0.01)  # hand arithmetic to 4 digits


def test_theta_form_eq13_equals_eq14():
    # Eq. 13 written with theta of Eqs. 7-8 (cos = x/(r+R), sin = (h+delta+r)/(r+R)).
    x = np.linspace(-2.3, 2.3, 47) * MM
    d = roller_opening(x, P)
    c = x / (P.r + P.R)
    s = (P.h + d + P.r) / (P.r + P.R)
    k, mu = P.k, P.mu
    eq13_in = -2 * k * d * (c + mu * s) / (s - mu * c)
    eq13_out = -2 * k * d * (c - mu * s) / (s + mu * c)
    np.testing.assert_allclose(latch_force(x, LATCHING, P), eq13_in, rtol=1e-12, atol=1e-12)  # algebraic identity
    np.testing.assert_allclose(latch_force(x, UNLATCHING, P), eq13_out, rtol=1e-12, atol=1e-12)  # algebraic identity


def test_frictionless_law_is_gradient_of_roller_energy():
    # mu = 0: no dissipation, so the cable does work dT dx = dU with U = k delta^2 (two springs).
    p0 = LatchParameters(r=P.r, x_backstop=P.x_backstop, k=P.k, mu=0.0, h=P.h, R=P.R)
    x = np.linspace(-2.2, 2.2, 23) * MM
    hstep = 1e-9
    dU = (latch_energy(x + hstep, p0) - latch_energy(x - hstep, p0)) / (2 * hstep)
    np.testing.assert_allclose(latch_force(x, UNLATCHING, p0), dU, rtol=1e-6, atol=1e-6)  # central FD, O(h^2)
    np.testing.assert_allclose(latch_force(x, LATCHING, p0), dU, rtol=1e-6, atol=1e-6)  # central FD, O(h^2)


def test_odd_symmetry_between_branches():
    # Mirror x -> -x and reverse the motion: dT_out(-x) = -dT_in(x).
    x = np.linspace(-2.3, 2.3, 31) * MM
    np.testing.assert_allclose(latch_force(-x, UNLATCHING, P), -latch_force(x, LATCHING, P), atol=1e-10)  # rounding


def test_friction_orders_branches():
    x = np.linspace(-2.34, 2.34, 200) * MM
    assert np.all(latch_force(x, LATCHING, P) <= latch_force(x, UNLATCHING, P) + 1e-12)  # friction dissipates


@pytest.mark.parametrize("direction", [LATCHING, UNLATCHING])
def test_derivative_matches_finite_differences(direction):
    x = np.linspace(-2.3, 2.3, 41) * MM
    v, dv = latch_force(x, direction, P, derivative=True)
    h = 1e-9  # m; truncation ~h^2 * f''' ~ 1e-6 relative
    fd = (latch_force(x + h, direction, P) - latch_force(x - h, direction, P)) / (2 * h)
    np.testing.assert_allclose(dv, fd, rtol=1e-5, atol=1e-3)  # central FD error, N/m on ~1e5 N/m slopes


def test_contact_zone_and_no_force_outside():
    xc = contact_half_width(P)
    assert xc == pytest.approx(math.sqrt(3.5**2 - 2.6**2) * MM, rel=1e-14)  # Eq. 6 with delta = 0
    outside = np.array([xc, xc * 1.001, 4 * MM, -xc, 10.0])
    for d in (LATCHING, UNLATCHING):
        np.testing.assert_array_equal(latch_force(outside, d, P), 0.0)  # no contact, no force
    assert abs(latch_force(xc * 0.999, UNLATCHING, P)) > 0.0


def test_peak_forces_match_figure_10_range():
    # Fig. 10 spans about +-60 N; the fitted law peaks at +-63.5 N (x = +-1.43 mm).
    x = np.linspace(-2.0, 2.34, 20001) * MM
    lat = latch_force(x, LATCHING, P)
    unl = latch_force(x, UNLATCHING, P)
    assert lat.min() == pytest.approx(-63.54, abs=0.02)  # dense grid around a smooth minimum
    assert unl.max() == pytest.approx(63.54, abs=0.02)  # dense grid around a smooth maximum
    assert x[np.argmin(lat)] == pytest.approx(1.43e-3, abs=0.01e-3)  # grid spacing 0.2 um, flat peak


def test_friction_band_and_backstop():
    lo, hi = friction_band(np.array([-2 * MM, 0.0, 3 * MM]), P)
    assert lo[0] == -np.inf  # backstop takes any inward pull
    assert hi[0] == pytest.approx(latch_force(-2 * MM, UNLATCHING, P), rel=1e-15)  # same formula
    assert lo[1] == pytest.approx(-12.6, rel=1e-12) and hi[1] == pytest.approx(12.6, rel=1e-12)  # hand values
    assert lo[2] == 0.0 and hi[2] == 0.0  # no contact


def test_zones():
    z = latch_zone(np.array([-2.0, -1.0, 0.0, 1.0, 2.5]) * MM, P)
    np.testing.assert_array_equal(z, [ZONE_BACKSTOP, ZONE_BEHIND_AXIS, ZONE_IN_FRONT, ZONE_IN_FRONT, ZONE_FREE])


def test_broadcast_over_parameter_arrays():
    pa = np.stack([P.as_array(), LatchParameters(k=2e5).as_array()])
    v = latch_force(0.0, UNLATCHING, pa)
    np.testing.assert_allclose(v, [12.6, 25.2], rtol=1e-12)  # linear in k


@pytest.mark.parametrize(
    "kw, words",
    [
        (dict(R=1.0e-3, h=1.5e-3), "never touch"),
        (dict(k=-1.0), "k="),
        (dict(r=0.0), "r="),
        (dict(mu=-0.1), "mu"),
        (dict(x_backstop=-1e-3), "x_backstop"),
        (dict(mu=2.0), "self-locks"),
    ],
)
def test_bad_parameters_raise_clear_errors(kw, words):
    with pytest.raises(ModelError, match=words):
        LatchParameters(**{**P.__dict__, **kw}).validate("latch L1")


def test_direction_must_be_unit():
    with pytest.raises(ModelError, match="direction"):
        latch_force(0.0, 0, P)
