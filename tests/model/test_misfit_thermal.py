"""Length errors (lack of fit) and thermal strain against closed forms."""

import numpy as np
import pytest

import femast as fm
from femast.analysis import Analysis
from femast.errors import ModelError
from femast.model.amplitudes import Amplitude
from femast.testing import fd_tangent


def _run(m):
    frames = []
    an = Analysis(m, None, progress=False, on_frame=frames.append)
    an.run()
    return an, frames


def _tube():
    return fm.circular_tube(0.02, 0.016, E=70e9)


def test_determinate_truss_with_one_long_member_moves_without_stress():
    """Two bars from fixed supports (-a, 0) and (a, 0) to an apex (0, h); bar 1 is dL too long.
    Determinate: no force; the apex goes where the bar lengths L + dL and L meet (exact geometry:
    x = ((L + dL)^2 - L^2) / 4a, y = sqrt((L + dL)^2 - (x + a)^2))."""
    a, h, dL, EA = 1.0, 0.8, 2e-3, 1e6
    m = fm.Model("two-bar")
    A, B, C = m.node(-a, 0, 0), m.node(a, 0, 0), m.node(0, h, 0)
    m.truss(A, C, EA, length_error_m=dL)
    m.truss(B, C, EA)
    m.fix(A)
    m.fix(B)
    m.fix(C, "uz")
    m.step("misfit")
    an, frames = _run(m)
    L = np.hypot(a, h)
    x = ((L + dL) ** 2 - L**2) / (4 * a)
    y = np.sqrt((L + dL) ** 2 - (x + a) ** 2)
    # round-off of the positions (1e-16 m) and Newton's tolerance on a stress-free solution
    np.testing.assert_allclose(an.x[m.index(C)], [x, y, 0.0], atol=1e-12)
    N = an.system.evaluate(an.system.committed_context())[0].output["N"]
    assert np.abs(N).max() <= 1e-9 * EA * dL / L  # no stress: round-off of EA (l - L s) / L


def test_cantilever_beam_with_length_error_and_n_elements_grows_by_it_without_stress():
    dL = 0.5e-3
    m = fm.Model("cantilever")
    root, tip = m.node(0, 0, 0), m.node(1.2, 0, 0)
    labels = m.beam(root, tip, _tube(), n=4, length_error_m=dL)  # dL / 4 on each element
    assert sorted(m.length_errors.values()) == [dL / 4] * 4
    m.fix(root)
    m.step("misfit")
    an, _ = _run(m)
    assert len(labels) == 4
    np.testing.assert_allclose(an.x[m.index(tip)], [1.2 + dL, 0, 0], atol=1e-13)  # round-off on 1.2 m
    sf = an.system.evaluate(an.system.committed_context())[0].output["section_forces"]
    assert np.abs(sf).max() <= 1e-9 * 70e9 * _tube().A * dL  # round-off of N


@pytest.mark.parametrize("kind", ["truss", "beam"])
def test_free_thermal_expansion_follows_the_amplitude_without_stress(kind):
    """u = alpha dT L at every time, dT = a(t) (T - T_init) with the amplitude as ramp factor."""
    alpha, T0, T1, L = 23e-6, 20.0, 120.0, 2.0
    m = fm.Model("free bar")
    n1, n2 = m.node(0, 0, 0), m.node(L, 0, 0)
    if kind == "truss":
        e = m.truss(n1, n2, 1e6, alpha_per_K=alpha)
        m.fix(n2, "uy", "uz")
    else:
        e = m.beam(n1, n2, _tube(), alpha_per_K=alpha)
    m.fix(n1)
    m.initial_temperature(T0)
    amp = Amplitude([0.0, 0.5, 1.0], [0.0, 1.0, 0.25])
    m.step("heat", max_increment=0.25).temperature(T1, elements=e, amplitude=amp)
    an, frames = _run(m)
    i = m.index(n2)
    for fr in frames[1:]:
        dT = float(amp(fr["time"])) * (T1 - T0)
        # round-off of positions of ~2 m (1e-15 relative) and of U = x - X0
        assert abs(fr["U"][i, 0] - L * alpha * dT) <= 1e-13
    assert len(frames) >= 5  # 4 increments of 0.25 s at least (hit at the amplitude's 0.5 s)
    N = an.system.evaluate(an.system.committed_context())[0]
    forces = N.output["N"] if kind == "truss" else N.output["section_forces"]
    assert np.abs(forces).max() <= 1e-6  # N (no stress; EA alpha dT would be ~1e3 N)


@pytest.mark.parametrize("kind", ["truss", "beam"])
def test_clamped_bar_heated_carries_minus_EA_alpha_dT(kind):
    alpha, dT, L = 12e-6, 80.0, 1.5
    sec = _tube()
    EA = sec.E * sec.A
    m = fm.Model("clamped bar")
    ends = [m.node(0, 0, 0), m.node(L, 0, 0)]
    if kind == "truss":
        mid = m.node(L / 2, 0, 0)
        els = [m.truss(ends[0], mid, EA), m.truss(mid, ends[1], EA)]
        m.fix(mid, "uy", "uz")
    else:
        els = m.beam(ends[0], ends[1], sec, n=2)
    m.thermal_expansion(alpha)
    for n in ends:
        m.fix(n)
    m.step("heat").temperature(dT)
    an, _ = _run(m)
    r = an.system.evaluate(an.system.committed_context())[0]
    N = r.output["N"] if kind == "truss" else r.output["section_forces"][:, :, 0]
    # exact with the strain measured on L: N = EA (L - L (1 + alpha dT)) / L; round-off only
    np.testing.assert_allclose(N, -EA * alpha * dT, rtol=1e-9)
    assert len(els) == 2


def test_bimetallic_bar_strain_and_forces():
    """Aluminium and steel bars side by side between a wall and a free end (one node): equal strains,
    forces in balance: eps = (EA1 a1 + EA2 a2) dT / (EA1 + EA2), N_i = EA_i (eps - a_i dT)."""
    L, dT = 0.8, 60.0
    EA = np.array([70e9 * 1e-4, 200e9 * 0.5e-4])
    al = np.array([23e-6, 12e-6])
    m = fm.Model("bimetallic")
    n1, n2 = m.node(0, 0, 0), m.node(L, 0, 0)
    t = [
        m.truss(n1, n2, EA[0], alpha_per_K=al[0], family="alu"),
        m.truss(n1, n2, EA[1], alpha_per_K=al[1], family="steel"),
    ]
    m.fix(n1)
    m.fix(n2, "uy", "uz")
    m.step("heat").temperature(dT, family=["alu", "steel"])
    an, _ = _run(m)
    eps = (EA @ al) * dT / EA.sum()
    assert abs(an.x[m.index(n2), 0] - L * (1 + eps)) <= 1e-14  # round-off on 0.8 m
    resp = an.system.evaluate(an.system.committed_context())
    N = np.array([resp[k].output["N"][0] for k in range(2)])
    np.testing.assert_allclose(N, EA * (eps - al * dT), rtol=1e-7)  # Newton tolerance on the balance
    assert len(t) == 2


def test_three_bar_truss_with_a_long_middle_bar_matches_compatibility():
    """Symmetric three-bar truss (middle bar vertical, length h; outer bars at theta); the middle bar
    is delta too long.  Small-displacement compatibility: v = delta / (1 + 2 cos^3 theta),
    N_mid = -2 EA delta cos^3 theta / (h (1 + 2 cos^3 theta)), N_out = -N_mid / (2 cos theta)."""
    h, theta, EA, delta = 1.0, np.radians(40.0), 1e6, 1e-6
    c = np.cos(theta)
    m = fm.Model("three-bar")
    top = [m.node(-h * np.tan(theta), 0, 0), m.node(0, 0, 0), m.node(h * np.tan(theta), 0, 0)]
    D = m.node(0, -h, 0)
    outer1 = m.truss(top[0], D, EA)
    mid = m.truss(top[1], D, EA, length_error_m=delta)
    outer2 = m.truss(top[2], D, EA)
    for n in top:
        m.fix(n)
    m.fix(D, "uz")
    m.step("misfit")
    an, _ = _run(m)
    v = -(an.x[m.index(D), 1] + h)
    N = dict(zip([outer1, mid, outer2], an.system.evaluate(an.system.committed_context())[0].output["N"]))
    k = 1 + 2 * c**3
    # geometric nonlinearity: relative differences O(delta / h) = 1e-6
    np.testing.assert_allclose(v, delta / k, rtol=1e-5)
    Nmid = -2 * EA * delta * c**3 / (h * k)
    np.testing.assert_allclose(N[mid], Nmid, rtol=1e-5)
    np.testing.assert_allclose([N[outer1], N[outer2]], -Nmid / (2 * c), rtol=1e-5)


def test_tangents_with_length_factor_match_finite_differences():
    rng = np.random.default_rng(20)
    from femast.elements.beam_corot import BeamFamily, element_frame
    from femast.elements.truss import TrussFamily
    from femast.rotations import expm_so3

    X = rng.normal(size=(8, 3))
    nodes = np.array([[0, 1], [2, 3], [4, 5], [6, 7]])
    E0 = np.array([element_frame(X[a], X[b], rng.normal(size=3)) for a, b in nodes])
    l0 = np.linalg.norm(X[nodes[:, 1]] - X[nodes[:, 0]], axis=1)
    beams = BeamFamily(
        nodes,
        E0,
        l0,
        EA=rng.uniform(1e2, 1e3, 4),
        GJ=rng.uniform(1, 5, 4),
        EIy=rng.uniform(1, 5, 4),
        EIz=rng.uniform(1, 5, 4),
    )
    beams.length_factor[:] = 1 + rng.uniform(-0.05, 0.05, 4)  # misfit + thermal strain of a few %
    x = X + 0.05 * rng.normal(size=X.shape)
    R = np.array([expm_so3(0.8 * rng.normal(size=3)) for _ in range(8)])
    K = beams.evaluate(x, R, None).k
    Kfd = fd_tangent(beams, x, R)
    for e in range(4):  # central FD, h = 1e-6: truncation ~1e-10 relative
        assert np.abs(K[e] - Kfd[e]).max() <= 1e-6 * np.abs(K[e]).max()
    trusses = TrussFamily(nodes, l0, [1e3] * 4, [False, True, False, True])
    trusses.length_factor[:] = [1.03, 0.97, 0.98, 1.01]
    K = trusses.evaluate(x, R, None).k
    Kfd = fd_tangent(trusses, x, R, dofs=range(3))
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()


def test_assembled_tangent_with_temperature_matches_finite_differences_of_the_residual():
    """The analysis' K_ff under a thermal field and a length error (a frame of beams, heated)."""
    m = fm.Model("frame")
    a, b, c, d = m.node(0, 0, 0), m.node(0, 0, 1), m.node(1, 0, 1), m.node(1, 0.2, 0)
    sec = _tube()
    m.beam(a, b, sec, up=(1, 0, 0), n=2, alpha_per_K=23e-6)
    m.beam(b, c, sec, n=2, length_error_m=1e-3)
    m.beam(c, d, sec, up=(1, 0, 0), n=2)
    m.fix(a)
    m.fix(d)
    m.step("heat").temperature(150.0)
    an, _ = _run(m)
    sys_ = an.system
    K = an.tangent().toarray()
    nf = an.dofmap.n_free

    def internal(shift):
        x, R, spin = an.x.copy(), an.R.copy(), an.spin.copy()
        sys_.update(shift)
        resp = sys_.evaluate(sys_.committed_context())
        r = -sys_.residual(resp, an.loads)[:nf]
        an.x, an.R, an.spin = x, R, spin
        return r

    h = 1e-7
    Kfd = np.column_stack([(internal(h * e) - internal(-h * e)) / (2 * h) for e in np.eye(nf)])
    assert np.abs(K - Kfd).max() <= 1e-5 * np.abs(K).max()  # FD truncation and round-off ~1e-8


def test_temperatures_carry_over_steps_and_unchanged_models_are_not_touched():
    alpha, L = 10e-6, 1.0
    m = fm.Model("two steps")
    n1, n2 = m.node(0, 0, 0), m.node(L, 0, 0)
    m.truss(n1, n2, 1e6, alpha_per_K=alpha)
    m.fix(n1)
    m.fix(n2, "uy", "uz")
    m.step("heat").temperature(50.0)
    m.step("load").load(n2, fx=10.0)
    an, _ = _run(m)
    # 50 K stays in step 2; the load adds N L / EA
    assert abs(an.x[m.index(n2), 0] - (L * (1 + alpha * 50.0) + 10.0 * L / 1e6)) <= 1e-13
    plain = fm.Model("plain")
    p1, p2 = plain.node(0, 0, 0), plain.node(L, 0, 0)
    plain.truss(p1, p2, 1e6)
    plain.fix(p1)
    plain.step("s").load(p2, fx=1.0)
    assert Analysis(plain, None, progress=False, on_frame=lambda f: None).fields is None


def test_bad_inputs_name_the_item_and_the_unit():
    m = fm.Model("bad")
    n1, n2 = m.node(0, 0, 0), m.node(1, 0, 0)
    e = m.truss(n1, n2, 1e6)
    with pytest.raises(ModelError, match="not finite.*m"):
        m.length_error(e, float("nan"))
    with pytest.raises(ModelError, match="not a beam or truss element"):
        m.length_error(99, 1e-3)
    with pytest.raises(ModelError, match="non-positive"):
        m.length_error(e, -1.0)
    with pytest.raises(ModelError, match="1/K"):
        m.thermal_expansion(23.0)  # ppm/K given as 1/K
    with pytest.raises(ModelError, match="1/K"):
        m.thermal_expansion(float("inf"))
    with pytest.raises(ModelError, match="K or degC"):
        m.initial_temperature("warm")
    with pytest.raises(ModelError, match="no beam or truss family"):
        m.step("s").temperature(10.0, family="nope")
    with pytest.raises(ModelError, match="picks no element"):
        m.thermal_expansion(1e-5, where=lambda p: p[0] > 5.0)
    with pytest.raises(ModelError, match="2 values for 1 elements"):
        m.thermal_expansion([1e-5, 2e-5], elements=[e])
    with pytest.raises(ModelError, match="length_error_m"):
        m.truss(n1, n2, 1e6, length_error_m=float("inf"))


def test_thermal_step_under_arc_length_is_refused():
    from femast.analysis.control.arclength import ArcLength

    m = fm.Model("arc")
    n1, n2 = m.node(0, 0, 0), m.node(1, 0, 0)
    m.truss(n1, n2, 1e6, alpha_per_K=1e-5)
    m.fix(n1)
    m.step("s", control=ArcLength()).temperature(10.0).load(n2, fx=1.0)
    with pytest.raises(ModelError, match="temperatures follow step time"):
        Analysis(m, None, progress=False, on_frame=lambda f: None)


def test_bimetallic_strip_bends_with_timoshenkos_curvature():
    """Steel under aluminium, bonded (two beams joined by rigid links at every node: a composite
    Euler-Bernoulli beam), heated by dT: Timoshenko (1925) curvature
    kappa = 6 (a2 - a1) dT (1 + m)^2 / (h (3 (1 + m)^2 + (1 + m n) (m^2 + 1 / (m n)))),
    m = t1 / t2, n = E1 / E2, h = t1 + t2; the free end turns by kappa L."""
    import femast.model.sections as fs

    L, w, t1, t2, dT, n_el = 0.2, 0.01, 0.5e-3, 0.8e-3, 50.0, 8
    E1, a1, E2, a2 = 200e9, 12e-6, 70e9, 23e-6

    def layer(E, t):
        return fs.Section(E=E, G=E / 2.6, A=w * t, Iy=t * w**3 / 12, Iz=w * t**3 / 12, J=w * t**3 / 3)

    m = fm.Model("bimetallic strip")
    bottom = [m.node(L * i / n_el, 0, -t1 / 2) for i in range(n_el + 1)]
    top = [m.node(L * i / n_el, 0, t2 / 2) for i in range(n_el + 1)]
    for i in range(n_el):
        m.beam(bottom[i], bottom[i + 1], layer(E1, t1), up=(0, 0, 1), family="steel", alpha_per_K=a1)
        m.beam(top[i], top[i + 1], layer(E2, t2), up=(0, 0, 1), family="aluminium", alpha_per_K=a2)
    for b, t in zip(bottom, top):
        m.rigid_body(b, [t])
    m.fix(bottom[0])
    m.step("heat").temperature(dT)
    an, frames = _run(m)
    mm, nn, h = t1 / t2, E1 / E2, t1 + t2
    kappa = 6 * (a2 - a1) * dT * (1 + mm) ** 2 / (h * (3 * (1 + mm) ** 2 + (1 + mm * nn) * (mm**2 + 1 / (mm * nn))))
    ry = frames[-1]["URA"][m.index(bottom[-1]), 1]
    # aluminium on top expands more: the strip curls down (+ry).  Uniform curvature is exact for the
    # cubic corotational elements (a circular arc); measured 2e-8 relative, 1e-6 leaves Newton's tolerance
    np.testing.assert_allclose(ry, kappa * L, rtol=1e-6)


def test_increments_end_on_the_temperature_amplitudes_points():
    """A one-increment step still stops at the amplitude's peak (0.3 s), as for loads."""
    alpha, dT, L = 10e-6, 100.0, 1.0
    m = fm.Model("peak")
    n1, n2 = m.node(0, 0, 0), m.node(L, 0, 0)
    m.truss(n1, n2, 1e6, alpha_per_K=alpha)
    m.fix(n1)
    m.fix(n2, "uy", "uz")
    amp = Amplitude([0.0, 0.3, 1.0], [0.0, 1.0, 0.0])
    m.step("pulse").temperature(dT, amplitude=amp)
    _, frames = _run(m)
    times = [f["time"] for f in frames[1:]]
    assert times[0] == pytest.approx(0.3, abs=1e-12) and times[-1] == pytest.approx(1.0, abs=1e-12)
    for f in frames[1:]:  # round-off of displacements of 1e-3 m
        assert abs(f["U"][m.index(n2), 0] - alpha * dT * L * float(amp(f["time"]))) <= 1e-15
