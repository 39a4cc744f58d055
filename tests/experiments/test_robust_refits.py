"""Robust refits: a femast error of the model at one parameter set skips that set (the fit goes on,
the count is reported); a candidate that cannot be fitted at all is shown as failed, never as a bar."""

import numpy as np
import two_axis_rig as rig

from femast.effects import Effect, Implementation, Parameter, register_effect, unregister_effect
from femast.errors import ConvergenceError, SingularModelError
from femast.experiments import diagnose, fit


def _register():
    def brittle(u, p, ctx):  # a mechanism whose (FE) model does not converge beyond some stiffening
        if p["beta"] > 2e-3:
            raise ConvergenceError("no equilibrium found in 12 cutbacks (a stand-in for an FE run that fails)")
        return u / (1.0 + p["beta"] * np.abs(ctx["load"]))

    def broken(u, p, ctx):
        raise SingularModelError("the tangent is singular at node 7 (a stand-in for a model that cannot run)")

    mech = dict(hook="displacement", needs=("load",))
    register_effect(
        Effect(
            name="test_brittle",
            title="stiffening whose model fails beyond a point",
            physics="stiffening with the load, computed by a model that does not converge beyond beta = 2e-3 1/N " * 2,
            signature="stiffer at high load",
            mechanism=Implementation(
                **mech,
                parameters=(Parameter("beta", "1/N", 5e-4, 0.0, 1e-2, "stiffening", scale=5e-4, starts=(5e-3,)),),
                apply=brittle,
            ),
        ),
        replace_existing=True,
    )
    register_effect(
        Effect(
            name="test_broken",
            title="a mechanism whose model never runs",
            physics="a mechanism whose model raises a singular-matrix error at every parameter set " * 2,
            signature="none",
            mechanism=Implementation(
                **mech, parameters=(Parameter("a", "-", 1.0, 0.0, 2.0, "anything"),), apply=broken
            ),
        ),
        replace_existing=True,
    )


def test_a_failing_parameter_set_is_skipped_and_counted():
    _register()
    try:
        data = rig.data(gap_x=0.0, n=300)
        sigma = {"ux_mm": 5e-3, "uy_mm": 5e-3}
        f = fit(rig.RIG, data, ["test_brittle"], start={"k_x": 2e6, "k_y": 3e6}, noise=sigma)  # starts at 5e-3 fail
        assert f.skipped > 0 and "parameter set(s) skipped" in f.message and "ConvergenceError" in f.message
        assert f.x[2] < 2e-3 and f.ratio < 1.3  # the fit went on, from the start that works
    finally:
        unregister_effect("test_brittle")
        unregister_effect("test_broken")


def test_a_candidate_that_cannot_be_fitted_is_failed_not_a_bar(tmp_path, monkeypatch):
    _register()
    drawn = []
    import matplotlib.axes

    real = matplotlib.axes.Axes.barh

    def spy(self, y, width, *a, **k):
        drawn.append(len(np.atleast_1d(width)))
        return real(self, y, width, *a, **k)

    monkeypatch.setattr(matplotlib.axes.Axes, "barh", spy)
    try:
        data = rig.data(gap_x=2e-4, n=300)
        d = diagnose(rig.RIG, data, ["joint_clearance", "test_broken", "test_brittle"], workers=1, out=tmp_path)
        failed = [e for e in d.ranking if e.get("failed")]
        assert [e["effect"] for e in failed] == ["test_broken"] and "SingularModelError" in failed[0]["reading"]
        assert d.ranking[-1]["effect"] == "test_broken"  # listed last, after every fitted one
        assert d.verdict["missing_effect"] == "joint_clearance"  # the rest of the diagnosis went on
        rep = {e["effect"]: e for e in d.report["ranking"]}
        assert rep["test_broken"]["failed"]
        # the figure: one bar per fitted model (baseline + 2 candidates + pairs), none for the failed one
        n_models = 1 + len(d.ranking) - 1 + min(3, len(d.pairs))
        assert drawn == [n_models]
    finally:
        unregister_effect("test_brittle")
        unregister_effect("test_broken")
