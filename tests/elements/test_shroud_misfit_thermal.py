"""Length errors (lack of fit) and thermal strain of the Dyneema shroud cables (the Rocaspect paper,
Eq. 25), and of the guyed FE mast built from them.

The closed forms use the rope law only in its printed, forward form ``eps = tau / g(tau)``,
``g = k0 + k1 tau + k2 tau^2`` (Eq. 27), solved here with brentq: nothing of the element's inverse
formula or kernel."""

import numpy as np
import pytest
from scipy.optimize import brentq

import femast as fm
from femast.analysis import Analysis
from femast.elements.shroud_cable import ShroudCableFamily, add_shrouds, unstretched_length
from femast.elements.shroud_law import DyneemaLaw
from femast.errors import ModelError
from femast.guyed.fe_mast import MastFE
from femast.model.amplitudes import Amplitude
from femast.model.sections import Section
from femast.rotations import expm_so3
from femast.testing import fd_tangent

LAW = DyneemaLaw()
K0, K1, K2 = LAW.k0, LAW.k1, LAW.k2
T0 = 1200.0  # N, the paper's pretension


def g(tau):
    return K0 + K1 * tau + K2 * tau * tau


def strain(tau):
    """Eq. 27 forward: the strain at which the rope carries tau (N)."""
    return tau / g(tau)


def tension(eps):
    """Inverse of Eq. 27 by root finding (0 when slack)."""
    if eps <= 0.0:
        return 0.0
    return brentq(lambda t: strain(t) - eps, 0.0, 2.0e5, xtol=1e-14, rtol=1e-15)


#: the closed forms below are checked to 1e-8 .. 1e-10 relative: tolerances of 1e-10 (femast's
#: default 1e-6 lets a state be up to ~1e-6 off; an increment may be accepted on its
#: predicted next correction, without the extra iteration that used to leave it ~1e-12 away)
TIGHT = fm.Convergence(force_tol=1e-10, disp_tol=1e-10)


def _frames(model, convergence=TIGHT):
    frames = []
    Analysis(model, None, progress=False, on_frame=frames.append, convergence=convergence).run()
    return frames


# ------------------------------------------------------------------ a rope between fixed points
def test_pretensioned_rope_cut_short_carries_the_law_at_its_new_strain():
    """A rope pretensioned to T0 between fixed points, cut d short: eps = L / (L0 - d) - 1 and tau
    from Eq. 27 at that strain; cut d long enough to go slack: no force."""
    L = 5.0
    X = np.array([[0.0, 0.0, 0.0], [3.0, 4.0, 0.0]])
    L0 = float(unstretched_length(LAW, T0, L))
    for d, expected in (
        (2e-3, tension(L / (L0 - 2e-3) - 1.0)),
        (-0.3e-3, tension(L / (L0 + 0.3e-3) - 1.0)),
        (-0.01, 0.0),
    ):
        fam = ShroudCableFamily([[0, 1]], L0, LAW, length_error=-d)
        out = fam.evaluate(X, None, None).output
        # the law's inverse is closed form in the kernel and a root here: round-off ~1e-13
        assert out["tension"][0] == pytest.approx(expected, rel=1e-11, abs=1e-9)
        assert out["strain"][0] == pytest.approx(L / (L0 - d) - 1.0, rel=1e-12)
    # first order: the tension gains EA_t d L / L0^2 (d eps = L d / L0^2; EA_t = g^2 / (k0 - k2 tau^2) at T0)
    fam = ShroudCableFamily([[0, 1]], L0, LAW, length_error=-1e-6)
    gain = fam.evaluate(X, None, None).output["tension"][0] - T0
    EAt = g(T0) ** 2 / (K0 - K2 * T0**2)
    # second order: (d EA_t / d tau) dtau / (2 EA_t) ~ 300 x 0.26 N / 2.2 MN = 4e-5 (the law stiffens)
    assert gain == pytest.approx(EAt * 1e-6 * L / L0**2, rel=1e-4)


def _series(d=0.0, alpha=0.0, dT=0.0, amplitude=None, increments=4):
    """Two ropes in series between fixed anchors (x = 0 and x = 7 m), the middle node on a
    roller along x; rope 'a' (0 - 3 m) cut d short, rope 'b' (3 - 7 m) heated by dT."""
    m = fm.Model("ropes in series")
    n0, n1, n2 = m.node(0, 0, 0), m.node(3.0, 0, 0), m.node(7.0, 0, 0)
    m.fix(n0)
    m.fix(n2)
    m.fix(n1, "uy", "uz", "rx", "ry", "rz")
    add_shrouds(m, [[n0, n1]], tension=T0, name="a", length_error=-d)
    add_shrouds(m, [[n1, n2]], tension=T0, name="b")
    if alpha:
        m.thermal_expansion(alpha, family="b")
    st = m.step("heat", initial_increment=1.0 / increments, max_increment=1.0 / increments)
    if alpha:
        st.temperature(dT, family="b", amplitude=amplitude)
    return m


def _series_closed_form(d, s):
    """tau and the middle node's displacement: La (1 + eps) + Lb s (1 + eps) = 7 m."""
    La, Lb = 3.0 / (1 + strain(T0)) - d, 4.0 / (1 + strain(T0)) * s
    eps = 7.0 / (La + Lb) - 1.0
    return tension(eps), La * (1.0 + eps) - 3.0


def test_ropes_in_series_short_and_heated_follow_the_closed_form_at_every_increment():
    """Rope a 1 mm short; rope b (Dyneema-like alpha = -12e-6 /K) heated by +40 K over a 0 -> 1 -> 0
    amplitude (a thermal cycle): the tension and the middle node follow the closed form at every
    increment, and the cycle ends where it started (the rope law is elastic)."""
    d, alpha, dT = 1e-3, -12e-6, 40.0
    amp = Amplitude([0.0, 0.5, 1.0], [0.0, 1.0, 0.0])
    frames = [f for f in _frames(_series(d, alpha, dT, amp, increments=8)) if f["step"] == "heat"]
    assert len(frames) == 8
    for f in frames:
        s = 1.0 + alpha * dT * amp(float(f["total_time"]))
        tau, u = _series_closed_form(d, s)
        # Newton's tolerance (TIGHT) dominates; tau ~ 1.4 kN
        np.testing.assert_allclose(f["el/a/tension"][0], tau, rtol=1e-8)
        np.testing.assert_allclose(f["el/b/tension"][0], tau, rtol=1e-8)
        assert f["U"][1, 0] == pytest.approx(u, rel=1e-7, abs=1e-12)
    peak = max(frames, key=lambda f: f["el/b/tension"][0])
    assert float(peak["total_time"]) == pytest.approx(0.5)
    tau_end, _ = _series_closed_form(d, 1.0)
    assert frames[-1]["el/a/tension"][0] == pytest.approx(tau_end, rel=1e-8)
    # the shortening alone is a real load: compare with no error
    assert tau_end - T0 > 50.0


def test_heated_rope_free_to_grow_keeps_its_force_and_grows_by_alpha_dT():
    """A rope from an anchor to a node pulled by a dead load F (statically determinate): heating it
    leaves the tension F and moves the node by L0 alpha dT (1 + eps(F)) (free thermal expansion)."""
    F, alpha, dT = 800.0, 2.0e-5, -30.0
    m = fm.Model("free rope")
    n0, n1 = m.node(0, 0, 0), m.node(0, 0, -2.5)
    m.fix(n0)
    m.fix(n1, "ux", "uy", "rx", "ry", "rz")
    fam = add_shrouds(m, [[n0, n1]], tension=F, name="r")
    m.thermal_expansion(alpha, family="r")
    m.step("load").load(n1, fz=-F)
    m.step("heat").temperature(dT, family="r")
    frames = _frames(m)
    end = {f["step"]: f for f in frames}
    assert end["heat"]["el/r/tension"][0] == pytest.approx(F, rel=1e-10)  # Newton's tolerance
    du = end["heat"]["U"][1, 2] - end["load"]["U"][1, 2]
    expected = -fam.L0[0] * alpha * dT * (1.0 + strain(F))
    assert du == pytest.approx(expected, rel=1e-7)  # 1.5 mm; equilibrium to 1e-9 of F
    assert np.all(m.families[0].length_factor == 1.0)  # the analysis heated its own copy


# ------------------------------------------------------------------ a beam guyed by two ropes
def test_cantilever_guyed_by_two_ropes_one_cut_short_deflects_as_the_hand_calculation():
    """A clamped tube (length H, EI) with two horizontal ropes from its tip to anchors at x = +-a,
    both pretensioned to T0 (balanced).  Rope + cut d short pulls the tip by u:
    3 EI / H^3 u = tau(eps_+) - tau(eps_-), eps_+ = (a - u) / (L0 - d) - 1, eps_- = (a + u) / L0 - 1
    (Euler-Bernoulli tip stiffness; the ropes stay horizontal to O(u^2 / H))."""
    H, a, d = 3.651, 3.0, 1e-3
    E, s_out, s_in = 6.55e10, 0.1, 0.094
    I = (s_out**4 - s_in**4) / 12.0
    sec = Section(E=E, G=E / 2.6, A=s_out**2 - s_in**2, Iy=I, Iz=I, J=2 * I)
    m = fm.Model("guyed cantilever")
    base, tip = m.node(0, 0, 0), m.node(0, 0, H)
    m.beam(base, tip, sec, up=(0.0, 1.0, 0.0), n=8, family="tube")
    m.fix(base)
    pa, ma = m.node(a, 0, H), m.node(-a, 0, H)
    m.fix(pa)
    m.fix(ma)
    add_shrouds(m, [[tip, pa], [tip, ma]], tension=T0, length_error=[-d, 0.0], name="guy")
    m.step("cut")
    f = _frames(m)[-1]
    kb = 3.0 * E * I / H**3
    L0 = a / (1.0 + strain(T0))
    u = brentq(lambda u: kb * u - (tension((a - u) / (L0 - d) - 1.0) - tension((a + u) / L0 - 1.0)), 0.0, d, xtol=1e-15)
    # neglected: the tip's drop u^2 / H ~ 1e-7 m tilting the ropes (cos ~ 1 - 1e-15), the beam's
    # large-rotation terms ~ (u / H)^2 ~ 2e-8; Newton 1e-9 (measured 2e-10)
    assert f["U"][1, 0] == pytest.approx(u, rel=1e-7)
    np.testing.assert_allclose(
        f["el/guy/tension"], [tension((a - u) / (L0 - d) - 1.0), tension((a + u) / L0 - 1.0)], rtol=1e-6
    )
    # the rope nearly wins: u is most of d / 2 (rope stiffness >> the tube's 3 EI / H^3 = 2.5 kN/m)
    assert 0.45 * d < u < 0.5 * d


# ------------------------------------------------------------------ the guyed FE mast
def test_fe_mast_heated_shrouds_equal_the_same_length_error():
    """Heating the shrouds by dT (alpha) makes them stress free at L0 (1 + alpha dT): the state after
    the thermal step equals that of a mast whose shrouds are L0 alpha dT too long (to Newton's
    tolerance); warming Dyneema (alpha < 0) tightens the shrouds."""
    alpha, dT = -12e-6, 30.0
    hot = MastFE(1200.0, temperature_change_K=dT, shroud_alpha_per_K=alpha)
    hot.solve()
    long = MastFE(1200.0, length_error=hot.L0 * alpha * dT)
    long.solve()
    a, b = hot.state(), long.state()
    np.testing.assert_allclose(a.tension, b.tension, rtol=1e-8)  # Newton 1e-9 on ~1.3 kN
    np.testing.assert_allclose(a.displacement, b.displacement, rtol=0, atol=1e-8 * np.abs(b.displacement).max())
    nominal = MastFE(1200.0)
    nominal.solve()
    assert np.all(a.tension > nominal.state().tension + 50.0)  # 360 ppm shorter: ~+120 N each
    assert [fr[0] for fr in hot._frames][-1] == "thermal"


def test_fe_mast_heated_top_rises_as_the_hand_calculation_of_tube_and_shrouds():
    """Tube (+23e-6 /K) and Dyneema shrouds (-12e-6 /K) warmed by 20 K.  Hand model: the top rises by
    delta, the tube (EA / H) grows freely by alpha_t dT H less its extra compression, each rope
    (vertical cosine c_r, length l_r) stretches by c_r delta from its heated stress-free length
    L0_r (1 + alpha_s dT), with the Eq. 27 law: k_t (alpha_t dT H - delta) = sum c_r (tau_r(delta) - tau_r0).
    Neglected: the top's lateral drift (0.27 mm; the ropes are not placed symmetrically), which
    changes the rope lengths by ~0.04 mm of their ~2.4 mm: ~1 % on the tensions, less on delta."""
    from femast.guyed.cantilever import mast_section
    from femast.guyed.rocaspect import E_NO_SHROUD, L_BEAM

    at, as_, dT = 23e-6, -12e-6, 20.0
    nom = MastFE(1200.0)
    nom.solve()
    s0 = nom.state()
    hot = MastFE(1200.0, temperature_change_K=dT, shroud_alpha_per_K=as_, beam_alpha_per_K=at)
    hot.solve()
    s1 = hot.state()
    sec = mast_section(E_NO_SHROUD)
    kt = sec.E * sec.A / L_BEAM
    d = s0.upper - s0.lower
    length = np.linalg.norm(d, axis=1)
    c = d[:, 2] / length

    def taus(delta):
        return np.array([tension((length[r] + c[r] * delta) / (nom.L0[r] * (1 + as_ * dT)) - 1.0) for r in range(3)])

    delta = brentq(lambda z: kt * (at * dT * L_BEAM - z) - np.sum(c * (taus(z) - s0.tension)), 0.0, at * dT * L_BEAM)
    rise = s1.displacement[2] - s0.displacement[2]
    assert rise == pytest.approx(delta, rel=1e-3)  # measured 4e-5
    np.testing.assert_allclose(s1.tension, taus(delta), rtol=0.02)  # measured 1.1 %
    assert rise < 0.95 * at * dT * L_BEAM  # the tightening ropes hold the tube back


def test_fe_mast_one_shroud_short_moves_the_top_as_its_linearised_stiffness_says():
    """Shroud 0 cut 0.1 mm short: the top moves by K^-1 B_0 dtau (K the condensed top stiffness at
    the pretension, B_0 shroud 0's direction and arm, dtau = EA_t d / L0 the tension it would gain on
    a fixed top); linearisation error: the law stiffens, (d EA_t / d tau) dtau / (2 EA_t) ~ 3e-3 at
    dtau ~ 25 N (measured 1.4e-3 of the motion)."""
    from femast.elements.shroud_law import axial_rigidity_tangent

    d = 1e-4
    nom = MastFE(1200.0)
    nom.solve()
    st = nom.state()
    K = nom.top_stiffness("full")
    dvec = st.lower - st.upper
    length = np.linalg.norm(dvec, axis=1)
    e = dvec / length[:, None]
    B = np.vstack([e.T, np.cross(st.upper - st.top, e).T])[:, 0]  # wrench of a unit tension of rope 0
    dtau = axial_rigidity_tangent(LAW, st.tension[0]) * length[0] / nom.L0[0] ** 2 * d
    lin = np.linalg.solve(K, B * dtau)
    cut = MastFE(1200.0, length_error=[-d, 0.0, 0.0])
    cut.solve()
    du = cut.state().displacement - st.displacement
    np.testing.assert_allclose(du, lin, rtol=0, atol=3e-3 * np.abs(lin).max())
    assert np.abs(du[:3]).max() > 1e-5  # a real motion (tens of micrometres)


def test_fe_mast_equilibrate_absorbs_length_errors():
    """Tensioning to a measured force removes the lack of fit: equilibrated with errors, the ropes
    carry the target and their stress-free lengths (L0 + dL) are the error-free ones."""
    dL = np.array([2e-3, -1e-3, 0.5e-3])
    ref = MastFE(1200.0)
    ref.equilibrate()
    err = MastFE(1200.0, length_error=dL)
    err.equilibrate()
    np.testing.assert_allclose(err.state().tension, 1200.0, rtol=2e-9)  # equilibrate's tolerance
    np.testing.assert_allclose(err.L0 + dL, ref.L0, rtol=0, atol=1e-9)  # 1e-9 of 1.2 kN on ~4 m ropes


# ------------------------------------------------------------------ tangent and bad input
def test_tangent_matches_finite_differences_with_errors_and_heat():
    rng = np.random.default_rng(3)
    n = 3
    X = rng.normal(size=(2 * n, 3)) * 2.0
    nodes = np.arange(2 * n).reshape(n, 2)
    off = rng.normal(size=(n, 2, 3)) * 0.3
    R = np.array([expm_so3(rng.normal(size=3)) for _ in range(2 * n)])
    p = X[nodes] + np.einsum("enij,enj->eni", R[nodes], off)
    length = np.linalg.norm(p[:, 1] - p[:, 0], axis=1)
    fam = ShroudCableFamily(nodes, length / 1.002, LAW, offsets=off, length_error=[-3e-3, 1e-3, 2e-3])
    fam.length_factor[:] = [1.0 - 4e-4, 1.0 + 3e-4, 1.0]
    r = fam.evaluate(X, R, None)
    assert np.all(r.output["tension"] > 0.0)
    # the stress-free length the law sees
    np.testing.assert_allclose(
        r.output["strain"], length / ((length / 1.002 + fam.length_error) * fam.length_factor) - 1.0, rtol=1e-12
    )
    Kfd = fd_tangent(fam, X, R)
    for e in range(n):
        # central FD, h = 1e-6 m/rad on ~2 m ropes: truncation and round-off below 1e-7 of K
        np.testing.assert_allclose(r.k[e], Kfd[e], atol=1e-7 * np.abs(r.k[e]).max())


@pytest.mark.parametrize(
    "value, words",
    [
        ([1e-3, 2e-3], r"one value per rope, shape \(3,\).*got shape \(2,\)"),
        ([[1e-3, 0, 0]], r"one value per rope.*shape \(1, 3\)"),
        ([0.0, float("nan"), 0.0], r"guys element 2: length_error = nan m is not finite"),
        ([0.0, 0.0, -10.0], r"guys element 3: length_error = -10.0 m leaves the rope a stress-free length -5 m"),
        ("short", r"must be numbers in m"),
    ],
)
def test_bad_length_errors_name_the_rope(value, words):
    with pytest.raises(ModelError, match=words):
        ShroudCableFamily([[0, 1], [2, 3], [4, 5]], 5.0, LAW, length_error=value, name="guys")


def test_bad_thermal_and_mast_input_is_named():
    m = fm.Model("m")
    n0, n1 = m.node(0, 0, 0), m.node(1, 0, 0)
    add_shrouds(m, [[n0, n1]], tension=100.0, name="guy")
    with pytest.raises(ModelError, match=r"no beam or truss family named \['guys'\].*'guy'"):
        m.thermal_expansion(-12e-6, family="guys")
    with pytest.raises(ModelError, match=r"alpha = -0.012 1/K is beyond any structural material"):
        m.thermal_expansion(-12e-3, family="guy")
    assert m.thermal_expansion(-12e-6, family="guy") == [("guy", 0)]
    with pytest.raises(ModelError, match=r"temperature of element \('guy', 0\)|not finite"):
        m.step("s").temperature(float("nan"), family="guy")
    with pytest.raises(ModelError, match="temperature_change_K = nan is not finite"):
        MastFE(1200.0, temperature_change_K=float("nan"))
    with pytest.raises(ModelError, match="length_error is given but the mast has no shrouds"):
        MastFE(None, length_error=1e-3)
    with pytest.raises(ModelError, match=r"shroud: length_error must be a scalar or one value per rope, shape \(3,\)"):
        MastFE(1200.0, length_error=[1e-3, 0.0]).build()


def test_guyed_study_script_runs_its_samples(tmp_path):
    """benchmarks/study_guyed.py (docs/studies.md): the study loads, runs 2 base samples with
    sensitivity (10 runs) without failure, and a warm mast's top rises (dT > 0) or sinks (dT < 0)."""
    from pathlib import Path

    import femast.studies as st
    from femast.studies.cli import load_script

    study = load_script(Path(__file__).resolve().parents[2] / "benchmarks" / "study_guyed.py")
    s = st.run(study, tmp_path / "g", samples=2)
    assert s.complete and s.failed == 0 and s.ok == 10
    res = st.load(tmp_path / "g")
    uz = res.output("top_u", blocks=("A", "B"))[:, 0, 2]  # after 'thermal'
    dT = res.inputs("dT", blocks=("A", "B"))
    # the vertical error is the temperature's (1.55 mm at 20 K; shroud errors move z by < 0.01 mm)
    assert np.all(np.sign(uz - np.median(uz)) == np.sign(dT - np.median(dT)))


def test_platform_study_calibration_removes_the_static_lean_of_erroneous_shrouds():
    """benchmarks/study_guyed_platform.py: exit points calibrated with the masts as they stand, so
    shroud errors that lean the tops by millimetres give no platform error at the calibration pose;
    a temperature change after calibration does."""
    import runpy
    from pathlib import Path

    ns = runpy.run_path(
        str(Path(__file__).resolve().parents[2] / "benchmarks" / "study_guyed_platform.py"), run_name="__femast_study__"
    )
    rng = np.random.default_rng(0)
    dL, pre = rng.normal(0.0, 0.5e-3, 12), rng.normal(T0, 60.0, 12)
    cold = ns["platform"](dL, pre, 0.0)
    assert np.abs(cold["error_cal"]).max() < 1e-9  # solve_pose's Newton tolerance (1e-11) on metres
    assert cold["error_max"] > 1e-3  # the cable wrenches along the path still bend the masts
    warm = ns["platform"](dL, pre, 20.0)
    assert np.abs(warm["error_cal"][2]) > 1e-3  # masts 1.5 mm taller: millimetres at the platform
