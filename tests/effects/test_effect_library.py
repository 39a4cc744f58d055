"""The effect library: operators, documentation, applicability, registration."""

from pathlib import Path

import numpy as np
import pytest

from femast.effects import (
    Effect,
    Implementation,
    add_implementation,
    applicable_effects,
    get_effect,
    list_effects,
    play,
    proportional_play,
    register_effect,
    resolve,
    unregister_effect,
)
from femast.errors import ModelError
from femast.experiments import Parameter, get_experiment, list_experiments, predict
from femast.rigs.synthetic import mast_top_data, mast_top_path

ROOT = Path(__file__).resolve().parents[2]
REQUIRED = (
    "joint_clearance",
    "friction_hysteresis",
    "beam_flexibility",
    "progressive_stiffness",
    "cable_hysteresis",
    "latch_hysteresis",
    "ball_joint_friction",
    "off_axis_motion",
    "pretension_loss",
)
BUILT_IN = REQUIRED + ("stretch_error",)


def test_play_operator_lags_then_sticks_for_twice_the_friction():
    u = np.concatenate([np.linspace(0, 10, 11), np.linspace(9, -10, 20)])
    p = play(u, 2.0)
    np.testing.assert_allclose(p[:3], 0.0)  # static friction: nothing moves until the load exceeds r
    np.testing.assert_allclose(p[5:11], u[5:11] - 2.0)  # then it lags by r
    np.testing.assert_allclose(p[11:15], 8.0)  # after the reversal at 10 it sticks until u = 10 - 2 r
    np.testing.assert_allclose(p[16:], u[16:] + 2.0)  # then lags by r the other way
    np.testing.assert_allclose(play(u, 0.0), u)


def test_proportional_play_loop_widens_with_load_and_closes_at_zero():
    u = np.concatenate([np.linspace(0, 10, 101), np.linspace(10, 0, 101)])
    p = proportional_play(u, 0.1)
    np.testing.assert_allclose(p[100], 9.0)  # loading branch: (1 - eta) u
    np.testing.assert_allclose(p[-1], 0.0, atol=1e-12)  # the loop closes at zero load
    i = 101 + 60  # unloading at u = 4: (1 + eta) u after the stick
    np.testing.assert_allclose(p[i], 1.1 * u[i])


def test_every_effect_is_documented_with_units_bounds_and_applicability():
    names = [e.name for e in list_effects()]
    for n in REQUIRED:
        assert n in names
    for e in map(get_effect, BUILT_IN):
        assert e.title and len(e.physics) > 80 and e.signature and (e.implementations or e.mechanism), e.name
        for exp in list_experiments():
            impl = e.implementation(exp)
            if impl is None:
                continue
            assert impl.hook, (e.name, exp.name)
            for im in (impl, *impl.forms.values()):
                for p in im.parameters:
                    assert p.unit and p.doc and p.lower <= p.default <= p.upper, (e.name, exp.name, p.name)


def test_applicability_of_the_built_in_effects():
    mt = {e.name for e in applicable_effects(get_experiment("mast-top"))}
    lp = {e.name for e in applicable_effects(get_experiment("latch-pull"))}
    assert {
        "joint_clearance",
        "friction_hysteresis",
        "beam_flexibility",
        "progressive_stiffness",
        "cable_hysteresis",
        "pretension_loss",
    } <= mt
    assert {"latch_hysteresis", "friction_hysteresis", "stretch_error", "cable_hysteresis"} <= lp
    # the FE experiments (their own tests: tests/experiments/test_experiments_fe.py)
    bt = {e.name for e in applicable_effects(get_experiment("bay-torsion"))}
    tc = {e.name for e in applicable_effects(get_experiment("tip-cycle"))}
    assert bt == {"ball_joint_friction", "latch_hysteresis", "pretension_loss", "off_axis_motion"}
    assert tc == {"ball_joint_friction", "latch_hysteresis", "pretension_loss"}
    with pytest.raises(ModelError, match=r"effect 'joint_clearance' does not apply to bay-torsion"):
        resolve(get_experiment("bay-torsion"), ["joint_clearance"])


def test_docs_describe_every_effect_and_experiment():
    text = (ROOT / "docs" / "experiments.md").read_text()
    for name in BUILT_IN:
        assert f"`{name}`" in text, name
    for x in list_experiments():
        assert f"`{x.name}`" in text, x.name
        for c in x.columns:
            assert f"`{c.name}`" in text, (x.name, c.name)


def test_register_a_user_effect_and_extend_an_existing_one():
    def shift(d, p, ctx):
        return d + p["a"]

    eff = Effect(
        name="test_offset",
        title="offset",
        physics="a constant offset of the top " * 4,
        signature="a constant",
        implementations={
            "mast-top": Implementation(
                hook="top_displacement", apply=shift, parameters=(Parameter("a", "m", 1e-4, -1.0, 1.0, "offset"),)
            )
        },
    )
    register_effect(eff, replace_existing=True)
    try:
        with pytest.raises(ModelError, match="already registered"):
            register_effect(Effect(name="test_offset", title="x", physics="y"))
        assert "test_offset" in {e.name for e in applicable_effects(get_experiment("mast-top"))}  # a candidate now
        data, _ = mast_top_data(path=mast_top_path(n=50, seed=1), noise_m=0.0)
        base = predict(get_experiment("mast-top"), data)
        moved = predict(get_experiment("mast-top"), data, effects={"test_offset": {"a": 1e-3}})
        np.testing.assert_allclose(moved["dx_m"] - base["dx_m"], 1e-3)  # default rtol 1e-7: an exact shift
        # make an effect apply to another (a user's) experiment
        add_implementation(
            "test_offset",
            "spring-x",
            Implementation(hook="h", apply=shift, parameters=eff.implementations["mast-top"].parameters),
        )
        assert get_effect("test_offset").applies_to("spring-x")
    finally:  # other tests' diagnoses must not see it
        unregister_effect("test_offset")
    assert "test_offset" not in {e.name for e in list_effects()}


def test_effects_do_not_change_the_model_at_their_neutral_values():
    exp = get_experiment("mast-top")
    data, _ = mast_top_data(path=mast_top_path(n=80, moment_Nm=100.0, seed=2), noise_m=0.0)
    base = predict(exp, data)
    neutral = {
        "joint_clearance": {"c": 0.0},
        "friction_hysteresis": {"M_f": 0.0},
        "progressive_stiffness": {"beta": 0.0},
        "cable_hysteresis": {"eta": 0.0},
        "pretension_loss": {"lam": 0.0},
        "beam_flexibility": {"E": 1e30},
    }
    for name, p in neutral.items():
        got = predict(exp, data, effects={name: p})
        # exactly neutral up to round-off (E = 1e30 Pa leaves a 1e-20 relative compliance)
        np.testing.assert_allclose(got["dx_m"], base["dx_m"], rtol=1e-12, atol=1e-15, err_msg=name)


def test_beam_flexibility_is_the_rocaspect_cantilever_in_series():
    from femast.guyed.cantilever import cantilever_compliance, mast_section

    exp = get_experiment("mast-top")
    data, _ = mast_top_data(path=mast_top_path(n=40, moment_Nm=200.0, seed=3), noise_m=0.0)
    got = predict(exp, data, effects={"beam_flexibility": {"E": 7e10}})
    base = predict(exp, data)
    C = cantilever_compliance(3.651, mast_section(7e10, 0.3, 0.1, 0.094))
    dw = np.column_stack([data[c] for c in ("fx_N", "fy_N", "fz_N", "mx_Nm", "my_Nm", "mz_Nm")])
    # the same compliance matrix, scaled by 1/E instead of built at E: round-off only
    np.testing.assert_allclose(got["dx_m"] - base["dx_m"], (dw @ C.T)[:, 0], rtol=1e-10, atol=1e-16)
