"""``off_axis_motion`` on bay-torsion: the rig's rotation axis off the bay axis in any direction.

The bay repeats itself every 90 degrees about its axis, so an axis at c and at c turned by 90
degrees give the same moment, but an axis between two sides does not behave like one on a side:
the effect needs a direction (e_x, e_y), not a distance only.  The data of the slow case are an FE
run of the plain bay driven along the path a rig turning about an off-axis point gives (written
here with complex numbers, not with the effect's rotation matrix), with the measured ux, uy then
left out of the file, as a rig that does not measure them gives it.
"""

import numpy as np
import pytest

from femast.effects import resolve
from femast.experiments import EffectStack, Measured, diagnose, get_experiment, predict

BT = get_experiment("bay-torsion")


def _turned(theta_rad, c):
    """Top-centre path (ux, uy) when the top turns by theta about the vertical axis through c = x + iy."""
    z = c - c * np.exp(1j * theta_rad)  # the centre, at 0, turned about c
    return z.real, z.imag


def test_the_top_centre_turns_about_the_axis_in_any_direction():
    th = np.radians(np.linspace(0.0, 3.0, 9))
    drive = np.column_stack([th, np.zeros(9), np.zeros(9)])
    ((nm, impl),) = resolve(BT, ["off_axis_motion"])
    assert [p.name for p in impl.parameters] == ["e_x", "e_y"]
    for ang in (0.0, 11.5, 60.0, 200.0):
        c = 0.012 * np.exp(1j * np.radians(90.0 + ang))
        out = EffectStack([(nm, impl, {"e_x": c.real, "e_y": c.imag})]).apply(
            "control_path", drive, options=BT.options, params=BT.defaults()
        )
        ux, uy = _turned(th, c)
        np.testing.assert_allclose(out[:, 1], ux, atol=1e-15)
        np.testing.assert_allclose(out[:, 2], uy, atol=1e-15)
    # the one-distance form keeps the direction of option off_axis_side (side 0: +y)
    ((nm, side),) = resolve(BT, ["off_axis_motion/side"])
    out = EffectStack([(nm, side, {"e": 0.012})]).apply("control_path", drive, options=BT.options, params=BT.defaults())
    ux, uy = _turned(th, 0.012j)
    np.testing.assert_allclose(out[:, 1:], np.column_stack([ux, uy]), atol=1e-15)


def _moment(c, theta_deg):
    th = np.radians(theta_deg)
    ux, uy = _turned(th, c)
    data = Measured("bay-torsion", {"theta_deg": theta_deg, "ux_m": ux, "uy_m": uy, "Mz_Nm": np.zeros(th.size)})
    return predict(BT, data)["Mz_Nm"]


def test_a_quarter_turn_of_the_axis_changes_nothing_but_another_direction_does():
    theta = np.concatenate([np.linspace(0.0, 3.2, 17), np.linspace(3.2, 0.0, 17)[1:]])
    c = 0.010 * np.exp(1j * np.radians(90.0 + 11.5))
    a, b = _moment(c, theta), _moment(1j * c, theta)
    np.testing.assert_allclose(a, b, atol=2e-3)  # the bay's four-fold symmetry, to the FE tolerances
    on_side = _moment(0.010j, theta)
    assert np.max(np.abs(a - on_side)) > 0.1  # N m: more than the noise of a torsion rig (0.1 N m)


@pytest.mark.slow
def test_an_axis_off_every_side_is_found_with_its_direction():
    theta = np.concatenate([np.linspace(0.0, 3.2, 21), np.linspace(3.2, 0.0, 21)[1:]])
    c = 0.010 * np.exp(1j * np.radians(90.0 + 11.5))  # 10 mm, 11.5 degrees off side 0
    rng = np.random.default_rng(4)
    Mz = _moment(c, theta) + 0.1 * rng.standard_normal(theta.size)
    data = Measured("bay-torsion", {"theta_deg": theta, "Mz_Nm": Mz})  # ux, uy not measured
    d = diagnose(BT, data, candidates=["off_axis_motion"], workers=1)
    top = d.ranking[0]
    e = top["params"]["e_x"]["value"] + 1j * top["params"]["e_y"]["value"]
    assert abs(abs(e) - 0.010) < 0.0015
    ang = (np.degrees(np.angle(e)) - 90.0) % 90.0  # the direction up to a quarter turn
    assert min(abs(ang - 11.5), abs(ang - 11.5 - 90.0)) < 4.0
    assert top["ratio"] <= d.at_noise
