"""The ``vibration`` experiment: data, baseline against the closed form, effects,
and diagnose on the shipped example (hidden pretension loss, generator independent of femast)."""

import math

import numpy as np
import pytest

import femast.examples
from femast.adam.mass import UNIT_MASS, cable_mass_per_length
from femast.adam.parameters import BayParameters
from femast.effects import get_effect
from femast.errors import ModelError
from femast.experiments import diagnose, from_arrays, get_experiment, predict, read_data

EXAMPLE = femast.examples.path("vibration_example.csv")  # package data


def _closed_form(T, m_unit):
    p = BayParameters()
    L = 0.5 * p.diagonal
    m = m_unit + 2 * cable_mass_per_length(p.cable_EA) * L
    return math.sqrt(4 * T / (L * m)) / (2 * math.pi)


def test_baseline_is_the_taut_cable_resonance_and_fit_option_sets_parameters():
    exp = get_experiment("vibration")
    assert [p.name for p in exp.parameters] == ["pretension"]
    assert [p.name for p in get_experiment("vibration", fit="both").parameters] == ["pretension", "unit_mass"]
    data = from_arrays(exp, mode=[1, 1, 2], f_Hz=[60.0, 70.0, 500.0], pretension_N=[130.0, 170.0, 170.0])
    f = predict(exp, data, params={"pretension": 170.0})["f_Hz"]
    # 1e-6: the Newton tolerance of the static state
    assert f[0] == pytest.approx(_closed_form(130.0, UNIT_MASS), rel=1e-6)
    assert f[1] == pytest.approx(_closed_form(170.0, UNIT_MASS), rel=1e-6)
    assert f[2] > 5 * f[1]  # mode 2 is in plane: the cables' EA, far above


def test_effects_shift_frequencies_as_their_physics_says():
    exp = get_experiment("vibration", fit="mass")
    data = from_arrays(exp, mode=[1, 1], f_Hz=[60.0, 70.0], pretension_N=[130.0, 170.0])
    p = {"unit_mass": 0.02}
    base = predict(exp, data, params=p)["f_Hz"]
    loss = predict(exp, data, p, {"pretension_loss": {"dT0": -10.0}})["f_Hz"]
    np.testing.assert_allclose(loss / base, np.sqrt((np.array([130.0, 170.0]) - 10) / [130.0, 170.0]), rtol=1e-6)
    added = predict(exp, data, p, {"added_mass": {"added": 0.005}})["f_Hz"]
    m_c = 2 * cable_mass_per_length(BayParameters().cable_EA) * 0.5 * BayParameters().diagonal
    np.testing.assert_allclose(added / base, math.sqrt((0.02 + m_c) / (0.025 + m_c)), rtol=1e-6)
    stick = predict(exp, data, p, {"joint_stick": {"k_stick": 5000.0}})["f_Hz"]
    k = 4 * np.array([130.0, 170.0]) / (0.5 * BayParameters().diagonal)
    np.testing.assert_allclose(stick / base, np.sqrt((k + 5000.0) / k), rtol=1e-6)


def test_pretension_loss_keeps_its_other_experiments():
    eff = get_effect("pretension_loss")
    assert {"bay-torsion", "tip-cycle", "vibration"} <= set(eff.implementations) and eff.mechanism is not None


def test_bad_mode_and_fit_option():
    exp = get_experiment("vibration")
    data = from_arrays(exp, mode=[0, 1], f_Hz=[60.0, 70.0])
    with pytest.raises(ModelError, match="line 2, column 'mode': mode = 0; modes are whole numbers"):
        predict(exp, data)
    with pytest.raises(ModelError, match="option fit = 'tension'"):
        get_experiment("vibration", fit="tension")


@pytest.mark.slow
def test_diagnose_finds_the_hidden_pretension_loss(tmp_path):
    exp = get_experiment("vibration", fit="mass")
    data = read_data(exp, EXAMPLE)
    d = diagnose(exp, data, out=tmp_path, workers=1)
    top = d.ranking[0]
    assert top["effect"] == "pretension_loss" and top["significant"]
    assert d.verdict["missing_effect"] == "pretension_loss"
    # the generator's hidden loss is 15 N: within 3 standard errors of the fit (0.12 Hz noise, 9 rows)
    est, se = top["params"]["dT0"]["value"], top["params"]["dT0"]["stderr"]
    assert abs(est + 15.0) <= 3 * se


def _string_builder(T, m_unit, load, options):
    """A user's model: a taut string of 2 m with a bead (the unit mass) at its middle."""
    import femast as fm

    mod = fm.Model("bead on a string")
    a, c, b = mod.node(0, 0, 0), mod.node(1.0, 0, 0), mod.node(2.0, 0, 0)
    mod.truss(a, c, EA=1e7, pretension=T)
    mod.truss(c, b, EA=1e7, pretension=T)
    mod.fix(a)
    mod.fix(b)
    mod.point_mass(c, m_unit)
    mod.step("hold")
    return mod, c


def test_user_model_builder():
    """Bead m on a massless string, tension T, halves of 1 m: omega^2 = 2 T / (m 1 m) (exact up to
    the Newton tolerance of the state, 1e-6)."""
    exp = get_experiment("vibration", builder=_string_builder, drive_direction=(0.0, 0.0, 1.0), unit_mass_kg=0.05)
    data = from_arrays(exp, mode=[1, 1], f_Hz=[10.0, 12.0], pretension_N=[50.0, 80.0])
    f = predict(exp, data, params={"pretension": 170.0})["f_Hz"]
    np.testing.assert_allclose(f, np.sqrt(2 * np.array([50.0, 80.0]) / 0.05) / (2 * math.pi), rtol=1e-6)
    # the joint_stick spring acts along the drive direction (z): it stiffens one of the two
    # transverse modes, k = 2T/L + k_stick
    g = predict(exp, data, {"pretension": 170.0}, {"joint_stick": {"k_stick": 100.0}})["f_Hz"]
    np.testing.assert_allclose(g, f, rtol=1e-6)  # mode 1 is the y mode, the spring is along z
