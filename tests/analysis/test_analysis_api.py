"""The analysis' public pieces: the architecture tour's examples run, the state saves and loads bit
for bit, commit/rollback restore exactly, the Newton variants reach the same solution, observers
hear every converged increment."""

import numpy as np
import pytest
from doc_examples import run_python_blocks

import femast as fm
from femast.analysis import Analysis, Observer, State


def test_architecture_page_examples_run(tmp_path, capsys):
    # the "add a control strategy" example asserts against linear theory and the built-in control
    run_python_blocks("architecture.md", cwd=tmp_path)
    out = capsys.readouterr().out
    assert "tip deflection" in out and "saved state" in out


def _frame(n=6, load=-200.0, steps=1):
    m = fm.Model("frame")
    a, b, c = m.node(0, 0, 0), m.node(0, 0, 1), m.node(1, 0, 1)
    sec = fm.circular_tube(0.02, 0.016, E=70e9)
    m.beam(a, b, sec, n=n, up=(1, 0, 0))
    m.beam(b, c, sec, n=n)
    m.fix(a)
    for k in range(steps):
        m.step(f"s{k}").load(c, fz=load * (k + 1), fx=0.3 * load)
    return m, c


def test_state_saves_and_loads_bit_for_bit(tmp_path):
    m, _ = _frame(steps=2)
    an = Analysis(m, None, progress=False, on_frame=lambda fr: None)
    an.run()
    st = an.state
    p = tmp_path / "s.npz"
    st.save(p)
    back = State.load(p)
    assert back.equal(st)
    for name in ("x", "R", "spin", "loads", "prescribed", "reactions", "last_increment"):
        a, b = getattr(st, name), getattr(back, name)
        assert a.tobytes() == b.tobytes() and a.dtype == b.dtype and a.shape == b.shape, name
    assert (back.lam, back.total_time, back.step, back.increment) == (st.lam, st.total_time, 1, st.increment)
    assert back.size == st.size and type(back.at_equilibrium) is bool
    assert [f.tobytes() for f in back.families] == [f.tobytes() for f in st.families]
    # a changed bit is seen
    back.x[0, 0] = np.nextafter(back.x[0, 0], 1.0)
    assert not back.equal(st)


def test_a_loaded_state_replaces_the_analysis_state_and_its_cached_responses(tmp_path):
    m, c = _frame(steps=2)
    an = Analysis(m, None, progress=False, on_frame=lambda fr: None)
    an.run()
    p = tmp_path / "s.npz"
    an.state.save(p)
    other = Analysis(m, None, progress=False, on_frame=lambda fr: None)  # at the initial state
    other.system.last_converged = an.system.last_converged  # a stale cache...
    other.state = State.load(p)  # ...is dropped
    assert other.system.state is other.state and other.system.last_converged is None
    np.testing.assert_array_equal(other.x, an.x)
    # the same tangent from the loaded state as from the analysis that produced it
    np.testing.assert_array_equal(other.tangent().toarray(), an.tangent().toarray())


def test_state_load_rejects_a_foreign_file(tmp_path):
    p = tmp_path / "other.npz"
    np.savez(p, x=np.zeros(3))
    with pytest.raises(fm.FemastError, match="not a femast state file"):
        State.load(p)


def test_rollback_restores_the_checkpoint_exactly():
    m, _ = _frame()
    an = Analysis(m, None, progress=False, on_frame=lambda fr: None)
    an.run()
    st = an.state
    x, R, spin, lam, version = st.x.copy(), st.R.copy(), st.spin.copy(), st.lam, st.version
    st.checkpoint()
    an.system.update(np.random.default_rng(0).normal(size=an.dofmap.n_free) * 1e-2)
    st.lam = 7.0
    assert not np.array_equal(st.x, x)
    st.rollback()
    assert np.array_equal(st.x, x) and np.array_equal(st.R, R) and np.array_equal(st.spin, spin)
    assert (st.lam, st.version) == (lam, version)


def _two_bar_truss(load):
    m = fm.Model("two bars")
    a, top, b = m.node(0, 0, 0), m.node(1, 0, 1), m.node(2, 0, 0)
    m.truss(a, top, EA=1e7)
    m.truss(top, b, EA=1e7)
    m.fix(a, "translations")
    m.fix(b, "translations")
    m.fix(top, "uy")
    m.step("load").load(top, fz=load, fx=0.2 * load)
    return m, top


@pytest.mark.parametrize("tangent", ["modified", "initial"])
def test_modified_and_initial_stiffness_newton_reach_the_full_newton_solution(tangent):
    # strain ~1e-3: mildly nonlinear, so the constant tangent contracts the error by ~1e-2 per iteration
    conv = fm.Convergence(force_tol=1e-10, disp_tol=1e-10, max_iterations=60)
    tips = {}
    for t in ("full", tangent):
        m, top = _two_bar_truss(-2e4)
        an = Analysis(m, None, progress=False, on_frame=lambda fr: None, tangent=t, convergence=conv)
        an.run()
        tips[t] = (an.x[m.index(top)] - an.X0[m.index(top)], an.summary.iterations)
    (full, n_full), (other, n_other) = tips["full"], tips[tangent]
    # both within the displacement tolerance (1e-10 of the increment) of the same equilibrium
    np.testing.assert_allclose(other, full, rtol=0, atol=1e-9 * np.abs(full).max())
    assert n_other > n_full  # linear instead of quadratic convergence: more iterations


def test_unknown_tangent_option_is_a_clear_error():
    m, _ = _frame()
    with pytest.raises(fm.ModelError, match="tangent='secant'"):
        Analysis(m, None, progress=False, on_frame=lambda fr: None, tangent="secant")


def test_observers_hear_every_converged_increment_and_the_end(tmp_path):
    class Count(Observer):
        def __init__(self):
            self.events = []

        def started(self, analysis):
            self.events.append("start")

        def converged(self, analysis, step, increment, attempt, iterations, time, dtime, last, responses, note):
            self.events.append((step.name, increment, last))

        def finished(self, analysis):
            self.events.append("end")

    m, _ = _frame(steps=2)
    obs = Count()
    frames = []
    res = Analysis(m, tmp_path / "r", progress=False, observers=[obs], on_frame=frames.append).run()
    conv = [e for e in obs.events if isinstance(e, tuple)]
    assert obs.events[0] == "start" and obs.events[-1] == "end"
    assert len(conv) == res.summary["increments"] and len(frames) == len(res) == len(conv) + 1
    assert [e[2] for e in conv if e[0] == "s0"][-1] and [e[2] for e in conv if e[0] == "s1"][-1]
