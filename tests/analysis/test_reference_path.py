"""A reference run's converged increments as the predictor of a nearby run:
femast/analysis/reference.py, the whole-increment predictor of newton.py, and its use by the FE
experiments (femast/experiments/fe_reference.py)."""

from __future__ import annotations

import numpy as np
import pytest

import femast as fm
from femast.analysis import Analysis
from femast.analysis.reference import ReferencePath

CONV = fm.Convergence(force_tol=1e-8, disp_tol=1e-9, max_iterations=40)


def _cantilever(E=70e9, drive="load", dt=0.1):
    """A 1 m tube cantilever bent to a large deflection: by a tip load (load control), by a prescribed
    tip deflection uz or by a prescribed tip rotation ry (the bending stays in the x-z plane), then
    under an axial compression of 1/6 of its Euler load (so that its shape depends on E)."""
    m = fm.Model("cantilever")
    a, b = m.node(0, 0, 0), m.node(1.0, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=E), up=(0, 0, 1), n=8)
    m.fix(a)
    st = m.step("bend", initial_increment=dt, max_increment=dt)
    if drive == "load":
        st.load(b, fz=-400.0, my=30.0)
    elif drive == "uz":
        st.prescribe(b, uz=-0.3).load(b, fx=-2000.0)
    else:
        st.prescribe(b, ry=0.6).load(b, fx=-2000.0)
    return m, b


def _run(model, reference=None, record=None):
    frames = []
    an = Analysis(
        model,
        None,
        progress=False,
        convergence=CONV,
        on_frame=frames.append,
        observers=[record] if record is not None else (),
    )
    an.reference = reference
    an.run()
    return an, frames


@pytest.mark.parametrize("drive", ["load", "uz", "ry"])
def test_a_nearby_run_started_from_the_reference_reaches_the_same_solution_in_fewer_iterations(drive):
    ref = ReferencePath()
    _run(_cantilever(drive=drive)[0], record=ref)
    assert len(ref) == 10  # one recorded increment per converged increment
    m, tip = _cantilever(E=70.07e9, drive=drive)  # 0.1 % stiffer: a finite-difference step of a fit
    plain, f0 = _run(m)
    m2, _ = _cantilever(E=70.07e9, drive=drive)
    fast, f1 = _run(m2, reference=ref)
    assert fast.summary.increments == plain.summary.increments
    assert fast.summary.iterations <= 0.7 * plain.summary.iterations
    i = m.index(tip)
    for a, b in zip(f0[1:], f1[1:]):  # every converged increment: same displacements and reactions
        u0, u1 = a["U"], b["U"]
        # both meet the 1e-9 displacement test from different starts; 1e-7 of the largest motion
        # leaves room for a few soft directions amplifying it
        np.testing.assert_allclose(u1, u0, rtol=0, atol=1e-7 * np.abs(u0).max())
        np.testing.assert_allclose(b["RF"], a["RF"], rtol=0, atol=1e-7 * np.abs(a["RF"]).max())
    assert np.abs(f0[-1]["U"][i]).max() > 0.1  # a large deflection, not a linear case


def test_a_reference_without_matching_increments_changes_nothing():
    """Increments whose (step, start, end) the reference did not make start as without it: a
    reference with other increment sizes gives the same run bit for bit."""
    ref = ReferencePath()
    _run(_cantilever(dt=0.25, drive="uz")[0], record=ref)
    plain, f0 = _run(_cantilever(drive="uz")[0])
    other, f1 = _run(_cantilever(drive="uz")[0], reference=ref)
    assert other.summary.iterations == plain.summary.iterations
    for a, b in zip(f0, f1):
        np.testing.assert_array_equal(a["U"], b["U"])


def test_a_reference_of_another_model_size_is_ignored():
    ref = ReferencePath()
    m = fm.Model("short")
    a, b = m.node(0, 0, 0), m.node(1.0, 0, 0)
    m.beam(a, b, fm.circular_tube(0.02, 0.016, E=70e9), up=(0, 0, 1), n=4)
    m.fix(a)
    m.step("bend", initial_increment=0.1, max_increment=0.1).load(b, fz=-400.0, my=30.0)
    _run(m, record=ref)
    plain, f0 = _run(_cantilever()[0])
    other, f1 = _run(_cantilever()[0], reference=ref)  # 4 elements recorded, 8 now: other DOFs
    assert other.summary.iterations == plain.summary.iterations
    np.testing.assert_array_equal(f0[-1]["U"], f1[-1]["U"])


def test_bay_runs_with_a_reference_are_cached_under_their_own_key_and_agree():
    """bay-torsion: a run with ``fe_reference`` is another cache entry than the same run without, its
    moment agrees within the path dependence of the prescribed rotation (docs/performance.md: 6e-5
    N m on the example; 1e-3 N m is 1/200 of the example's noise), and a changed drive path runs
    without the reference."""
    from femast import examples
    from femast.experiments import fe_cache, fe_reference, get_experiment, read_data
    from femast.rigs import bay_torsion as bt

    exp = get_experiment("bay-torsion")
    data = read_data(exp, examples.for_experiment("bay-torsion"))
    fe_cache.clear()
    fe_reference.clear()
    p0 = {"latch_k": 1.0e5, "latch_mu": 0.07}
    p1 = {"latch_k": 1.05e5, "latch_mu": 0.068}
    plain = bt.model(p1, data, None, exp.options)["Mz_Nm"]
    opts = {**exp.options, "fe_reference": p0}
    m0 = fe_cache.stats()["misses"]
    fast = bt.model(p1, data, None, opts)["Mz_Nm"]
    assert fe_cache.stats()["misses"] == m0 + 2  # the reference run (p0) and the run with it
    np.testing.assert_allclose(fast, plain, rtol=0, atol=1e-3)
    m1 = fe_cache.stats()["misses"]
    again = bt.model(p1, data, None, opts)["Mz_Nm"]
    assert fe_cache.stats()["misses"] == m1  # a cache hit, the same values
    np.testing.assert_array_equal(again, fast)
    ref0 = bt.model(p0, data, None, opts)["Mz_Nm"]  # the reference itself: its plain run, cached
    assert fe_cache.stats()["misses"] == m1
    np.testing.assert_array_equal(ref0, bt.model(p0, data, None, exp.options)["Mz_Nm"])


def test_a_lazy_frame_has_the_keys_and_values_of_a_written_frame_and_a_kept_one_is_completed(tmp_path):
    """Without a results folder the recorders get a LazyFrame (femast/analysis/output.py): the same
    keys and the same values as the frames written to disk; a recorder that keeps
    the frame gets it completed with the state of its own increment."""
    from femast.post.results import Results

    kept, read = [], []
    m, tip = _cantilever(drive="uz")
    Analysis(m, tmp_path / "r", progress=False, convergence=CONV).run()
    m2, _ = _cantilever(drive="uz")
    Analysis(m2, None, progress=False, convergence=CONV, on_frame=kept.append).run()
    m3, _ = _cantilever(drive="uz")
    Analysis(m3, None, progress=False, convergence=CONV, on_frame=lambda fr: read.append(fr["U"])).run()
    res = Results(tmp_path / "r")
    assert len(kept) == len(res) == len(read)
    for i, fr in enumerate(kept):
        disk = res.frame(i)
        assert set(fr) == set(disk)
        for k in ("U", "UR", "URA", "RF", "P"):
            np.testing.assert_array_equal(fr[k], disk[k])  # bit for bit: the same computation
        np.testing.assert_array_equal(read[i], disk["U"])
    assert "el/nope/x" not in kept[0] and "U" in kept[0]
