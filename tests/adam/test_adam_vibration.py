"""Stohlman & Pellegrino's pretension-by-vibration method (Sec. IV, Eq. 16)."""

import math

import numpy as np
import pytest

from femast.adam import vibration as v
from femast.adam.mass import cable_mass_per_length
from femast.adam.parameters import BayParameters
from femast.errors import ModelError


def test_eq16_read_in_lbf_matches_the_seed_figures():
    # Fig. 14: data from about 130 N at 65 Hz to about 210 N at 80 Hz (axis 130-210 N, 65-80 Hz);
    # the bounds are the figure's axis ticks (+-10 N: reading a printed axis)
    assert 125 < v.eq16_tension(65.0) < 140
    assert 200 < v.eq16_tension(80.0) < 220
    # as printed (N), the same frequencies give 30 and 47 "N": not the figure
    assert v.eq16_printed(65.0) == pytest.approx(30.0, abs=1e-9)
    # Fig. 13: peaks of 125-188 N inside its 55-85 Hz axis
    f = v.eq16_frequency(np.array([125.0, 188.0]))
    assert np.all((f > 55) & (f < 85))
    np.testing.assert_allclose(v.eq16_tension(f), [125.0, 188.0], rtol=1e-12)  # exact inverse


def test_mock_side_resonance_is_the_taut_cable_closed_form():
    """Out-of-plane stiffness of the unit: sum T_i / L_i (stress stiffness); mass: the unit plus
    half of each section's cable mass (lumped).  Tolerance 1e-6: the Newton tolerance of the state."""
    p = BayParameters()
    side = v.mock_bay_side(150.0, p, unit_mass=0.02)
    f, T, modes = v.latch_resonance(side)
    assert T == pytest.approx(150.0, rel=1e-6)
    cm = cable_mass_per_length(p.cable_EA)
    m = 0.02 + 0.5 * cm * side.lengths.sum()
    exact = math.sqrt(np.sum(T / side.lengths) / m) / (2 * math.pi)
    assert f == pytest.approx(exact, rel=1e-6)
    assert side.lengths == pytest.approx(np.full(4, 0.5 * p.diagonal), rel=1e-12)


def test_unit_mass_identified_from_eq16():
    fit = v.identify_unit_mass()
    # the model curve lies within the calibration's scatter (2 lbf) over 120-200 N
    assert fit.max_dev < v.EQ16_SD_N
    # independent check: least-squares T = c f^2 to Eq. 16 on a uniform frequency grid, then
    # m_eff = sum(1/L_i) c / (2 pi)^2.  1 %: the two fits weight the range differently
    f1, f2 = v.eq16_frequency(np.array(v.EQ16_RANGE_N))
    ff = np.linspace(f1, f2, 201)
    c = np.sum(ff**2 * v.eq16_tension(ff)) / np.sum(ff**4)
    m_eff = 4 / (0.5 * BayParameters().diagonal) * c / (2 * math.pi) ** 2
    assert fit.effective_mass == pytest.approx(m_eff, rel=1e-2)
    # the inverse use returns the model's own tensions at the model's frequencies (T = c f^2 exact)
    T, s = v.tension_from_frequency(fit.frequency, fit, sigma_f_hz=0.0)
    np.testing.assert_allclose(T, fit.tension, rtol=1e-6)
    assert np.all(s >= v.EQ16_SD_N)


def test_bad_frequency_and_tension():
    fit = v.UnitMassFit(0.02, 0.0204, np.array([150.0]), np.array([70.0]), np.array([150.0]), 0, 0, 1e-4)
    with pytest.raises(ModelError, match="frequency -1.0 Hz"):
        v.tension_from_frequency(-1.0, fit)
    with pytest.raises(ModelError, match="tension = -5"):
        v.mock_bay_side(-5.0)
