"""Frames by step: ``Results.frame(step=, index=)`` and ``Results.frame_number`` against the
frames' own step names and increment numbers, and the errors for a step or index that is not there."""

import numpy as np
import pytest

import femast as fm


@pytest.fixture(scope="module")
def two_steps(tmp_path_factory):
    m = fm.Model("lu")
    a, b = m.node(0, 0, 0), m.node(1, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), n=4)
    m.fix(a)
    m.step("load", initial_increment=0.25).load(b, fz=-50.0)
    m.step("unload", initial_increment=0.5).load(b, fz=0.0)
    return fm.Analysis(m, tmp_path_factory.mktemp("r") / "lu", progress=False).run(), b


def test_last_and_first_frame_of_a_step(two_steps):
    res, tip = two_steps
    steps = res.steps  # ["initial", 4 x "load", 2 x "unload"]
    assert steps == ["initial"] + ["load"] * 4 + ["unload"] * 2
    assert res.frame_number("load") == 4 and res.frame_number("load", 0) == 1
    assert res.frame_number("unload") == 6 and res.frame_number("unload", -2) == 5
    last_load = res.frame(step="load")
    assert str(last_load["step"]) == "load" and int(last_load["increment"]) == 4
    assert float(last_load["time"]) == pytest.approx(1.0)  # the end of the step
    assert int(res.frame(step="unload", index=0)["increment"]) == 1
    # the end of the load step: the full tip load, fz = -50 N applied
    assert res.node_history(tip, "fz")[res.frame_number("load")] == pytest.approx(-50.0)
    np.testing.assert_array_equal(res.frame(step="load")["U"], res.frame(4)["U"])


def test_missing_steps_and_indices_are_named(two_steps):
    res, _ = two_steps
    with pytest.raises(
        fm.FemastError, match=r"no frame of step 'lod' \(did you mean 'load'\?\); its steps: load, unload"
    ):
        res.frame(step="lod")
    with pytest.raises(fm.FemastError, match=r"step 'unload' has 2 frames; index 5"):
        res.frame(step="unload", index=5)
    with pytest.raises(fm.FemastError, match="not both"):
        res.frame(3, step="load")
    with pytest.raises(fm.FemastError, match="give a frame number"):
        res.frame()
