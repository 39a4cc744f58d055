"""The independent data generator of the diagnose generalisation benchmark.

Its physics is checked against closed forms (not against femast's effects, which it must not
share code or functional form with); the two rigs' baselines are cross-checked against femast's
baseline models of the papers (3R Jacobian, latch law), which the generator re-implements.
"""

import ast
import sys
from pathlib import Path

import numpy as np
import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCH))

from generalisation import mechanisms as mech  # noqa: E402
from generalisation import noise as nz  # noqa: E402
from generalisation.rigs import LATCH, joint_moments, latch_law, top_translation, viscous_joint  # noqa: E402
from generalisation.scoring import is_right, read_verdict, score  # noqa: E402


def test_generator_imports_no_femast_code():
    allowed = {"numpy", "matplotlib", "__future__", "dataclasses", "re"}  # gallery.py draws with matplotlib
    for path in (BENCH / "generalisation").glob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                mods = [a.name.split(".")[0] for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:  # relative: inside the generator package
                    continue
                mods = [node.module.split(".")[0]]
            else:
                continue
            assert set(mods) <= allowed, f"{path.name} imports {mods}; the generator may use only {allowed}"


# --------------------------------------------------------------------------- friction operators
def test_dahl_monotone_stroke_matches_closed_form():
    F_c, sigma, F0 = 5.0, 2e4, -3.0
    u = np.linspace(0.0, 1e-3, 201)
    F = mech.smooth_driven(u, mech.dahl_tangent(F_c, sigma, 1.0), F0=F0)
    exact = F_c + (F0 - F_c) * np.exp(-sigma * u / F_c)
    # RK4 with 40 substeps per sample on a step of 5e-6 (sigma du / F_c = 0.02): error ~1e-12
    assert np.allclose(F, exact, rtol=0, atol=1e-9 * F_c)


def test_bouc_wen_limits():
    F_y, u_y = 4.0, 1e-4
    u = np.linspace(0.0, 6e-4, 301)
    # n = 1, beta = gamma = 1/2, loading from zero: dz/du = (1 - z)/u_y, z = 1 - exp(-u/u_y)
    F = mech.smooth_driven(u, mech.bouc_wen_tangent(F_y, u_y, 1.0))
    assert np.allclose(F, F_y * (1 - np.exp(-u / u_y)), atol=1e-9 * F_y)
    # n -> inf: the elastic-perfectly-plastic (Jenkins) element of stiffness F_y/u_y, over a cycle
    t = np.linspace(0, 2 * np.pi, 2001)
    uc = 4e-4 * np.sin(t)
    F_bw = mech.smooth_driven(uc, mech.bouc_wen_tangent(F_y, u_y, 400.0))
    F_j = mech.jenkins_driven(uc, F_y / u_y, F_y)
    # with n = 400 the knee is rounded over |z| > 1 - O(ln(n)/n): a 2 % band of F_y holds it
    assert np.max(np.abs(F_bw - F_j)) < 0.02 * F_y
    assert np.max(np.abs(F_bw)) <= F_y * (1 + 1e-9)  # beta + gamma = 1 bounds |F| by F_y


def test_jenkins_loop_area_is_the_dissipated_energy():
    k_s, F_s, A = 3e4, 2.0, 4e-4
    t = np.linspace(0, 4 * np.pi, 80001)
    u = A * np.sin(t)
    F = mech.jenkins_driven(u, k_s, F_s)
    second = t >= 2 * np.pi  # the second cycle is the steady loop
    area = np.sum(0.5 * (F[second][1:] + F[second][:-1]) * np.diff(u[second]))
    exact = 4 * F_s * (A - F_s / k_s)
    # trapezoid rule on 40000 steps per cycle: relative error ~ step/A ~ 1e-4
    assert area == pytest.approx(exact, rel=1e-3)


def test_load_controlled_solutions_are_in_equilibrium():
    k = 2.5e5
    m = np.concatenate([np.linspace(0, 30, 40), np.linspace(30, -25, 60), np.linspace(-25, 12, 40)])
    u, F = mech.jenkins_load_controlled(m, k, 2e5, 8.0)
    F_again = mech.jenkins_driven(u, 2e5, 8.0)
    assert np.allclose(F, F_again, atol=1e-9) and np.allclose(k * u + F_again, m, atol=1e-9 * 30)
    g = mech.dahl_tangent(8.0, 3e5, 1.0)
    u, F = mech.smooth_load_controlled(m, k, g)
    F_again = mech.smooth_driven(u, g)
    # two RK4 integrations of different ODEs (driven by m and by u): agree to 1e-6 of the load
    assert np.allclose(k * u + F_again, m, atol=1e-6 * 30)


# --------------------------------------------------------------------------- contact, stiffening, loops
def test_clearance_laws():
    m = np.linspace(-40, 40, 801)
    phi = mech.clearance_piecewise(m, 1e-4, 2e4, 5e6)
    back = np.where(np.abs(phi) <= 1e-4, 2e4 * phi, np.sign(phi) * (2e4 * 1e-4 + 5e6 * (np.abs(phi) - 1e-4)))
    assert np.allclose(back, m, atol=1e-9)
    c, k0, K = 1e-4, 2e4, 5e7
    phi = mech.clearance_hertz(m, c, k0, K)
    back = k0 * phi + K * np.maximum(np.abs(phi) - c, 0) ** 1.5 * np.sign(phi)
    assert np.allclose(back, m, atol=1e-9)  # 80 bisections: |phi| to 2^-80 of its bracket
    assert np.all(np.diff(phi) > 0)
    assert np.allclose(mech.clearance_tanh(m, 1e-4, 1e-6)[np.abs(m) > 1e-3], 1e-4 * np.sign(m[np.abs(m) > 1e-3]))


def test_stiffening_laws():
    m = np.linspace(-50, 50, 101)
    u = mech.duffing_rotation(m, 2.5e5, 2.5e13)
    assert np.allclose(2.5e5 * u + 2.5e13 * u**3, m, atol=1e-9)
    u = mech.asinh_rotation(m, 2.5e5, 10.0)
    dm_du = np.gradient(m, u)
    assert np.allclose(dm_du[1:-1], 2.5e5 * np.sqrt(1 + (m[1:-1] / 10) ** 2), rtol=2e-3)  # central differences


def test_cable_loop_closes_at_zero_and_has_the_quadratic_area():
    P, eps = 20.0, 0.4
    y = np.concatenate([np.linspace(0, P, 20001), np.linspace(P, 0, 20001)[1:]])
    r = mech.loop_quadratic(y, eps)
    assert r[-1] == pytest.approx(0.0, abs=1e-12) and r[20000] == pytest.approx(P)
    area = np.sum(0.5 * (r[1:] + r[:-1]) * np.diff(y))  # integral of response dy around the path
    assert -area == pytest.approx(eps * P**2 / 6, rel=1e-4)
    rp = mech.loop_power(y, 0.5)
    assert rp[-1] == pytest.approx(0.0, abs=1e-12) and np.all(rp[20001:] >= y[20001:] - 1e-12)


def test_cantilever_compliance_closed_forms():
    L, EI = 3.651, 1.2e5
    c_f, c_m = mech.cantilever_compliance(L, [(L, EI)])
    assert c_f == pytest.approx(L**3 / (3 * EI)) and c_m == pytest.approx(L**2 / (2 * EI))
    assert mech.cantilever_compliance(L, [(1.0, EI), (L - 1.0, EI)]) == pytest.approx((c_f, c_m))
    assert mech.cantilever_compliance(L, [(L, EI)], shear_GA=2e5)[0] == pytest.approx(c_f + L / 2e5)


def test_viscous_joint_lags_a_ramp_by_the_relaxation_time():
    k, c = 2e5, 1.2e6  # relaxation time c/k = 6 s
    t = np.linspace(0, 120, 241)
    m = 0.5 * t  # N m, a ramp of 0.5 N m/s
    u = viscous_joint(m, t, k, c)
    assert u[-1] == pytest.approx((m[-1] - 0.5 * c / k) / k, rel=1e-6)  # after 20 relaxation times


# --------------------------------------------------------------------------- noise
def test_ar1_noise_has_its_variance_and_lag1_correlation():
    e = nz.ar1(np.random.default_rng(3), 200_000, 0.5, 0.6)
    r1 = np.corrcoef(e[1:], e[:-1])[0, 1]
    assert r1 == pytest.approx(0.6, abs=0.01)  # standard error sqrt((1 - phi^2)/n) = 0.0018
    assert np.std(e) == pytest.approx(0.5, rel=0.02)  # std error of the variance of an AR(1) ~ 0.5 %


def test_eq15_noise_variance_follows_the_slope():
    rng = np.random.default_rng(7)
    C, sT, sd = 2.5e-6, 0.4, 4e-6
    n = 200_000
    x = rng.uniform(-1e-3, 1e-3, n)
    for s in (0.0, 8e4, -1.5e5):  # N/m; a linear law makes the first-order variance exact
        xm, dTm = nz.eq15_measurement(rng, x, s * x, C, sT, sd)
        r = dTm - s * xm
        assert np.var(r) == pytest.approx(float(nz.eq15_residual_variance(s, C, sT, sd)), rel=0.02)  # SE 0.3 %


# --------------------------------------------------------------------------- rigs against the papers' baselines
def test_mast_rig_matches_the_3r_jacobian():
    from femast.guyed.mast_3r import jacobian_3r

    rng = np.random.default_rng(0)
    w = rng.normal(size=(5, 6))
    J = jacobian_3r(np.array([0, 0, 3.651]))
    assert np.allclose(joint_moments(w), w @ J, atol=1e-12)
    th = rng.normal(size=(5, 3))
    assert np.allclose(top_translation(th), th @ J[:3].T, atol=1e-12)


def test_latch_rig_matches_the_seed_law():
    from femast.elements.latch_law import LATCHING, UNLATCHING, latch_force

    p = np.array([LATCH[k] for k in ("r", "xb", "k", "mu", "h", "R")])
    x = np.linspace(-2e-3, 4e-3, 301)
    assert np.allclose(latch_law(x, -1), latch_force(x, LATCHING, p), atol=1e-9)
    assert np.allclose(latch_law(x, +1), latch_force(x, UNLATCHING, p), atol=1e-9)


@pytest.mark.parametrize("name", ["mt_null_white", "mt_null_hetero", "lp_null_white", "lp_null_ar1"])
def test_noise_free_null_data_is_the_seed_baseline(name):
    # the null cases must be exactly what the experiment's baseline model predicts at the paper's
    # parameters, or every null redraw carries a systematic error (a hold pulled past the
    # breakaway force once did: 4 samples 1-4 N above the static band on the backstop)
    from dataclasses import replace

    from generalisation.cases import generate, get_case
    from generalisation.rigs import K_JOINTS

    from femast.experiments import from_arrays, get_experiment
    from femast.experiments.core import NO_EFFECTS

    case = replace(get_case(name), level=1e-12)
    exp = get_experiment(case.experiment)
    for seed in range(3):
        cols = generate(case, seed)
        data = from_arrays(exp, **cols)
        params = {"k_theta1": K_JOINTS[0], "k_theta2": K_JOINTS[1]} if case.experiment == "mast-top" else exp.defaults()
        pred = exp.model(params, data, NO_EFFECTS, exp.options)
        scale = max(np.max(np.abs(cols[ch])) for ch in pred)  # dz is zero in the 3R model: one scale
        for ch, p in pred.items():
            assert np.max(np.abs(cols[ch] - p)) < 1e-9 * scale, (name, seed, ch)  # round-off of the two codes


# --------------------------------------------------------------------------- scoring and the harness
def test_verdict_adapter_reads_old_and_new_reports():
    old = {
        "verdict": {
            "missing_effect": "joint_clearance",
            "explained": True,
            "best_candidate": "joint_clearance",
            "conclusion": "missing effect: joint_clearance (joint clearance); with it ...",
        }
    }
    assert read_verdict(old) == {
        "kind": "missing",
        "effects": ["joint_clearance"],
        "conclusion": old["verdict"]["conclusion"],
    }
    none = {
        "verdict": {
            "missing_effect": None,
            "explained": False,
            "best_candidate": "x",
            "conclusion": "none of the candidates explains this: the best, x, ...",
        }
    }
    assert read_verdict(none)["kind"] == "not_explained"
    null = {"verdict": {"missing_effect": None, "explained": True, "conclusion": "nothing is missing: ..."}}
    assert read_verdict(null)["kind"] == "nothing"
    form = {
        "verdict": {
            "missing_effect": None,
            "conclusion": "mechanism found, form imperfect: friction_hysteresis explains 80 %",
            "best_candidate": "friction_hysteresis",
        }
    }
    assert read_verdict(form) == {
        "kind": "form_imperfect",
        "effects": ["friction_hysteresis"],
        "conclusion": form["verdict"]["conclusion"],
    }
    pair = {
        "verdict": {
            "kind": "missing_effect",
            "missing_effect": "joint_clearance+friction_hysteresis",
            "conclusion": "missing effect: joint_clearance + friction_hysteresis",
        }
    }
    assert read_verdict(pair)["effects"] == ["friction_hysteresis", "joint_clearance"]
    slashed = {
        "verdict": {"kind": "missing_effect", "missing_effect": "friction_hysteresis/jenkins", "conclusion": "?"}
    }
    assert read_verdict(slashed)["effects"] == ["friction_hysteresis"]  # a form names its mechanism
    v = read_verdict(pair)
    assert is_right("pair", ("joint_clearance", "friction_hysteresis"), v)
    assert not is_right("effect", ("joint_clearance",), v)
    assert is_right("ool", (), read_verdict(form)) and not is_right("ool", (), read_verdict(old))
    assert is_right("null", (), read_verdict(null)) and not is_right("null", (), read_verdict(none))


def test_verdict_adapter_reads_the_verdict_kinds():
    pair = {
        "verdict": {
            "kind": "missing_pair",
            "missing_effect": None,
            "missing_effects": ["latch_hysteresis", "stretch_error"],
            "mechanism": None,
            "conclusion": "missing effects: ...",
        }
    }
    assert read_verdict(pair)["kind"] == "missing"
    assert read_verdict(pair)["effects"] == ["latch_hysteresis", "stretch_error"]
    form = {
        "verdict": {
            "kind": "form_imperfect",
            "missing_effect": None,
            "missing_effects": [],
            "mechanism": "joint_clearance",
            "best_candidate": "joint_clearance",
            "conclusion": "...",
        }
    }
    assert read_verdict(form)["kind"] == "form_imperfect" and read_verdict(form)["effects"] == ["joint_clearance"]
    for kind, expect in (
        ("nothing_missing", "nothing"),
        ("not_explained", "not_explained"),
        ("missing_effect", "missing"),
        ("better_form", "missing"),
    ):
        assert read_verdict({"verdict": {"kind": kind, "conclusion": "?"}})["kind"] == expect


def test_score_weighs_each_null_case_as_one_case():
    rows = [{"case": "a", "expect": "effect", "right": True}, {"case": "b", "expect": "ool", "right": False}] + [
        {"case": "n", "expect": "null", "right": i < 15} for i in range(20)
    ]
    s = score(rows)
    assert s["score"] == pytest.approx((1 + 0 + 15 / 20) / 3)
    assert s["false_alarm_rate"] == pytest.approx(5 / 20) and s["null_runs"] == 20


def test_benchmark_harness_smoke(tmp_path):
    import diagnose_generalisation as bench

    cases = bench.select("mt_null_white,lp_ool_ripple", quick=False)
    rows = bench.run_all(cases, redraws=1, workers=1, progress=False)
    assert [r["case"] for r in rows] == ["lp_ool_ripple", "mt_null_white"]  # catalogue order
    for r in rows:
        assert r["kind"] in ("missing", "form_imperfect", "not_explained", "nothing"), r["conclusion"]
        assert isinstance(r["right"], bool) and r["baseline_ratio"] > 0
    s = bench.score(rows)
    assert s["cases"] == 2 and s["null_runs"] == 1
    text = bench.format_table(rows)
    assert "confusion table" in text and "lp_ool_ripple" in text
    paths = bench.figures(rows, s, tmp_path)
    assert all(p.stat().st_size > 10_000 for p in paths)  # a real PNG, not an empty canvas


def test_benchmark_runs_on_femast_workers(monkeypatch):
    """--workers other than 1 runs on femast's one pool (here one worker: one run); the row is the
    same as in this process (the draw's seed depends on the case and redraw only)."""
    import diagnose_generalisation as bench

    from femast import workers

    started = []
    monkeypatch.setattr(workers.Pool, "__init__", _recording(workers.Pool.__init__, started))
    cases = bench.select("mt_null_white", quick=False)
    pooled = bench.run_all(cases, redraws=1, workers=None, progress=False)
    here = bench.run_all(cases, redraws=1, workers=1, progress=False)
    assert started == [1]  # one pool of one worker (one run), none for workers=1
    for key in ("kind", "effects", "right", "baseline_ratio"):
        assert pooled[0][key] == here[0][key]


def _recording(init, started):
    def wrapped(self, n, *args, **kwargs):
        started.append(n)
        init(self, n, *args, **kwargs)

    return wrapped


def test_docs_page_example_runs():
    from doc_examples import run_python_blocks

    run_python_blocks("diagnose_generalisation.md", cwd=BENCH.parent)


# --------------------------------------------------------------------------- guys, relays, creep, heavy tails
def test_slack_guys_are_in_equilibrium_and_engage_past_the_slack():
    k, k_g, th_s = 2.5e5, 2.5e5, 0.7e-4
    m = np.linspace(-60.0, 60.0, 241)
    u = mech.slack_guys_rotation(m, k, k_g, th_s)
    np.testing.assert_allclose(k * u + k_g * np.sign(u) * np.maximum(np.abs(u) - th_s, 0.0), m, rtol=1e-12, atol=1e-12)
    inside = np.abs(m) <= k * th_s
    np.testing.assert_allclose(u[inside], m[inside] / k)
    one = mech.slack_guys_rotation(m, k, k_g, th_s, sides=1)  # one guy, on the positive side
    np.testing.assert_allclose(k * one + k_g * np.maximum(one - th_s, 0.0), m, rtol=1e-12, atol=1e-12)


def test_preisach_with_uniform_symmetric_relays_has_the_everett_branch():
    # relays (a, -a), a uniform on [0, A]: from negative saturation the ascending branch is 2 m / A - 1
    A = 10.0
    a = (np.arange(2000) + 0.5) / 2000 * A
    u = np.concatenate([np.linspace(0, -A, 101), np.linspace(-A, A, 401)[1:]])
    out = mech.preisach_relays(a, -a, np.full(a.size, 1 / a.size), u)
    up = u[101:]
    rising = up > 0
    np.testing.assert_allclose(out[101:][rising], 2 * up[rising] / A - 1, atol=1e-3)
    np.testing.assert_allclose(out[101:][~rising], -1.0)
    with pytest.raises(ValueError, match="alpha >= beta"):
        mech.preisach_relays([0.0], [1.0], [1.0], u)


def test_log_creep_under_a_held_load_and_superposition():
    k, phi, t0, m0 = 2.5e5, 0.05, 2.0, 30.0
    t = np.linspace(0.0, 100.0, 201)
    m = np.full(t.size, m0)
    np.testing.assert_allclose(mech.log_creep_rotation(m, t, k, phi, t0), m0 * (1 + phi * np.log1p(t / t0)) / k)
    # loading then unloading at t = 50 s: the recovery is the difference of the two step responses
    m2 = np.where(t < 50.0, m0, 0.0)
    late = t >= 50.0
    ref = m0 * phi * (np.log1p(t[late] / t0) - np.log1p((t[late] - 50.0) / t0)) / k
    np.testing.assert_allclose(mech.log_creep_rotation(m2, t, k, phi, t0)[late], ref, rtol=1e-12, atol=1e-18)


def test_heavy_tailed_noise_and_spikes():
    rng = np.random.default_rng(3)
    e = nz.student_t(rng, 200_000, 2.0, 3.0)
    # quartiles of Student's t with 3 degrees of freedom: +-0.76489, scaled by sigma sqrt(1/3)
    q1, q3 = np.percentile(e, [25, 75])
    np.testing.assert_allclose([q1, q3], np.array([-0.76489, 0.76489]) * 2.0 / np.sqrt(3.0), rtol=0.02)
    assert np.mean(np.abs(e) > 4 * 2.0) > 10 * 6.3e-5  # far more 4-sigma rows than a normal's 6.3e-5
    s = nz.spikes(rng, 300, 12, 10.0)
    assert np.count_nonzero(s) == 12 and np.all(np.abs(s[s != 0]) >= 5.0) and np.all(np.abs(s) <= 10.0)
    assert not s[:5].any() and not s[-5:].any()
