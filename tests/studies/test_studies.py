"""femast.studies: distributions, sampling, the Sobol' estimators against closed forms,
percentile intervals' coverage, the store (resume, failures), runners (serial, local processes),
femast model outputs against the cantilever closed form, and bad input before any sample runs."""

from pathlib import Path

import numpy as np
import pytest
from scipy import special, stats

import femast as fm
import femast.studies as st
from femast.errors import ConvergenceError, StudyError
from femast.studies.sampling import Design


# ------------------------------------------------------------------ model functions (plain formulas)
def ishigami(x1, x2, x3, a=7.0, b=0.1):
    return {"y": np.sin(x1) + a * np.sin(x2) ** 2 + b * x3**4 * np.sin(x1)}


# Ishigami indices, closed form (Sobol' & Levitan 1999; Saltelli et al. 2008, Sec. 4.4), a = 7, b = 0.1
_A, _B = 7.0, 0.1
_V1 = 0.5 * (1 + _B * np.pi**4 / 5) ** 2
_V2 = _A**2 / 8
_V13 = _B**2 * np.pi**8 * (1 / 18 - 1 / 50)
_V = _V1 + _V2 + _V13
ISHIGAMI_S1 = np.array([_V1, _V2, 0.0]) / _V
ISHIGAMI_ST = np.array([_V1 + _V13, _V2, _V13]) / _V


def _uniform_pi(names=("x1", "x2", "x3")):
    return [st.Uniform(n, -np.pi, np.pi) for n in names]


def test_ishigami_closed_form_indices():
    # the reference values themselves (published: S1 = 0.3139, 0.4424, 0; ST = 0.5576, 0.4424, 0.2437)
    assert np.allclose(ISHIGAMI_S1, [0.3139, 0.4424, 0.0], atol=5e-5)
    assert np.allclose(ISHIGAMI_ST, [0.5576, 0.4424, 0.2437], atol=5e-5)


def test_jansen_estimators_converge_to_ishigami_indices():
    # the design's own Saltelli layout, evaluated vectorised: 2^15 scrambled Sobol' base samples
    d = Design(_uniform_pi(), sampler="sobol", seed=3, sensitivity=True)
    n = 2**15
    runs = np.arange(n * d.runs_per_sample)
    base, block, u = d.points(runs, n)
    v = d.values(u)
    y = ishigami(**v)["y"].reshape(n, d.runs_per_sample)
    s = st.sobol_indices(y[:, 0], y[:, 1], y[:, 2:].T, names=["x1", "x2", "x3"], resamples=50)
    # Saltelli 2010 S1 / Jansen ST errors at n = 2^15 QMC samples are ~1e-3 (Saltelli et al. 2010, Fig. 2)
    assert np.max(np.abs(s["S1"] - ISHIGAMI_S1)) < 0.01
    assert np.max(np.abs(s["ST"] - ISHIGAMI_ST)) < 0.01


def test_linear_model_indices_and_intervals():
    # Y = sum c_i X_i, X_i ~ N(0, s_i) independent: S1_i = ST_i = c_i^2 s_i^2 / sum (closed form)
    c, s_ = np.array([1.0, 2.0, 0.5]), np.array([1.0, 0.5, 2.0])
    d = Design([st.Normal(f"x{i}", 0.0, s_[i]) for i in range(3)], sampler="mc", seed=5, sensitivity=True)
    n = 4096
    _, _, u = d.points(np.arange(n * 5), n)
    v = d.values(u)
    y = (c[0] * v["x0"] + c[1] * v["x1"] + c[2] * v["x2"]).reshape(n, 5)
    res = st.sobol_indices(y[:, 0], y[:, 1], y[:, 2:].T, resamples=400)
    exact = c**2 * s_**2 / np.sum(c**2 * s_**2)
    for k in ("S1", "ST"):
        se = (res[k + "_high"] - res[k + "_low"]) / (2 * 1.96)  # bootstrap standard error
        assert np.all(se < 0.05)  # ~1/sqrt(n) scale, not an inflated interval
        # the error within 4 bootstrap standard errors (a false alarm: ~1e-4 per index)
        assert np.all(np.abs(res[k] - exact) < 4 * se), (k, res[k], exact, se)


def test_order_statistic_interval_coverage():
    # 1500 repetitions of n = 60 normal samples: the 90 % percentile's interval covers the true
    # quantile at least at its stated (exact binomial) coverage, within 3 binomial sigmas
    rng = np.random.default_rng(11)
    n, q, reps = 60, 0.9, 1500
    xi = stats.norm.ppf(q)
    hits, cover = 0, None
    for _ in range(reps):
        p = st.percentile(rng.standard_normal(n), q)
        hits += p["low"] <= xi <= p["high"]
        cover = p["coverage"]
    assert cover >= 0.95
    sigma = np.sqrt(cover * (1 - cover) / reps)
    assert hits / reps > cover - 3 * sigma


def test_percentile_interval_matches_binomial_ranks():
    # n = 100, q = 0.5, 95 %: the classical ranks of the median interval are 40 and 61 (Conover Table A3)
    from femast.studies.statistics import order_statistic_ranks

    assert order_statistic_ranks(100, 0.5, 0.95) == (40, 61)


def test_distributions_and_copula():
    n = 2**14
    ins = [
        st.Normal("a", 2.0, 0.5),
        st.Uniform("b", -1.0, 3.0),
        st.TruncatedNormal("c", 0.0, 1.0, low=-0.5, high=2.0),
        st.LogNormal("d", 3.0, 0.2),
        st.Normal("e", 0.0, 1.0, size=4),
    ]
    d = Design(ins, sampler="sobol", seed=2, correlation={("a", "d"): 0.6})
    _, _, u = d.points(np.arange(n), n)
    v = d.values(u)
    assert v["e"].shape == (n, 4)
    # marginals: KS distance to the exact cdf (QMC: far below the 1/sqrt(n) ~ 0.008 of random samples)
    assert stats.kstest(v["a"], stats.norm(2.0, 0.5).cdf).statistic < 3e-3
    assert stats.kstest(v["b"], stats.uniform(-1.0, 4.0).cdf).statistic < 3e-3
    assert stats.kstest(v["c"], stats.truncnorm(-0.5, 2.0).cdf).statistic < 3e-3
    assert v["c"].min() >= -0.5 and v["c"].max() <= 2.0
    assert stats.kstest(v["d"], stats.lognorm(0.2, scale=3.0).cdf).statistic < 3e-3
    # copula: normal scores of a and d correlated 0.6 (sampling error ~ (1 - rho^2)/sqrt(n) = 0.005)
    za, zd = (v["a"] - 2.0) / 0.5, np.log(v["d"] / 3.0) / 0.2
    assert abs(np.corrcoef(za, zd)[0, 1] - 0.6) < 0.02
    assert abs(np.corrcoef(v["a"], v["b"])[0, 1]) < 0.02


def test_points_do_not_depend_on_chunking():
    for sampler in ("sobol", "mc", "lhs"):
        d = Design(_uniform_pi(), sampler=sampler, seed=4, sensitivity=True)
        n = 50
        runs = np.arange(n * 5)
        _, _, whole = d.points(runs, n)
        parts = np.vstack([d.points(runs[i : i + 7], n)[2] for i in range(0, len(runs), 7)])
        assert np.array_equal(whole, parts), sampler
        # AB^g rows: A's columns except g's, which come from B
        u = whole.reshape(n, 5, 3)
        assert np.array_equal(u[:, 2, 1:], u[:, 0, 1:]) and np.array_equal(u[:, 2, 0], u[:, 1, 0])


# ------------------------------------------------------------------ running, storing, resuming
def _ishigami_study(**kw):
    return st.Study(run=ishigami, inputs=_uniform_pi(), outputs=["y"], **kw)


def test_run_store_and_indices_through_the_runner(tmp_path):
    study = _ishigami_study(sensitivity=True)
    s = st.run(study, tmp_path / "s", samples=64)
    assert s.complete and s.ok == 64 * 5 and s.failed == 0
    res = st.load(tmp_path / "s")
    fA, fB, fAB, dropped = res.saltelli("y")
    # stored outputs are the function of the stored inputs
    x = {n: res.inputs(n) for n in ("x1", "x2", "x3")}
    assert np.allclose(res.output("y"), ishigami(**x)["y"], rtol=0, atol=1e-12)  # float64 round trip
    assert dropped == 0 and fAB.shape == (3, 64)


def _flaky(x, level):
    if x > level:
        raise ConvergenceError(f"no convergence at x = {x:.3f}")
    return {"y": x, "z": np.array([x, 2 * x])}


def test_failures_recorded_with_their_reason(tmp_path):
    study = st.Study(
        run=lambda x: _flaky(x, 0.7), inputs=[st.Uniform("x", 0.0, 1.0)], outputs=["y", "z"], sampler="mc", seed=9
    )
    s = st.run(study, tmp_path / "f", samples=200, chunk_size=16)
    res = st.load(tmp_path / "f")
    t = res.table(["x", "status", "error"])
    expected = int(np.sum(t["x"] > 0.7))
    assert expected > 0 and s.failed == expected and res.counts()["failed"] == expected
    fails = res.failures()
    assert len(fails) == expected and all("ConvergenceError: no convergence at x" in r for _, r in fails)
    assert len(res.output("y")) == 200 - expected and res.output("z").shape == (200 - expected, 2)
    assert "FAILED" in str(s) and "complete" in str(s)


def test_interrupt_then_resume_equals_one_run(tmp_path):
    one = st.run(_ishigami_study(sensitivity=True, sampler="mc"), tmp_path / "one", samples=40, chunk_size=9)
    part = st.run(_ishigami_study(sensitivity=True, sampler="mc"), tmp_path / "two", samples=40, chunk_size=9, limit=57)
    assert not part.complete and part.ran == 57 and "resume" in str(part)
    rest = st.run(_ishigami_study(sensitivity=True, sampler="mc"), tmp_path / "two", samples=40, chunk_size=5)
    assert rest.complete and rest.resumed == 57 and rest.ran == 200 - 57 and one.complete
    a = st.load(tmp_path / "one").table(["x1", "x2", "x3", "y", "block"])
    b = st.load(tmp_path / "two").table(["x1", "x2", "x3", "y", "block"])
    for k in a:
        assert np.array_equal(a[k], b[k]), k


def test_local_processes_give_the_serial_results(tmp_path):
    a = st.run(_ishigami_study(), tmp_path / "a", samples=64)
    b = st.run(_ishigami_study(), tmp_path / "b", samples=64, workers=2)
    assert a.complete and b.complete and b.engine == "local"
    ta, tb = st.load(tmp_path / "a").table(["y"]), st.load(tmp_path / "b").table(["y"])
    assert np.array_equal(ta["y"], tb["y"]) and len(set(st.load(tmp_path / "b").table(["worker"])["worker"])) >= 1


# ------------------------------------------------------------------ femast models
L_M, D_M, T_M = 1.0, 0.02, 0.002


def cantilever(E, F):
    m = fm.Model("cantilever")
    a, b = m.node(0, 0, 0), m.node(L_M, 0, 0)
    m.beam(a, b, fm.circular_tube(D_M, D_M - 2 * T_M, E=E), n=4)
    m.fix(a)
    m.step("load").load(b, fz=-F)
    m.step("unload").load(b, fz=0.0)
    return m


def _cantilever_study(outputs=None, **kw):
    outs = (
        outputs
        if outputs is not None
        else [
            st.NodeOutput("tip_w", node=2, quantity="U", components="z"),
            st.NodeOutput("tip_rot", node=2, quantity="URA", components="y", at="load", relative_to="initial"),
        ]
    )
    return st.Study(model=cantilever, inputs=[st.Normal("E", 70e9, 5e9), st.Uniform("F", 0.5, 1.5)], outputs=outs, **kw)


def test_model_outputs_match_the_cantilever_closed_form(tmp_path):
    s = st.run(_cantilever_study(sampler="lhs"), tmp_path / "c", samples=6)
    assert s.complete and s.failed == 0
    res = st.load(tmp_path / "c")
    E, F = res.inputs("E"), res.inputs("F")
    I = np.pi / 64 * (D_M**4 - (D_M - 2 * T_M) ** 4)
    w, rot = res.output("tip_w"), res.output("tip_rot")
    assert w.shape == (6, 2)  # (steps load, unload) of the z component
    # Euler-Bernoulli tip deflection F L^3 / 3EI and rotation F L^2 / 2EI; the rest is the
    # geometric nonlinearity, O((w/L)^2) ~ 1e-6 relative at these loads, and shear (d/L)^2 ~ 4e-4
    assert np.allclose(-w[:, 0], F * L_M**3 / (3 * E * I), rtol=2e-3)
    assert np.allclose(rot, F * L_M**2 / (2 * E * I), rtol=2e-3)
    # unloaded: back to zero (elastic), to the correction tolerance (disp_tol 1e-6 of the unload
    # increment, the loaded deflection: an increment may be accepted on its predicted
    # next correction, ~1e-7 of it here, without the extra iteration that went to round-off)
    assert np.all(np.abs(w[:, 1]) <= 1e-6 * np.abs(w[:, 0]))


# ------------------------------------------------------------------ bad input, before any sample
@pytest.mark.parametrize(
    "make, words",
    [
        (lambda: st.Normal("a", 0.0, -1.0), ["'a'", "std", "> 0"]),
        (lambda: st.Uniform("b", 2.0, 1.0), ["'b'", "low", "below high"]),
        (lambda: st.TruncatedNormal("c", 0.0, 1.0, low=10.0, high=11.0), ["'c'", "no probability"]),
        (lambda: st.TruncatedNormal("c", 0.0, 1.0, low=1.0, high=0.0), ["'c'", "below high"]),
        (lambda: st.LogNormal("d", -1.0, 0.1), ["'d'", "median", "> 0"]),
        (lambda: st.Normal("e", float("nan"), 1.0), ["'e'", "mean", "not finite"]),
        (lambda: st.Normal("f", 0.0, 1.0, size=0), ["'f'", "size"]),
        (
            lambda: Design(
                [st.Normal("a", 0, 1), st.Normal("b", 0, 1), st.Normal("c", 0, 1)],
                correlation={("a", "b"): 0.9, ("b", "c"): 0.9, ("a", "c"): -0.9},
            ),
            ["not positive definite"],
        ),
        (lambda: Design([st.Normal("a", 0, 1)], correlation={("a", "zz"): 0.5}), ["'zz'", "not an input"]),
        (
            lambda: Design(
                [st.Normal("a", 0, 1), st.Normal("b", 0, 1)], correlation={("a", "b"): 0.5}, sensitivity=True
            ),
            ["independent"],
        ),
    ],
)
def test_impossible_distributions_are_refused(make, words):
    with pytest.raises(StudyError) as e:
        make()
    for w in words:
        assert w in str(e.value)


def _never_runs(tmp_path, study, **kw):
    with pytest.raises(StudyError) as e:
        st.run(study, tmp_path / "bad", samples=4, **kw)
    assert not list((tmp_path / "bad").glob("chunks/*.parquet"))  # no sample ran
    return str(e.value)


def test_input_matching_nothing_in_the_model(tmp_path):
    study = st.Study(
        model=cantilever,
        inputs=[st.Normal("E", 70e9, 5e9), st.Uniform("F", 0.5, 1.5), st.Uniform("Fx", 0.0, 1.0)],
        outputs=[st.NodeOutput("w", node=2)],
    )
    msg = _never_runs(tmp_path, study)
    assert "'Fx' matches nothing" in msg and "cantilever()" in msg and "E, F" in msg
    study = st.Study(model=cantilever, inputs=[st.Normal("E", 70e9, 5e9)], outputs=[st.NodeOutput("w", node=2)])
    assert "needs 'F'" in _never_runs(tmp_path, study)


@pytest.mark.parametrize(
    "out, words",
    [
        (st.NodeOutput("w", node=99), ["'w'", "unknown node 99"]),
        (st.NodeOutput("w", node=2, at="pull"), ["'w'", "no step 'pull'", "'load'"]),
        (st.NodeOutput("w", node=2, relative_to="pre"), ["no step 'pre'"]),
        (st.ElementOutput("n", family="cables", key="N"), ["'n'", "no element family 'cables'", "'beam'"]),
        (st.ElementOutput("n", family="beam", key="axial_force"), ["'n'", "no output 'axial_force'"]),
        (
            st.ElementOutput("n", family="beam", key="section_forces", component=(0, 6)),
            ["'n'", "component (0, 6)", "outside"],
        ),
    ],
)
def test_output_that_does_not_exist(tmp_path, out, words):
    msg = _never_runs(tmp_path, _cantilever_study(outputs=[out]))
    for w in words:
        assert w in msg


def test_node_output_bad_quantity_or_component():
    with pytest.raises(StudyError, match="quantity 'V'"):
        st.NodeOutput("w", node=2, quantity="V")
    with pytest.raises(StudyError, match="component 'w' of U"):
        st.NodeOutput("w", node=2, components="w")


def test_unreachable_scheduler(tmp_path):
    pytest.importorskip("distributed")
    msg = _never_runs(tmp_path, _ishigami_study(), scheduler="tcp://127.0.0.1:9", connect_timeout=2)
    assert "cannot reach the dask scheduler at 'tcp://127.0.0.1:9'" in msg and "drop --scheduler" in msg


def test_run_function_missing_output(tmp_path):
    # missing at the nominal point (the warm-up): refused before any sample runs
    study = st.Study(run=lambda x: {"y": x}, inputs=[st.Uniform("x", 0, 1)], outputs=["y", "q"])
    msg = _never_runs(tmp_path, study)
    assert "nominal sample" in msg and "output(s) q not returned" in msg
    # missing in some samples only: those samples fail, with the reason
    study = st.Study(
        run=lambda x: {"y": x, **({"q": 1.0} if x < 0.8 else {})},
        inputs=[st.Uniform("x", 0, 1)],
        outputs=["y", "q"],
        sampler="mc",
    )
    s = st.run(study, tmp_path / "m", samples=50)
    res = st.load(tmp_path / "m")
    n_bad = int(np.sum(res.table(["x"])["x"] >= 0.8))
    assert n_bad > 0 and s.failed == n_bad and all("output(s) q not returned" in r for _, r in res.failures())


def test_other_study_in_the_folder_is_refused(tmp_path):
    st.run(_ishigami_study(), tmp_path / "s", samples=4)
    with pytest.raises(StudyError, match="holds another study"):
        st.run(_ishigami_study(seed=2), tmp_path / "s", samples=4)


# ------------------------------------------------------------------ dask and the command line
def _dask_same_as_serial(tmp_path, processes):
    distributed = pytest.importorskip("distributed")
    st.run(_ishigami_study(sensitivity=True), tmp_path / "a", samples=16)
    with (
        distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=processes, dashboard_address=None) as cl,
        distributed.Client(cl) as client,
    ):
        b = st.run(_ishigami_study(sensitivity=True), tmp_path / "b", samples=16, scheduler=client)
        c = st.run(
            _ishigami_study(sensitivity=True), tmp_path / "c", samples=16, scheduler=cl.scheduler_address, limit=30
        )
    assert b.engine == "dask" and b.complete and b.workers == 2 and c.ran == 30
    ta = st.load(tmp_path / "a").table(["y", "x1", "block"])
    tb = st.load(tmp_path / "b").table(["y", "x1", "block"])
    tc = st.load(tmp_path / "c").table(["y", "x1", "block"])
    for k in ta:
        assert np.array_equal(ta[k], tb[k]), k
        assert np.array_equal(ta[k][:30], tc[k]), k


def test_dask_local_cluster_gives_the_serial_results(tmp_path):
    # in-process workers (threads): the scheduler, scatter, submit and the pickled study; fast
    _dask_same_as_serial(tmp_path, processes=False)


@pytest.mark.slow
def test_dask_worker_processes_give_the_serial_results(tmp_path):
    # worker processes (the nanny spawns them: ~20 s on the shared 2-core machine)
    _dask_same_as_serial(tmp_path, processes=True)


STUDY_SCRIPT = """
import numpy as np
import femast.studies as st

def ishigami(x1, x2, x3):
    return {"y": np.sin(x1) + 7 * np.sin(x2) ** 2 + 0.1 * x3 ** 4 * np.sin(x1)}

study = st.Study(run=ishigami, inputs=[st.Uniform(n, -np.pi, np.pi) for n in ("x1", "x2", "x3")],
                 outputs=["y"], sensitivity=True, name="ishigami")
if __name__ == "__main__":
    raise SystemExit("the study command must not run the main block")
"""


def test_cli_study_runs_reports_and_resumes(tmp_path, capsys):
    from femast.cli import main

    script = tmp_path / "ishigami_study.py"
    script.write_text(STUDY_SCRIPT)
    out = tmp_path / "res"
    assert main(["--quiet", "study", str(script), "--samples", "32", "--workers", "1", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "study complete: 32 samples, 160 runs" in text and "0 failed" in text
    assert "sensitivity of y" in text and "percentiles" in text
    for f in ("distributions.png", "convergence.png", "sensitivity.png"):
        assert (out / "figures" / f).stat().st_size > 1000
    assert main(["--quiet", "study", str(script), "--samples", "32", "--out", str(out), "--no-report"]) == 0
    assert "160 already on disk" in capsys.readouterr().out


FAILING_SCRIPT = """
import femast.studies as st

def half_fail(x):
    if x > 0.5:
        raise RuntimeError(f"no convergence at x = {x:.3f}")
    return {"y": x}

study = st.Study(run=half_fail, inputs=[st.Uniform("x", 0.0, 1.0)], outputs=["y"], name="half")
"""


def test_cli_study_exits_3_when_runs_failed_also_after_a_resume(tmp_path, capsys):
    from femast.cli import main

    script = tmp_path / "half.py"
    script.write_text(FAILING_SCRIPT)
    out = tmp_path / "res"
    assert (
        main(["--quiet", "study", str(script), "--samples", "16", "--workers", "1", "--out", str(out), "--no-report"])
        == 3
    )
    cap = capsys.readouterr()
    n_failed = st.load(out).counts()["failed"]
    assert 0 < n_failed < 16  # x > 0.5 in about half of 16 Sobol' points
    assert f"{n_failed} FAILED" in cap.out and f"{n_failed} run(s) FAILED; exit code 3" in cap.err
    # resuming a complete study runs nothing new, and still says the study holds failures
    assert main(["--quiet", "study", str(script), "--samples", "16", "--out", str(out), "--no-report"]) == 3
    # the Ishigami study has no failure: exit 0 (test_cli_study_runs_reports_and_resumes)


def test_cli_study_errors_are_one_line(tmp_path, capsys):
    from femast.cli import main

    script = tmp_path / "nostudy.py"
    script.write_text("x = 1\n")
    assert main(["study", str(script), "--samples", "4"]) == 2
    assert "defines no 'study'" in capsys.readouterr().err
    script.write_text(STUDY_SCRIPT)
    assert main(["study", str(script), "--samples", "4", "--workers", "2", "--scheduler", "tcp://x:1"]) == 2
    assert "not both" in capsys.readouterr().err


SLOW_SCRIPT = """
import time
import numpy as np
import femast.studies as st

def slow(a, b):
    time.sleep(0.01)
    return {"y": a * b + np.sin(a), "v": np.array([a, b, a - b])}

study = st.Study(run=slow, inputs=[st.Normal("a", 1.0, 0.5), st.Uniform("b", 0.0, 2.0)], outputs=["y", "v"],
                 sampler="mc", seed=3, name="slow")
"""


@pytest.mark.slow
def test_ctrl_c_then_resume_equals_one_run(tmp_path):
    # a real interruption: SIGINT to `femast study` running 2 local workers, once chunks are on
    # disk; the same command again completes the study; the stored runs equal a one-shot run's
    # (slow: two fresh interpreters importing femast, ~50 s on the loaded machine; the default
    # suite has the same check with the interruption made by limit=, test_interrupt_then_resume...)
    import signal
    import subprocess
    import sys
    import time

    script = tmp_path / "slow_study.py"
    script.write_text(SLOW_SCRIPT)
    out = tmp_path / "interrupted"
    cmd = [
        sys.executable,
        "-m",
        "femast.cli",
        "--quiet",
        "study",
        str(script),
        "--samples",
        "600",
        "--workers",
        "2",
        "--chunk-size",
        "10",
        "--out",
        str(out),
        "--no-report",
    ]
    env = dict(__import__("os").environ, PYTHONPATH=str(Path(fm.__file__).resolve().parents[1]))
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    t0 = time.time()
    while len(list(out.glob("chunks/*.parquet"))) < 3 and time.time() - t0 < 120 and p.poll() is None:
        time.sleep(0.05)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130 and "interrupted" in err, err
    partial = st.load(out).counts()["runs"]
    assert 0 < partial < 600  # stopped part-way
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0 and f"({partial} already on disk)" in r.stdout and "study complete" in r.stdout, r.stderr
    st.run(
        st.Study(
            run=_slow_local,
            inputs=[st.Normal("a", 1.0, 0.5), st.Uniform("b", 0.0, 2.0)],
            outputs=["y", "v"],
            sampler="mc",
            seed=3,
            name="slow",
        ),
        tmp_path / "one",
        samples=600,
    )
    a, b = (
        st.load(tmp_path / "one").table(["a", "b", "y", "v", "status"]),
        st.load(out).table(["a", "b", "y", "v", "status"]),
    )
    for k in a:
        assert np.array_equal(a[k], b[k]), k


def _slow_local(a, b):
    return {"y": a * b + np.sin(a), "v": np.array([a, b, a - b])}


def test_more_samples_later_extend_the_same_study(tmp_path):
    # Sobol' points depend on the run index only: 16 samples then 32 equal 32 at once
    st.run(_ishigami_study(sensitivity=True), tmp_path / "grow", samples=16)
    s = st.run(_ishigami_study(sensitivity=True), tmp_path / "grow", samples=32)
    assert s.resumed == 80 and s.ran == 80 and s.complete
    st.run(_ishigami_study(sensitivity=True), tmp_path / "once", samples=32)
    a, b = st.load(tmp_path / "grow").table(["y", "x3"]), st.load(tmp_path / "once").table(["y", "x3"])
    for k in a:
        assert np.array_equal(a[k], b[k]), k
    with pytest.raises(StudyError, match="give --samples >= 32"):
        st.run(_ishigami_study(sensitivity=True), tmp_path / "grow", samples=8)
    st.run(_ishigami_study(sampler="lhs"), tmp_path / "lhs", samples=8)
    with pytest.raises(StudyError, match="Latin hypercube of 8 samples cannot be resumed with 16"):
        st.run(_ishigami_study(sampler="lhs"), tmp_path / "lhs", samples=16)


def test_report_names_steps_and_components(tmp_path, capsys):
    from femast.studies.report import report

    st.run(
        _cantilever_study(
            outputs=[
                st.NodeOutput("tip", node=2, quantity="U", components=["x", "z"]),
                st.ElementOutput(
                    "m_max",
                    family="beam",
                    key="section_forces",
                    component=(slice(None), slice(4, 6)),
                    reduce="absmax",
                    at="load",
                    unit="N m",
                ),
            ]
        ),
        tmp_path / "r",
        samples=4,
    )
    res = st.load(tmp_path / "r")
    assert (
        res.component_label("tip", (0, 1)) == "tip[load, uz]"
        and res.component_label("tip", (1, 0)) == "tip[unload, ux]"
    )
    rep = report(tmp_path / "r", print_table=True, figures=False)
    out = capsys.readouterr().out
    assert "tip[load, uz]" in out and "m_max" in out
    # the largest bending moment is at the root, F L (N m), sample by sample; the deflected tip's
    # lever arm is shorter by O((w/L)^2) ~ 1e-6 of L (w/L ~ 1e-3 here)
    assert np.allclose(res.output("m_max"), res.inputs("F") * L_M, rtol=1e-5)
    assert len(rep["rows"]) == 5


def _dies(x):
    if x > 0.9:
        import os

        os._exit(3)  # a worker process dying (a crash in compiled code, the OOM killer)
    return {"y": x}


def test_a_dying_worker_process_is_a_clear_error_and_resumable(tmp_path):
    study = st.Study(run=_dies, inputs=[st.Uniform("x", 0.0, 1.0)], outputs=["y"], sampler="mc", seed=4)
    with pytest.raises(StudyError, match="a worker process died"):
        st.run(study, tmp_path / "d", samples=200, workers=2, chunk_size=5)
    done = st.load(tmp_path / "d").counts()["runs"]
    assert done < 200  # what finished is kept (and a rerun resumes from it)


def test_sobol_convergence_approaches_the_ishigami_indices():
    d = Design(_uniform_pi(), sampler="sobol", seed=3, sensitivity=True)
    n = 2**13
    _, _, u = d.points(np.arange(n * 5), n)
    y = ishigami(**d.values(u))["y"].reshape(n, 5)
    c = st.sobol_convergence(y[:, 0], y[:, 1], y[:, 2:].T)
    assert c["n"][0] == 8 and c["n"][-1] == n and c["ST"].shape == (len(c["n"]), 3)
    err = np.max(np.abs(c["ST"] - ISHIGAMI_ST), axis=1)
    # the last estimate equals sobol_indices' and the error falls by 10x from n = 64 to n = 8192
    # (QMC: ~1/n; Monte Carlo would give sqrt(128) ~ 11x)
    assert np.allclose(c["ST"][-1], st.sobol_indices(y[:, 0], y[:, 1], y[:, 2:].T, resamples=10)["ST"])
    assert err[-1] < err[list(c["n"]).index(64)] / 10


def test_statistics_refuse_what_they_cannot_estimate():
    with pytest.raises(StudyError, match="q = 1.5"):
        st.percentile([1.0, 2.0], 1.5)
    with pytest.raises(StudyError, match="no values"):
        st.percentile([], 0.5)
    with pytest.raises(StudyError, match="not finite"):
        st.percentile([1.0, np.nan], 0.5)
    with pytest.raises(StudyError, match="variance 0"):
        st.sobol_indices(np.ones(8), np.ones(8), np.ones((2, 8)))
    with pytest.raises(StudyError, match=r"\(k, n\)"):
        st.sobol_indices(np.arange(8.0), np.arange(8.0), np.ones((2, 7)))
    p = st.percentile(np.arange(10.0), 0.99)  # 10 samples cannot bound the 99 % percentile from above
    assert np.isnan(p["high"]) and p["low"] <= p["estimate"]


def test_report_of_a_study_whose_samples_all_failed(tmp_path, capsys):
    from femast.studies.report import report

    study = st.Study(
        run=lambda x: _flaky(x, -1.0), inputs=[st.Uniform("x", 0.0, 1.0)], outputs=["y", "z"], units={"y": "m"}
    )
    # the nominal sample fails by non-convergence (not a definition error): the study runs, every sample fails
    s = st.run(study, tmp_path / "f", samples=4)
    assert s.failed == 4 and s.ok == 0
    rep = report(tmp_path / "f", figures=True)
    assert "(no successful sample)" in capsys.readouterr().out and rep["figures"] == []


def _sometimes_slow(x):
    if x > 0.8:
        import time

        time.sleep(5.0)  # a sample that struggles (cutbacks, a hang)
    return {"y": x}


@pytest.mark.parametrize("workers", [1, 2])
def test_samples_over_the_timeout_are_recorded_failed(tmp_path, workers):
    study = st.Study(
        run=_sometimes_slow, inputs=[st.Uniform("x", 0.0, 1.0)], outputs=["y"], sampler="mc", seed=2, timeout_s=0.3
    )
    s = st.run(study, tmp_path / "t", samples=20, workers=workers)
    res = st.load(tmp_path / "t")
    t = res.table(["x", "seconds", "status"])
    slow = t["x"] > 0.8
    n_slow = int(np.sum(slow))
    assert n_slow > 0 and s.failed == n_slow and s.ok == 20 - n_slow
    # the slow samples were cut short by the time-out (a sample that ran its 5 s would have succeeded)
    assert all("SampleTimeout: the sample ran over timeout_s = 0.3 s" in r for _, r in res.failures())
    with pytest.raises(StudyError, match="timeout_s"):
        st.Study(run=_sometimes_slow, inputs=[st.Uniform("x", 0.0, 1.0)], outputs=["y"], timeout_s=0)


# ------------------------------------------------------------------ timeout_s in threads (the analysis' deadline)
def _slow_cantilever(F):
    """A cantilever loaded in 1e-4 steps when F > 1.3: 10 000 increments (several seconds)."""
    m = fm.Model("slow cantilever")
    a, b = m.node(0, 0, 0), m.node(L_M, 0, 0)
    m.beam(a, b, fm.circular_tube(D_M, D_M - 2 * T_M, E=70e9), n=2)
    m.fix(a)
    inc = 1e-4 if F > 1.3 else 0.5
    m.step("load", initial_increment=inc, max_increment=inc, max_increments=20000, output_frequency=20000).load(
        b, fz=-F
    )
    return m


def test_deadline_stops_an_analysis_in_a_thread():
    import threading

    from femast.analysis.deadline import check, deadline, remaining
    from femast.errors import SampleTimeout

    out = {}
    an = fm.Analysis(_slow_cantilever(1.5), None, progress=False, on_frame=lambda fr: None)

    def job():
        try:
            with deadline(0.3, "stopped: over 0.3 s"):
                an.run()
        except SampleTimeout as exc:
            out["err"] = str(exc)
        out["after"] = remaining()

    th = threading.Thread(target=job)  # not the main thread: no SIGALRM could reach it
    th.start()
    th.join(600)
    assert out["err"] == "stopped: over 0.3 s"
    assert 0 < an.summary.increments < 10_000  # stopped at an iteration, long before the step's end
    assert out["after"] is None  # the deadline ends with its block
    # nested: the earlier deadline holds
    with deadline(10.0):
        with deadline(100.0):
            assert remaining() < 10.0
    with pytest.raises(fm.ModelError, match="must be > 0"):
        with deadline(0.0):
            pass
    check()  # no deadline: nothing (its cost per call: python benchmarks/deadline_check.py)


def test_timeout_on_dask_thread_workers_records_the_slow_samples_failed(tmp_path):
    distributed = pytest.importorskip("distributed")
    study = st.Study(
        model=_slow_cantilever,
        inputs=[st.Uniform("F", 0.5, 1.5)],
        outputs=[st.NodeOutput("tip_w", node=2, quantity="U", components="z")],
        sampler="mc",
        seed=3,
        timeout_s=0.5,
    )
    with (
        distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cl,
        distributed.Client(cl) as client,
    ):
        s = st.run(study, tmp_path / "d", samples=12, scheduler=client)
    res = st.load(tmp_path / "d")
    n_slow = int(np.sum(res.table(["F"])["F"] > 1.3))
    assert s.engine == "dask" and n_slow > 0 and s.failed == n_slow and s.ok == 12 - n_slow
    # cut short by the time-out: unstopped, each slow sample would run its 10 000 increments and succeed
    assert all("SampleTimeout: the sample ran over timeout_s = 0.5 s" in r for _, r in res.failures())


# ------------------------------------------------------------------ correlation between the members of one input
def test_member_equicorrelation_and_exponential_correlation_are_sampled():
    """Normal scores of the members carry the stated correlation; marginals unchanged.  n = 2^14
    points: the standard error of a sample correlation is (1 - rho^2) / sqrt(n) <= 0.008, so 0.03
    is ~4 standard errors (0.02 for the KS distance, ~1.4 / sqrt(n) = 0.011 at 95 %)."""
    n = 2**14
    rho = 0.6
    x = st.Normal("dL", 0.0, 2.0, size=5, member_correlation=rho)
    d = Design([x, st.Uniform("mu", 0.0, 1.0)], sampler="sobol", seed=4)
    _, _, u = d.points(np.arange(n), n)
    v = d.values(u)["dL"]
    C = np.corrcoef(v.T)
    off = C[~np.eye(5, dtype=bool)]
    assert np.abs(off - rho).max() < 0.03
    for j in range(5):
        assert stats.kstest(v[:, j], "norm", args=(0.0, 2.0)).statistic < 0.02
    # the scalar input stays independent of the members
    assert np.abs(np.corrcoef(v[:, 0], d.values(u)["mu"])[0, 1]) < 0.03
    # exponential correlation of members 0, 1, 2, 4 m apart with length 2 m; uniform marginals:
    # the normal scores carry exp(-|dx| / 2)
    z = np.array([0.0, 1.0, 2.0, 4.0])
    R = st.exponential_correlation(z, 2.0)
    assert R[0, 3] == pytest.approx(np.exp(-2.0)) and R[1, 2] == pytest.approx(np.exp(-0.5))
    y = st.Uniform("g", -1.0, 1.0, size=4, member_correlation=R)
    dm = Design([y], sampler="mc", seed=5)
    _, _, u = dm.points(np.arange(n), n)
    g = dm.values(u)["g"]
    scores = special.ndtri((g + 1.0) / 2.0)
    assert np.abs(np.corrcoef(scores.T) - R).max() < 0.03
    assert g.min() >= -1.0 and g.max() <= 1.0 and stats.kstest(g[:, 3], "uniform", args=(-1.0, 2.0)).statistic < 0.02


def test_member_correlation_holds_in_every_saltelli_block_and_keeps_indices_defined():
    """With sensitivity the group's columns are swapped together (A, B, AB:x), so every block has the
    correlation; the Sobol' indices of the groups stay those of independent groups."""
    n = 2**12
    x = st.Normal("a", 0.0, 1.0, size=3, member_correlation=0.5)
    d = Design([x, st.Normal("b", 0.0, 1.0)], sampler="sobol", seed=2, sensitivity=True)
    runs = np.arange(n * d.runs_per_sample)
    _, block, u = d.points(runs, n)
    v = d.values(u)["a"]
    for j in range(d.runs_per_sample):
        C = np.corrcoef(v[block == j].T)
        assert np.abs(C[~np.eye(3, dtype=bool)] - 0.5).max() < 0.05  # n = 4096: 4 standard errors
    # Y = sum of the members + b: Var(sum) = 3 + 6 * 0.5 = 6, Var(b) = 1 -> S_a = 6/7, S_b = 1/7
    vals = d.values(u)
    y = vals["a"].sum(axis=1) + vals["b"]
    fA, fB = y[block == 0], y[block == 1]
    fAB = np.stack([y[block == 2], y[block == 3]])
    idx = st.sobol_indices(fA, fB, fAB, ["a", "b"])
    np.testing.assert_allclose(idx["S1"], [6 / 7, 1 / 7], atol=0.03)  # 4096 Sobol' samples: bootstrap se ~0.008
    np.testing.assert_allclose(idx["ST"], [6 / 7, 1 / 7], atol=0.03)


@pytest.mark.parametrize(
    "make, words",
    [
        (lambda: st.Normal("a", 0, 1, member_correlation=0.5), ["'a'", "per-member input"]),
        (lambda: st.Normal("a", 0, 1, size=4, member_correlation=-0.5), ["'a'", "(-0.3333, 1)", "4 members"]),
        (lambda: st.Normal("a", 0, 1, size=4, member_correlation=1.0), ["'a'", "must lie in"]),
        (lambda: st.Normal("a", 0, 1, size=3, member_correlation=float("nan")), ["'a'", "not finite"]),
        (lambda: st.Normal("a", 0, 1, size=3, member_correlation=np.eye(2)), ["'a'", "(3, 3)", "(2, 2)"]),
        (lambda: st.Uniform("a", 0, 1, size=2, member_correlation=[[1, 0.5], [0.4, 1]]), ["symmetric"]),
        (
            lambda: st.Uniform("a", 0, 1, size=3, member_correlation=[[1, 0.9, -0.9], [0.9, 1, 0.9], [-0.9, 0.9, 1]]),
            ["not positive definite"],
        ),
        (lambda: st.exponential_correlation([0.0, 1.0], 0.0), ["length", "> 0"]),
    ],
)
def test_bad_member_correlation_is_named(make, words):
    with pytest.raises(StudyError) as e:
        make()
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_member_correlation_is_part_of_the_stored_study(tmp_path):
    def run_fn(a):
        return {"y": float(np.sum(a))}

    s1 = st.Study(run=run_fn, inputs=[st.Normal("a", 0, 1, size=3, member_correlation=0.3)], outputs=["y"])
    st.run(s1, tmp_path / "s", samples=4)
    s2 = st.Study(run=run_fn, inputs=[st.Normal("a", 0, 1, size=3, member_correlation=0.4)], outputs=["y"])
    with pytest.raises(StudyError, match="holds another study"):
        st.run(s2, tmp_path / "s", samples=4)


def test_first_order_indices_do_not_depend_on_the_output_mean():
    """Y = c + a + 0.5 b (a, b standard normal): S1 = (0.8, 0.2) whatever the offset c.  The
    estimator centres f_B (same expectation); uncentred, a mean 1000 times the spread adds a
    variance ~c^2 / n to S1 (errors ~1 at n = 512 Monte Carlo samples)."""
    n = 512
    d = Design([st.Normal("a", 0, 1), st.Normal("b", 0, 1)], sampler="mc", seed=3, sensitivity=True)
    _, block, u = d.points(np.arange(n * 4), n)
    v = d.values(u)
    out = []
    for c in (0.0, 1000.0):
        y = c + v["a"] + 0.5 * v["b"]
        out.append(st.sobol_indices(y[block == 0], y[block == 1], np.stack([y[block == 2], y[block == 3]])))
    np.testing.assert_allclose(out[1]["S1"], out[0]["S1"], rtol=0, atol=1e-9)  # round-off of the offset
    np.testing.assert_allclose(out[1]["S1"], [0.8, 0.2], atol=0.1)  # 512 MC samples: ~3 standard errors
    assert np.all(out[1]["S1_high"] - out[1]["S1_low"] < 0.5)
