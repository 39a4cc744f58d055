"""The joint-test rig: its model is what its docstring says (the effects on the load and the
displacement, the degradation on its own hook), its parameters carry the test's units and names,
and its shipped real example keeps its licence and citation."""

import numpy as np
import pytest

import femast.examples
from femast.effects.damage import damage, degrade
from femast.effects.gap_slip import gap_slip
from femast.effects.operators import play
from femast.experiments import from_arrays, get_experiment, predict, read_data
from femast.rigs.joint_test import joint_test


def _cycles(amps, n=200):
    """A force path 0 -> +a -> -a -> 0 for each amplitude (N)."""
    parts = [np.zeros(1)]
    for a in amps:
        for p in (a, -a, 0.0):
            parts.append(np.linspace(parts[-1][-1], p, n + 1)[1:])
    return np.concatenate(parts)


@pytest.fixture(scope="module")
def rig():
    exp = get_experiment("joint-test")
    F = _cycles([4e3, 8e3, 12e3])
    return exp, from_arrays(exp, F_N=F, u_m=F / 2e6), F


def test_baseline_is_a_spring(rig):
    exp, data, F = rig
    u = predict(exp, data, {"k": 2.5e6})["u_m"]
    np.testing.assert_allclose(u, F / 2.5e6, rtol=1e-14)


def test_friction_and_pinching_enter_as_the_docstring_says(rig):
    exp, data, F = rig
    k = 2e6
    pin = {"F_y": 5e3, "k_e": 8e6, "F_f": 600.0, "k_g": 4e5}
    u = predict(exp, data, {"k": k}, {"pinching": pin})["u_m"]
    np.testing.assert_allclose(u, F / k + gap_slip(F, pin["F_y"], pin["k_e"], pin["F_f"], pin["k_g"]), rtol=1e-12)
    # friction (play form) on the load: the spring sees F less the play's stop, u = play(F, F_f) / k
    u = predict(exp, data, {"k": k}, {"friction_hysteresis": {"F_f": 1.5e3}})["u_m"]
    np.testing.assert_allclose(u, play(F, 1.5e3) / k, rtol=1e-12, atol=1e-15)


def test_degradation_is_the_damage_fixed_point_over_every_other_mechanism(rig):
    exp, data, F = rig
    k, F_f, D_max, S_d = 2e6, 1.5e3, 0.4, 2e-3
    u = predict(exp, data, {"k": k}, {"friction_hysteresis": {"F_f": F_f}, "degradation": {"D_max": D_max, "S_d": S_d}})

    def slip_of(F_eff):  # the slip of the friction mechanism under the effective load
        return (play(F_eff, F_f) - F_eff) / k

    D, F_eff = degrade(F, slip_of, D_max, S_d, "slip")
    np.testing.assert_allclose(u["u_m"], play(F_eff, F_f) / k, rtol=1e-9)
    assert D[-1] > 0.1
    # the damage grows with the cumulative slip: D at the end from the slip of the degraded path
    s = slip_of(F_eff)
    np.testing.assert_allclose(D[-1], damage(np.sum(np.abs(np.diff(s))), D_max, S_d), rtol=1e-6)


def test_units_and_names_follow_the_quantities():
    force = get_experiment("joint-test")
    moment = joint_test("joint-test-moment", "M_Nm", "phi_rad", moment=True)
    from femast.effects import get_effect

    names = lambda exp, eff: {p.name: p.unit for p in get_effect(eff).parameters(exp)}  # noqa: E731
    assert names(force, "pinching") == {"F_y": "N", "k_e": "N/m", "F_f": "N", "k_g": "N/m"}
    assert names(moment, "pinching") == {"M_y": "N m", "k_e": "N m/rad", "M_f": "N m", "k_g": "N m/rad"}
    assert names(force, "degradation") == {"D_max": "-", "S_d": "m"}
    assert names(moment, "degradation") == {"D_max": "-", "S_d": "rad"}
    assert {p.name: p.unit for p in get_effect("degradation").implementation(force).forms["energy"].parameters} == {
        "D_max": "-",
        "E_d": "J",
    }
    assert names(moment, "friction_hysteresis") == {"M_f": "N m"}


def test_the_real_example_ships_with_its_licence_and_citation():
    exp = get_experiment("joint-test")
    path = femast.examples.for_experiment("joint-test")
    data = read_data(exp, path)
    assert data.n == 33028  # every row of the source, none added or removed
    lines = path.read_text().splitlines()
    assert next(ln for ln in lines if not ln.startswith("#")) == "F_N,u_m"
    # the source's kN and mm, converted exactly: the largest stroke of the test is 84.58 mm, its force 36.40 kN
    i = int(np.argmin(data["u_m"]))
    assert data["u_m"][i] == pytest.approx(-84.58e-3, abs=1e-12)
    assert data["F_N"][i] == pytest.approx(-36.40e3, abs=1e-9)
    folder = path.parent
    licence = (folder / "LICENSE-SPC1-Apache-2.0.txt").read_text()
    assert "Apache License" in licence and "Version 2.0" in licence
    notice = (folder / "NOTICE-SPC1.txt").read_text()
    for words in ("not made by femast", "Tannert", "World Conference on Timber Engineering", "cslotboom/hysteresis"):
        assert words in notice
    assert "not made by femast" in lines[1]


def test_copying_the_examples_keeps_the_licence_beside_the_real_data(tmp_path):
    from femast.cli import main

    assert main(["examples", "--copy", str(tmp_path)]) in (0, None)
    assert (tmp_path / "joint_test_spc1.csv").is_file()
    assert (tmp_path / "NOTICE-SPC1.txt").is_file() and (tmp_path / "LICENSE-SPC1-Apache-2.0.txt").is_file()
