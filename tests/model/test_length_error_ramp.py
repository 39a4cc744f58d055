"""Length errors applied gradually over a step (step.ramp_length_errors) against the closed form of
two bars in series between fixed walls, one of them too long by dL: N = -EA dL / (2 L)."""

import numpy as np
import pytest

import femast as fm
from femast.analysis import Analysis
from femast.errors import ModelError

EA, L, DL = 1.0e6, 0.75, 1.0e-3  # N, m (each bar), m (the first bar's length error)
N_FULL = -EA * DL / (2 * L)  # N: both bars carry it (the misfit shared by two equal springs)


def _bars():
    m = fm.Model("two bars between walls")
    a, mid, b = m.node(0, 0, 0), m.node(L, 0, 0), m.node(2 * L, 0, 0)
    m.truss(a, mid, EA, length_error_m=DL)
    m.truss(mid, b, EA)
    m.fix(a)
    m.fix(b)
    m.fix(mid, "uy", "uz")
    return m


def _forces(m):
    frames = []
    Analysis(m, None, progress=False, on_frame=frames.append).run()
    return [(str(f["step"]), float(f["time"]), f["el/truss/N"].copy()) for f in frames[1:]]


def test_misfit_grows_linearly_over_the_ramp_step_and_stays_after_it():
    m = _bars()
    m.step("fit", initial_increment=0.25, max_increment=0.25).ramp_length_errors()
    m.step("after", initial_increment=0.5, max_increment=0.5)
    rows = _forces(m)
    assert [s for s, *_ in rows] == ["fit"] * 4 + ["after"] * 2
    for step, t, N in rows:
        share = t if step == "fit" else 1.0
        np.testing.assert_allclose(N, share * N_FULL, rtol=1e-9)


def test_no_misfit_before_the_ramp_step():
    m = _bars()
    m.step("before", initial_increment=0.5, max_increment=0.5)
    m.step("fit", initial_increment=0.5, max_increment=0.5).ramp_length_errors()
    rows = _forces(m)
    for step, t, N in rows:
        np.testing.assert_allclose(N, (0.0 if step == "before" else t) * N_FULL, rtol=1e-9, atol=1e-9)


def test_without_a_ramp_the_whole_misfit_acts_in_the_first_increment():
    m = _bars()
    m.step("load", initial_increment=0.5, max_increment=0.5)
    for _step, _t, N in _forces(m):
        np.testing.assert_allclose(N, N_FULL, rtol=1e-9)


def test_one_ramp_step_per_model_and_not_under_arc_length():
    from femast.analysis.control.arclength import ArcLength

    m = _bars()
    m.step("fit").ramp_length_errors()
    with pytest.raises(ModelError, match="already ramp over step 'fit'"):
        m.step("again").ramp_length_errors()
    m = _bars()
    m.step("s", control=ArcLength()).ramp_length_errors().load(2, fx=1.0)
    with pytest.raises(ModelError, match="follow step time"):
        Analysis(m, None, progress=False, on_frame=lambda f: None)
