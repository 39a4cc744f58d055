"""Tube sections in both conventions of tube tables: outer and inner size, or outer size and wall
thickness (``square_tube(b=, t=)``, ``circular_tube(d=, t=)``), against the closed forms."""

import math

import pytest

import femast as fm


def test_square_tube_by_width_and_wall():
    b, t = 0.05, 0.003
    s = fm.square_tube(b=b, t=t, E=210e9)
    inner = b - 2 * t
    assert s.A == pytest.approx(b**2 - inner**2)  # 5.64e-4 m^2
    assert s.Iy == pytest.approx((b**4 - inner**4) / 12)
    assert s.J == pytest.approx(t * (b - t) ** 3)  # Bredt: 4 A_m^2 t / p_m with A_m = (b - t)^2
    other = fm.square_tube(0.05, 0.044, E=210e9)  # the same tube by outer and inner side
    assert (s.A, s.Iy, s.J) == pytest.approx((other.A, other.Iy, other.J), rel=1e-12)


def test_circular_tube_by_diameter_and_wall():
    d, t = 0.03, 0.002
    s = fm.circular_tube(d=d, t=t, E=70e9, nu=0.33)
    assert s.A == pytest.approx(math.pi * (d - t) * t)  # exact: pi (d^2 - (d - 2t)^2) / 4
    assert s.J == pytest.approx(math.pi * (d**4 - (d - 2 * t) ** 4) / 32)
    assert s.G == pytest.approx(70e9 / 2.66)
    other = fm.circular_tube(0.03, 0.026, E=70e9, nu=0.33)
    assert (s.A, s.Iy, s.J) == pytest.approx((other.A, other.Iy, other.J), rel=1e-12)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(b=0.05, E=1e9), "give both b="),
        (dict(b=0.05, t=0.03, E=1e9), "more than half the outer size"),
        (dict(s_out=0.05, t=0.003, E=1e9), "not both"),
        (dict(b=0.05, t=-0.003, E=1e9), "t=-0.003 must be a positive length"),
        (dict(b=0.05, t=0.003), "give Young's modulus E"),
        (dict(E=1e9), "give s_out and s_in"),
    ],
)
def test_mixed_or_incomplete_conventions_are_refused(kwargs, message):
    with pytest.raises(fm.ModelError, match=message):
        fm.square_tube(**kwargs)
