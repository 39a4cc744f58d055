"""The effect contract: effects as mechanisms on physical quantities, usable on any rig that
declares them, mixed with a user's own effects, named and sized by the rig's quantities.

The data of the user rig below come from a law that shares no code or functional form with the
library's clearance (``c tanh(L / L_s)``): a gap closed by a linear contact spring, about one axis
only (``u = F / k + clip(F / k_c, -g, g)``).
"""

import numpy as np
import pytest
from two_axis_rig import RIG  # the user rig of docs/your_own_rig.md's kind, shared with the experiments tests

from femast.effects import Effect, Implementation, Parameter, Quantity, register_effect, resolve, unregister_effect
from femast.effects.base import forms_of
from femast.errors import ModelError
from femast.experiments import Column, Experiment, fit, from_arrays, get_experiment, predict


def _data(gap_x=2e-4, noise_mm=5e-3, n=400, seed=3):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 4.0, n)
    Fx = 800.0 * np.sin(2 * np.pi * t)
    Fy = 600.0 * np.sin(2 * np.pi * t + 1.0)
    kx, ky, kc = 2e6, 3e6, 1e5  # kc: a soft centring inside the gap, which it crosses within 20 N
    ux = Fx / kx + np.clip(Fx / kc, -gap_x, gap_x)  # the gap about x only, closed by a contact spring
    uy = Fy / ky
    return from_arrays(
        RIG,
        Fx_N=Fx,
        Fy_N=Fy,
        ux_mm=1e3 * ux + rng.normal(0, noise_mm, n),
        uy_mm=1e3 * uy + rng.normal(0, noise_mm, n),
    )


def test_library_effects_apply_to_a_user_rig_with_its_names_and_units():
    names = {n for n, _ in resolve(RIG, ["joint_clearance", "friction_hysteresis", "progressive_stiffness"])}
    assert names == {"joint_clearance", "friction_hysteresis", "progressive_stiffness"}
    ((_, clear),) = resolve(RIG, ["joint_clearance/per_axis"])
    assert [(p.name, p.unit) for p in clear.parameters] == [("c_x", "m"), ("c_y", "m")]
    assert clear.parameters[0].default == pytest.approx(1e-4)  # sized by the displacement's scale
    ((_, fric),) = resolve(RIG, ["friction_hysteresis"])
    assert [(p.name, p.unit) for p in fric.parameters] == [("F_f", "N")]  # a force: F_f, not M_f
    ((_, prog),) = resolve(RIG, ["progressive_stiffness"])
    assert prog.parameters[0].unit == "1/N"
    mt = get_experiment("mast-top")
    ((_, fric_mt),) = resolve(mt, ["friction_hysteresis"])
    assert [(p.name, p.unit) for p in fric_mt.parameters] == [("M_f", "N m")]
    assert "joint_clearance/per_axis" in forms_of("joint_clearance", RIG)


def test_a_per_axis_gap_is_found_on_its_axis_only():
    data = _data()
    start = {"k_x": 2e6, "k_y": 3e6}
    one = fit(RIG, data, ["joint_clearance"], start=start)
    per = fit(RIG, data, ["joint_clearance/per_axis"], start=start)
    c = dict(zip(per.names, per.x))
    # the gap is crossed within g k_c = 20 N of 800 N: the fitted half play is the gap
    assert c["joint_clearance/per_axis.c_x"] == pytest.approx(2e-4, rel=0.05)
    assert abs(c["joint_clearance/per_axis.c_y"]) < 1e-5  # no gap about y
    # one gap for both axes damages y (the rest of the per-axis misfit: a ramp across the gap, not a tanh)
    assert per.channel_rms["uy_mm"] < 1.1 * per.noise["uy_mm"] < 0.5 * one.channel_rms["uy_mm"]
    assert per.ratio < 0.5 * one.ratio


def test_user_mechanism_applies_to_every_rig_with_its_quantities_and_mixes_with_library_effects():
    def creep(u, p, ctx):
        return u + p["v"] * ctx["time"][:, None] * np.sign(ctx["load"])

    register_effect(
        Effect(
            name="test_creep",
            title="creep under load",
            physics="the connection creeps in the direction of the load, in proportion to time " * 2,
            signature="an error growing with time",
            mechanism=Implementation(
                hook="displacement",
                needs=("load", "time"),
                parameters=lambda q: (Parameter("v", q["displacement"].unit, 0.0, -1.0, 1.0, "creep over the test"),),
                apply=creep,
            ),
        ),
        replace_existing=True,
    )
    try:
        data = _data(gap_x=0.0, n=100)
        base = {"k_x": 2e6, "k_y": 3e6}
        a = predict(RIG, data, base, {"test_creep": {"v": 1e-5}, "joint_clearance": {"c": 0.0}})
        b = predict(RIG, data, base)
        sign = np.sign(np.column_stack([data["Fx_N"], data["Fy_N"]]))
        np.testing.assert_allclose(a["ux_mm"] - b["ux_mm"], 1e-2 * data.tau * sign[:, 0], atol=1e-15)
        ((_, impl),) = resolve(get_experiment("mast-top"), ["test_creep"])  # a built-in rig has the quantities
        assert impl.parameters[0].unit == "rad"
    finally:
        unregister_effect("test_creep")


def test_an_effect_needing_a_quantity_the_rig_lacks_says_so():
    bare = Experiment(
        name="no-quantities",
        title="t",
        columns=(Column("F_N", "N"), Column("u_m", "m")),
        channels=("u_m",),
        model=lambda p, d, e, o: {"u_m": d["F_N"]},
    )
    with pytest.raises(ModelError, match="needs an experiment declaring the quantities displacement and load"):
        resolve(bare, ["joint_clearance"])


def test_quantities_are_checked():
    with pytest.raises(ModelError, match="unknown quantity 'force'"):
        Experiment(name="x", title="x", columns=(Column("a", "-"),), channels=("a",), quantities={"force": None})
    with pytest.raises(ModelError, match="needs the data column"):
        Experiment(
            name="x", title="x", columns=(Column("a", "-"),), channels=("a",), quantities={"temperature": Quantity("C")}
        )
    with pytest.raises(ModelError, match="same axes"):
        Experiment(
            name="x",
            title="x",
            columns=(Column("a", "-"),),
            channels=("a",),
            quantities={"load": Quantity("N", axes=("x",)), "displacement": Quantity("m", axes=("x", "y"))},
        )
    with pytest.raises(ModelError, match="scale must be"):
        Quantity("N", scale=0.0)
