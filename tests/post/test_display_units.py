"""Units chosen for the magnitude shown on axes and colour bars: um for um-scale motion, arcsec
for arcsecond rotations, and the factor that converts SI values into that unit."""

import math

import numpy as np
import pytest

from femast.post.plotstyle import display_scale


@pytest.mark.parametrize(
    "unit, values, label, shown",
    [
        ("m", [0.0, -7.04e-5, 3e-5], "um", 70.4),  # the colour bar of a um-scale deflection
        ("m", 2.5e-3, "mm", 2.5),
        ("m", [0.4, 1.7], "m", 1.7),
        ("m", 3e-8, "nm", 30.0),
        ("rad", 9.7e-6, "arcsec", 9.7e-6 * 180 * 3600 / math.pi),  # ~2 arcsec: the ADAM tip rotation scale
        ("rad", 0.01, "mrad", 10.0),
        ("rad", 0.5, "deg", 0.5 * 180 / math.pi),
        ("N", 2.0e4, "kN", 20.0),
        ("N m", 6.8, "N m", 6.8),
    ],
)
def test_unit_for_the_magnitude(unit, values, label, shown):
    factor, got = display_scale(unit, values)
    assert got == label
    assert factor * np.max(np.abs(values)) == pytest.approx(shown, rel=1e-12)


def test_without_values_or_with_nothing_to_size_the_default_stays():
    assert display_scale("m") == (1e3, "mm") and display_scale("rad") == (1e3, "mrad")
    assert display_scale("m", [0.0, np.nan]) == (1e3, "mm")
    assert display_scale("K", [300.0]) == (1.0, "K")  # a unit without a ladder is shown as it is
